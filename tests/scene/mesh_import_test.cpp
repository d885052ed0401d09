// Tests of import_mesh (mesh_import.cpp): formats, transforms, UV channels, bad files, degenerate
// and non-manifold triangles, and the example scenes' meshes (scenes/, written by
// tests/tools/make_scenes.py) as lightmap receivers.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include <stdlib.h>
#include <unistd.h>

#include "scene/mesh.h"
#include "support/test_gltf.h"
#include "texels/texel_space.h"

namespace sb {
namespace {

namespace fs = std::filesystem;

// Scale, then rotate about X, Y, Z (degrees), then translate: the scene format's object transform,
// built here so these tests do not depend on the scene reader.
Affine3 make_transform(const Vec3& translate, const Vec3& rotate_deg, const Vec3& scale) {
  const double to_rad = std::numbers::pi / 180.0;
  Affine3 t = Affine3::Identity();
  t.translate(translate);
  t.rotate(Eigen::AngleAxisd(rotate_deg.z() * to_rad, Vec3::UnitZ()));
  t.rotate(Eigen::AngleAxisd(rotate_deg.y() * to_rad, Vec3::UnitY()));
  t.rotate(Eigen::AngleAxisd(rotate_deg.x() * to_rad, Vec3::UnitX()));
  t.scale(scale);
  return t;
}

Vec3 point(const TriMesh& mesh, TriMesh::VertexHandle v) {
  const auto& p = mesh.point(v);
  return Vec3(p[0], p[1], p[2]);
}

Vec3 normal(const TriMesh& mesh, TriMesh::VertexHandle v) {
  const auto& n = mesh.normal(v);
  return Vec3(n[0], n[1], n[2]);
}

Vec3 face_normal(const TriMesh& mesh, TriMesh::FaceHandle f) {
  const auto& n = mesh.normal(f);
  return Vec3(n[0], n[1], n[2]);
}

// True when mesh has a vertex at p (within tolerance).
bool has_point(const TriMesh& mesh, const Vec3& p, double tolerance = 1e-6) {
  for (auto v : mesh.vertices()) {
    if ((point(mesh, v) - p).norm() < tolerance) return true;
  }
  return false;
}

std::string base64(const std::vector<std::uint8_t>& bytes) {
  static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    std::uint32_t chunk = std::uint32_t(bytes[i]) << 16;
    if (i + 1 < bytes.size()) chunk |= std::uint32_t(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) chunk |= std::uint32_t(bytes[i + 2]);
    out += alphabet[(chunk >> 18) & 63];
    out += alphabet[(chunk >> 12) & 63];
    out += i + 1 < bytes.size() ? alphabet[(chunk >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? alphabet[chunk & 63] : '=';
  }
  return out;
}

template <class T>
void append(std::vector<std::uint8_t>& bytes, const std::vector<T>& values) {
  const auto* begin = reinterpret_cast<const std::uint8_t*>(values.data());
  bytes.insert(bytes.end(), begin, begin + values.size() * sizeof(T));
}

// Each test writes its meshes into a fresh folder of its own.
class MeshImport : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("shadowbake_mesh_import_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::string& name, const std::string& text) {
    const fs::path file = dir_ / name;
    std::ofstream(file, std::ios::binary) << text;
    return file;
  }

  ObjectDesc object(const fs::path& mesh, bool receiver = true) {
    ObjectDesc obj;
    obj.name = "thing";
    obj.mesh = mesh;
    obj.receiver = receiver;
    obj.line = 7;
    return obj;
  }

  fs::path scene_file() const { return dir_ / "scene.toml"; }

  fs::path dir_;
};

// A unit quad in z = 0 (two triangles), normals +z, UVs (x, y).
const char* kQuadObj = R"(v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
f 1/1/1 2/2/1 3/3/1
f 1/1/1 3/3/1 4/4/1
)";

TEST_F(MeshImport, AppliesObjectTransformToPositions) {
  ObjectDesc obj = object(write("quad.obj", kQuadObj));
  obj.transform = make_transform(Vec3(1, 2, 3), Vec3(0, 0, 90), Vec3(2, 2, 2));
  const auto mesh = import_mesh(obj, scene_file());
  ASSERT_TRUE(mesh) << mesh.error().message;
  EXPECT_EQ(mesh->mesh.n_faces(), 2u);
  EXPECT_EQ(mesh->mesh.n_vertices(), 4u);
  EXPECT_EQ(mesh->skipped_degenerate, 0);
  EXPECT_EQ(mesh->name, "thing");
  // (x, y) -> scale 2 -> rotate 90 about Z: (-2y, 2x) -> translate.
  EXPECT_TRUE(has_point(mesh->mesh, Vec3(1, 2, 3)));
  EXPECT_TRUE(has_point(mesh->mesh, Vec3(1, 4, 3)));
  EXPECT_TRUE(has_point(mesh->mesh, Vec3(-1, 4, 3)));
  EXPECT_TRUE(has_point(mesh->mesh, Vec3(-1, 2, 3)));
  for (auto v : mesh->mesh.vertices()) {
    EXPECT_NEAR((normal(mesh->mesh, v) - Vec3(0, 0, 1)).norm(), 0, 1e-9);
  }
}

TEST_F(MeshImport, TransformsNormalsByInverseTranspose) {
  // A plane x + z = 1 tilted 45 degrees, with its normal in the file.
  ObjectDesc obj = object(write("tilted.obj", R"(v 0 0 1
v 1 0 0
v 0 1 1
vt 0 0
vt 1 0
vt 0 1
vn 0.70710678 0 0.70710678
f 1/1/1 2/2/1 3/3/1
)"));
  obj.transform = make_transform(Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(4, 1, 1));
  const auto mesh = import_mesh(obj, scene_file());
  ASSERT_TRUE(mesh) << mesh.error().message;
  // Points become (4x, y, z): the plane x/4 + z = 1, normal ∝ (1/4, 0, 1).
  const Vec3 expected = Vec3(0.25, 0, 1).normalized();
  for (auto v : mesh->mesh.vertices()) {
    EXPECT_NEAR((normal(mesh->mesh, v) - expected).norm(), 0, 1e-6);
  }
  for (auto f : mesh->mesh.faces()) {
    EXPECT_NEAR((face_normal(mesh->mesh, f) - expected).norm(), 0, 1e-6);
  }
}

TEST_F(MeshImport, MirroringTransformKeepsFaceAndVertexNormalsAgreeing) {
  ObjectDesc obj = object(write("quad.obj", kQuadObj));
  obj.transform = make_transform(Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(-1, 1, 1));
  const auto mesh = import_mesh(obj, scene_file());
  ASSERT_TRUE(mesh) << mesh.error().message;
  ASSERT_EQ(mesh->mesh.n_faces(), 2u);
  for (auto f : mesh->mesh.faces()) {
    EXPECT_NEAR((face_normal(mesh->mesh, f) - Vec3(0, 0, 1)).norm(), 0, 1e-9);
  }
  for (auto v : mesh->mesh.vertices()) {
    EXPECT_NEAR((normal(mesh->mesh, v) - Vec3(0, 0, 1)).norm(), 0, 1e-9);
  }
}

TEST_F(MeshImport, GeneratesNormalsWhenFileHasNone) {
  const auto mesh = import_mesh(object(write("bare.obj", R"(v 0 0 0
v 1 0 0
v 0 1 0
vt 0 0
vt 1 0
vt 0 1
f 1/1 2/2 3/3
)")),
                                scene_file());
  ASSERT_TRUE(mesh) << mesh.error().message;
  for (auto v : mesh->mesh.vertices()) {
    EXPECT_NEAR((normal(mesh->mesh, v) - Vec3(0, 0, 1)).norm(), 0, 1e-6);
  }
}

TEST_F(MeshImport, ReadsUVsFromChannel0) {
  ObjectDesc obj = object(write("quad.obj", kQuadObj));
  obj.transform = make_transform(Vec3(5, 0, 0), Vec3(0, 0, 0), Vec3(1, 1, 1));
  const auto mesh = import_mesh(obj, scene_file());
  ASSERT_TRUE(mesh) << mesh.error().message;
  EXPECT_TRUE(mesh->has_uv);
  for (auto v : mesh->mesh.vertices()) {
    const Vec3 p = point(mesh->mesh, v);
    const auto& uv = mesh->mesh.texcoord2D(v);
    EXPECT_NEAR(uv[0], p.x() - 5, 1e-6);
    EXPECT_NEAR(uv[1], p.y(), 1e-6);
  }
}

TEST_F(MeshImport, RejectsReceiverWithoutItsUVChannel) {
  ObjectDesc obj = object(write("quad.obj", kQuadObj));
  obj.uv_channel = 1;
  const auto mesh = import_mesh(obj, scene_file());
  ASSERT_FALSE(mesh);
  EXPECT_EQ(mesh.error().kind, ErrorKind::scene);
  const std::string& message = mesh.error().message;
  EXPECT_NE(message.find(scene_file().string() + ":7: object 'thing'"), std::string::npos)
      << message;
  EXPECT_NE(message.find("channel 1"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);

  // A blocker needs no UVs: it loads, without them.
  obj.receiver = false;
  const auto blocker = import_mesh(obj, scene_file());
  ASSERT_TRUE(blocker) << blocker.error().message;
  EXPECT_FALSE(blocker->has_uv);
  EXPECT_EQ(blocker->mesh.n_faces(), 2u);
}

TEST_F(MeshImport, RejectsMissingFile) {
  const auto mesh = import_mesh(object(dir_ / "nowhere.obj"), scene_file());
  ASSERT_FALSE(mesh);
  EXPECT_EQ(mesh.error().kind, ErrorKind::scene);
  EXPECT_NE(mesh.error().message.find("nowhere.obj"), std::string::npos) << mesh.error().message;
  EXPECT_NE(mesh.error().message.find("object 'thing'"), std::string::npos);
}

TEST_F(MeshImport, RejectsGarbageFile) {
  std::string noise;
  for (int i = 0; i < 4096; ++i) noise += static_cast<char>((i * 7919 + 13) % 256);
  for (const char* name : {"garbage.xyzw", "garbage.gltf", "garbage.ply", "garbage.obj"}) {
    const auto mesh = import_mesh(object(write(name, noise)), scene_file());
    ASSERT_FALSE(mesh) << name;
    EXPECT_EQ(mesh.error().kind, ErrorKind::scene);
    EXPECT_NE(mesh.error().message.find(name), std::string::npos) << mesh.error().message;
    EXPECT_EQ(mesh.error().message.find('\n'), std::string::npos) << mesh.error().message;
  }
  const auto empty = import_mesh(object(write("empty.obj", "")), scene_file());
  ASSERT_FALSE(empty);
  EXPECT_NE(empty.error().message.find("empty.obj"), std::string::npos);
}

// Assimp runs in a spawned helper, not a forked copy of this process: a fork while another thread
// holds an allocator's lock gave a child that never finished (the AddressSanitizer suite, 60 s).
TEST_F(MeshImport, ReadsWhileOtherThreadsAllocate) {
  const fs::path quad = write("quad.obj", kQuadObj);
  std::atomic<bool> stop{false};
  std::vector<std::thread> busy;
  for (int k = 0; k < 2; ++k)
    busy.emplace_back([&stop, k] {
      std::vector<std::unique_ptr<char[]>> held(64);
      for (std::size_t i = 0; !stop; ++i)
        held[i % held.size()].reset(new char[16 + (i * 37 + k) % 4096]);
    });
  for (int i = 0; i < 20; ++i) {
    const auto mesh = import_mesh(object(quad), scene_file());
    EXPECT_TRUE(mesh) << i << ": " << mesh.error().message;
  }
  stop = true;
  for (auto& t : busy) t.join();
}

TEST_F(MeshImport, NamesAMissingMeshReader) {
  ::setenv("SHADOWBAKE_MESH_READER", (dir_ / "no_such_reader").c_str(), 1);
  const auto mesh = import_mesh(object(write("quad.obj", kQuadObj)), scene_file());
  ::unsetenv("SHADOWBAKE_MESH_READER");
  ASSERT_FALSE(mesh);
  EXPECT_NE(mesh.error().message.find("quad.obj"), std::string::npos) << mesh.error().message;
  EXPECT_NE(mesh.error().message.find("cannot start the mesh reader"), std::string::npos)
      << mesh.error().message;
  EXPECT_NE(mesh.error().message.find("no_such_reader"), std::string::npos);
  EXPECT_EQ(mesh.error().message.find('\n'), std::string::npos);
}

TEST_F(MeshImport, RejectsFileWithoutTriangles) {
  const auto mesh = import_mesh(object(write("lines.obj", R"(v 0 0 0
v 1 0 0
v 0 1 0
l 1 2 3
)"),
                                       false),
                                scene_file());
  ASSERT_FALSE(mesh);
  EXPECT_NE(mesh.error().message.find("no triangles"), std::string::npos) << mesh.error().message;
}

TEST_F(MeshImport, RejectsNonFiniteVertex) {
  const auto mesh = import_mesh(object(write("nan.obj", R"(v 0 0 0
v 1 0 0
v 0 1 0
v nan 0 0
vt 0 0
vn 0 0 1
f 1/1/1 2/1/1 3/1/1
f 1/1/1 2/1/1 4/1/1
)")),
                                scene_file());
  ASSERT_FALSE(mesh);
  EXPECT_NE(mesh.error().message.find("vertex"), std::string::npos) << mesh.error().message;
  EXPECT_NE(mesh.error().message.find("finite"), std::string::npos) << mesh.error().message;
  EXPECT_NE(mesh.error().message.find("nan.obj"), std::string::npos) << mesh.error().message;
  EXPECT_NE(mesh.error().message.find("line 4"), std::string::npos) << mesh.error().message;
}

TEST_F(MeshImport, SkipsDegenerateTriangles) {
  // The quad, plus a collinear triangle and one with two equal corners.
  const auto mesh = import_mesh(object(write("degenerate.obj", std::string(kQuadObj) + R"(v 2 0 0
v 3 0 0
v 4 0 0
f 5/1/1 6/2/1 7/3/1
f 1/1/1 2/2/1 2/3/1
)")),
                                scene_file());
  ASSERT_TRUE(mesh) << mesh.error().message;
  EXPECT_EQ(mesh->mesh.n_faces(), 2u);
  EXPECT_EQ(mesh->skipped_degenerate, 2);
}

TEST_F(MeshImport, RejectsMeshWhoseTrianglesAreAllDegenerate) {
  const auto mesh = import_mesh(object(write("flat.obj", R"(v 0 0 0
v 1 0 0
v 2 0 0
vt 0 0
vn 0 0 1
f 1/1/1 2/1/1 3/1/1
)")),
                                scene_file());
  ASSERT_FALSE(mesh);
  EXPECT_NE(mesh.error().message.find("zero area"), std::string::npos) << mesh.error().message;
}

TEST_F(MeshImport, KeepsNonManifoldTriangles) {
  // Three fins sharing the edge (0,0,0)-(0,0,1), and a fourth triangle reusing a fin's edge in
  // the same direction (inconsistent winding).
  const auto mesh = import_mesh(object(write("fins.obj", R"(v 0 0 0
v 0 0 1
v 1 0 0
v 0 1 0
v -1 -1 0
vt 0 0
vt 1 0
vt 0 1
f 1/1 2/2 3/3
f 1/1 2/2 4/3
f 1/1 2/2 5/3
f 1/1 3/2 4/3
)")),
                                scene_file());
  ASSERT_TRUE(mesh) << mesh.error().message;
  EXPECT_EQ(mesh->mesh.n_faces(), 4u);
  EXPECT_EQ(mesh->skipped_degenerate, 0);
  double area = 0;
  for (auto f : mesh->mesh.faces()) area += mesh->mesh.calc_face_area(f);
  EXPECT_NEAR(area, 0.5 + 0.5 + std::sqrt(2.0) / 2 + 0.5, 1e-9);
}

TEST_F(MeshImport, ReadsAsciiPly) {
  const auto mesh = import_mesh(object(write("quad.ply", R"(ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
property float nx
property float ny
property float nz
property float s
property float t
element face 1
property list uchar int vertex_indices
end_header
0 0 0 0 0 1 0 0
2 0 0 0 0 1 1 0
2 2 0 0 0 1 1 1
0 2 0 0 0 1 0 1
4 0 1 2 3
)")),
                                scene_file());
  ASSERT_TRUE(mesh) << mesh.error().message;
  EXPECT_EQ(mesh->mesh.n_faces(), 2u);
  EXPECT_TRUE(mesh->has_uv);
  EXPECT_TRUE(has_point(mesh->mesh, Vec3(2, 2, 0)));
  for (auto v : mesh->mesh.vertices()) {
    const Vec3 p = point(mesh->mesh, v);
    EXPECT_NEAR(mesh->mesh.texcoord2D(v)[0], p.x() / 2, 1e-6);
    EXPECT_NEAR(mesh->mesh.texcoord2D(v)[1], p.y() / 2, 1e-6);
  }
}

// A glTF 2.0 file with one triangle (with NORMAL and TEXCOORD_0) drawn by two nodes with different
// transforms: one object of two triangles.
std::string two_node_gltf(const std::string& nodes = R"({"mesh": 0, "translation": [10, 0, 0]},
    {"mesh": 0, "rotation": [0, 0, 0.70710678, 0.70710678], "scale": [2, 2, 2]})") {
  const std::vector<float> positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::vector<float> normals = {0, 0, 1, 0, 0, 1, 0, 0, 1};
  // glTF's texture origin is the top left: t = 1 - v for our (u right, v up) UVs.
  const std::vector<float> texcoords = {0, 1, 1, 1, 0, 0};
  const std::vector<std::uint16_t> indices = {0, 1, 2, 0};  // padded to 4 bytes
  std::vector<std::uint8_t> bytes;
  append(bytes, positions);
  append(bytes, normals);
  append(bytes, texcoords);
  append(bytes, indices);
  return R"({
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0, 1]}],
  "nodes": [)" +
         nodes + R"(],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
                              "indices": 3, "mode": 4}]}],
  "buffers": [{"byteLength": )" +
         std::to_string(bytes.size()) + R"(, "uri": "data:application/octet-stream;base64,)" +
         base64(bytes) + R"("}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 36},
    {"buffer": 0, "byteOffset": 36, "byteLength": 36},
    {"buffer": 0, "byteOffset": 72, "byteLength": 24},
    {"buffer": 0, "byteOffset": 96, "byteLength": 6}
  ],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
     "min": [0, 0, 0], "max": [1, 1, 0]},
    {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"},
    {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"},
    {"bufferView": 3, "componentType": 5123, "count": 3, "type": "SCALAR"}
  ]
}
)";
}

TEST_F(MeshImport, ReadsGltfAndAppliesNodeTransforms) {
  ObjectDesc obj = object(write("two_nodes.gltf", two_node_gltf()));
  obj.transform = make_transform(Vec3(0, 0, 1), Vec3(0, 0, 0), Vec3(1, 1, 1));
  const auto mesh = import_mesh(obj, scene_file());
  ASSERT_TRUE(mesh) << mesh.error().message;
  EXPECT_EQ(mesh->mesh.n_faces(), 2u);
  EXPECT_TRUE(mesh->has_uv);
  // Node 0: translated by (10, 0, 0). Node 1: scaled by 2, rotated 90 degrees about Z.
  EXPECT_TRUE(has_point(mesh->mesh, Vec3(10, 0, 1)));
  EXPECT_TRUE(has_point(mesh->mesh, Vec3(11, 0, 1)));
  EXPECT_TRUE(has_point(mesh->mesh, Vec3(10, 1, 1)));
  EXPECT_TRUE(has_point(mesh->mesh, Vec3(0, 0, 1)));
  EXPECT_TRUE(has_point(mesh->mesh, Vec3(0, 2, 1)));
  EXPECT_TRUE(has_point(mesh->mesh, Vec3(-2, 0, 1)));
  // UVs come back as (u right, v up): the corner at file position (1, 0, 0) has uv (1, 0).
  for (auto v : mesh->mesh.vertices()) {
    const Vec3 p = point(mesh->mesh, v);
    const auto& uv = mesh->mesh.texcoord2D(v);
    if ((p - Vec3(11, 0, 1)).norm() < 1e-6) {
      EXPECT_NEAR(uv[0], 1, 1e-6);
      EXPECT_NEAR(uv[1], 0, 1e-6);
    }
    if ((p - Vec3(10, 1, 1)).norm() < 1e-6) {
      EXPECT_NEAR(uv[0], 0, 1e-6);
      EXPECT_NEAR(uv[1], 1, 1e-6);
    }
    EXPECT_NEAR((normal(mesh->mesh, v) - Vec3(0, 0, 1)).norm(), 0, 1e-6);
  }
}

// Assimp's pre-transform applies a mirroring node transform without reversing the winding; the
// importer reverses it so face and vertex normals agree.
TEST_F(MeshImport, MirroringNodeTransformKeepsFaceAndVertexNormalsAgreeing) {
  ObjectDesc obj = object(write("mirrored.gltf", two_node_gltf(R"({"mesh": 0},
    {"mesh": 0, "translation": [5, 0, 0], "scale": [-1, 1, 1]})")));
  const auto mesh = import_mesh(obj, scene_file());
  ASSERT_TRUE(mesh) << mesh.error().message;
  EXPECT_EQ(mesh->mesh.n_faces(), 2u);
  EXPECT_TRUE(has_point(mesh->mesh, Vec3(4, 0, 0)));
  for (auto f : mesh->mesh.faces()) {
    EXPECT_NEAR((face_normal(mesh->mesh, f) - Vec3(0, 0, 1)).norm(), 0, 1e-6);
    for (auto v : mesh->mesh.fv_range(f)) {
      EXPECT_NEAR((normal(mesh->mesh, v) - Vec3(0, 0, 1)).norm(), 0, 1e-6);
    }
  }
}

// --- The example scenes (scenes/, from tests/tools/make_scenes.py) ---

struct SceneObject {
  const char* name;
  const char* mesh;
  bool receiver;
  Affine3 transform;
};

// What scenes/showcase/scene.toml says, written out by hand (keep in step with make_scenes.py).
std::vector<SceneObject> showcase_objects() {
  const Vec3 zero(0, 0, 0), one(1, 1, 1);
  return {
      {"floor", "floor.obj", true, make_transform(zero, zero, one)},
      {"wall", "wall.obj", true, make_transform(zero, zero, one)},
      {"box", "box.obj", true, make_transform(Vec3(-0.8, 0.6, 0), Vec3(0, 0, 25), one)},
      {"sphere", "sphere.gltf", true, make_transform(Vec3(0.3, 0.4, 0.35), Vec3(90, 0, 0), one)},
      {"torus", "torus.obj", false, make_transform(Vec3(0.6, -0.8, 0.07), zero, one)},
      {"cone", "cone.obj", false, make_transform(Vec3(-0.5, -0.5, 0), zero, one)},
  };
}

// Counts texel centres (at resolution²) inside more than one of mesh's UV triangles, UV corners
// outside [0, 1], and UV triangles that are clockwise or flat (the generator winds every chart
// counter-clockwise, as the surface is seen from its front).
struct UVLayoutCheck {
  int overlapping_texels = 0;
  int corners_outside = 0;
  int not_counter_clockwise = 0;
};

UVLayoutCheck check_uv_layout(const TriMesh& mesh, int resolution) {
  UVLayoutCheck check;
  std::vector<std::uint8_t> hits(std::size_t(resolution) * resolution, 0);
  for (auto f : mesh.faces()) {
    const Triangle t = triangle(mesh, f);
    Vec2 lo = t.uv[0], hi = t.uv[0];
    for (const Vec2& uv : t.uv) {
      if ((uv.array() < 0).any() || (uv.array() > 1).any()) ++check.corners_outside;
      lo = lo.cwiseMin(uv);
      hi = hi.cwiseMax(uv);
    }
    auto edge = [](const Vec2& a, const Vec2& b, const Vec2& p) {
      return (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
    };
    const double area = edge(t.uv[0], t.uv[1], t.uv[2]);
    if (!(area > 0)) ++check.not_counter_clockwise;
    if (area == 0) continue;
    const int x0 = std::max(0, int(std::floor(lo.x() * resolution - 0.5)));
    const int x1 = std::min(resolution - 1, int(std::ceil(hi.x() * resolution - 0.5)));
    const int y0 = std::max(0, int(std::floor(lo.y() * resolution - 0.5)));
    const int y1 = std::min(resolution - 1, int(std::ceil(hi.y() * resolution - 0.5)));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const Vec2 centre((x + 0.5) / resolution, (y + 0.5) / resolution);
        const double w0 = edge(t.uv[1], t.uv[2], centre) / area;
        const double w1 = edge(t.uv[2], t.uv[0], centre) / area;
        const double w2 = edge(t.uv[0], t.uv[1], centre) / area;
        // Strictly inside: a centre on a shared edge belongs to neither neighbour twice.
        if (w0 > 1e-9 && w1 > 1e-9 && w2 > 1e-9) {
          if (hits[std::size_t(y) * resolution + x]++ == 1) ++check.overlapping_texels;
        }
      }
    }
  }
  return check;
}

Bounds3 bounds(const TriMesh& mesh) {
  Bounds3 b;
  for (auto v : mesh.vertices()) b.extend(point(mesh, v));
  return b;
}

// The layout check itself: two UV triangles over the same square overlap; side by side they do not.
TEST(MeshImportScenes, UVLayoutCheckSeesOverlaps) {
  auto quad = [](double u0) {
    TriMesh mesh;
    TriMesh::VertexHandle v[4];
    const double corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int i = 0; i < 4; ++i) {
      v[i] = mesh.add_vertex(TriMesh::Point(corners[i][0], corners[i][1], 0));
      mesh.set_normal(v[i], TriMesh::Normal(0, 0, 1));
      mesh.set_texcoord2D(v[i],
                          TriMesh::TexCoord2D(u0 + 0.25 * corners[i][0], 0.5 * corners[i][1]));
    }
    mesh.add_face(v[0], v[1], v[2]);
    mesh.add_face(v[0], v[2], v[3]);
    return mesh;
  };
  const TriMesh apart = quad(0.1);
  EXPECT_EQ(check_uv_layout(apart, 64).overlapping_texels, 0);
  TriMesh folded = quad(0.1);
  // A third triangle over the first one's UVs.
  const auto a = folded.add_vertex(TriMesh::Point(2, 0, 0));
  const auto b = folded.add_vertex(TriMesh::Point(3, 0, 0));
  const auto c = folded.add_vertex(TriMesh::Point(3, 1, 0));
  folded.set_texcoord2D(a, TriMesh::TexCoord2D(0.1, 0));
  folded.set_texcoord2D(b, TriMesh::TexCoord2D(0.35, 0));
  folded.set_texcoord2D(c, TriMesh::TexCoord2D(0.35, 0.5));
  folded.add_face(a, b, c);
  EXPECT_GT(check_uv_layout(folded, 64).overlapping_texels, 0);
  EXPECT_EQ(check_uv_layout(folded, 64).corners_outside, 0);
}

TEST(MeshImportScenes, ShowcaseObjectsHaveLightmapUVs) {
  const fs::path scene = fs::path(SB_SOURCE_DIR) / "scenes" / "showcase" / "scene.toml";
  std::size_t triangles = 0;
  for (const SceneObject& o : showcase_objects()) {
    SCOPED_TRACE(o.name);
    ObjectDesc obj;
    obj.name = o.name;
    obj.mesh = scene.parent_path() / o.mesh;
    obj.receiver = o.receiver;
    obj.transform = o.transform;
    const auto mesh = import_mesh(obj, scene);
    ASSERT_TRUE(mesh) << mesh.error().message;
    EXPECT_TRUE(mesh->has_uv);
    EXPECT_EQ(mesh->skipped_degenerate, 0);
    triangles += mesh->mesh.n_faces();
    const UVLayoutCheck uv = check_uv_layout(mesh->mesh, 512);
    EXPECT_EQ(uv.corners_outside, 0);
    EXPECT_EQ(uv.overlapping_texels, 0);
    EXPECT_EQ(uv.not_counter_clockwise, 0);
    for (auto f : mesh->mesh.faces()) {
      // Vertex normals on the side the winding says is outside.
      for (auto v : mesh->mesh.fv_range(f)) {
        EXPECT_GT(normal(mesh->mesh, v).dot(face_normal(mesh->mesh, f)), 0.5);
      }
    }
    const Bounds3 b = bounds(mesh->mesh);
    if (std::string(o.name) != "wall") {
      EXPECT_NEAR(b.lo.z(), 0, 1e-5) << "rests on the floor";
    }
  }
  EXPECT_LT(triangles, 20000u);
}

// The parallel-plane scenes' floor: UV (u, v) = ((x + 1) / 2, (y + 1) / 2) over the 2 m square.
// Assimp reads single-precision floats: positions agree to 1e-6.
TEST(MeshImportScenes, ParallelPlaneFloorUVsFollowPosition) {
  for (const char* name : {"plane", "parallel", "disk", "sphere"}) {
    SCOPED_TRACE(name);
    const fs::path scene = fs::path(SB_SOURCE_DIR) / "scenes" / name / "scene.toml";
    ObjectDesc obj;
    obj.name = "floor";
    obj.mesh = scene.parent_path() / "floor.obj";
    const auto mesh = import_mesh(obj, scene);
    ASSERT_TRUE(mesh) << mesh.error().message;
    EXPECT_EQ(mesh->mesh.n_faces(), 2u);
    const Bounds3 b = bounds(mesh->mesh);
    EXPECT_NEAR((b.lo - Vec3(-1, -1, 0)).norm(), 0, 1e-6);
    EXPECT_NEAR((b.hi - Vec3(1, 1, 0)).norm(), 0, 1e-6);
    for (auto v : mesh->mesh.vertices()) {
      const Vec3 p = point(mesh->mesh, v);
      EXPECT_NEAR(mesh->mesh.texcoord2D(v)[0], (p.x() + 1) / 2, 1e-6);
      EXPECT_NEAR(mesh->mesh.texcoord2D(v)[1], (p.y() + 1) / 2, 1e-6);
      EXPECT_NEAR((normal(mesh->mesh, v) - Vec3(0, 0, 1)).norm(), 0, 1e-6);
    }
    if (std::string(name) != "plane") {
      ObjectDesc blocker;
      blocker.name = "blocker";
      blocker.mesh = scene.parent_path() / "blocker.obj";
      blocker.receiver = false;
      const auto occluder = import_mesh(blocker, scene);
      ASSERT_TRUE(occluder) << occluder.error().message;
      EXPECT_EQ(occluder->mesh.n_faces(), 2u);
      const Bounds3 ob = bounds(occluder->mesh);
      EXPECT_NEAR((ob.lo - Vec3(-0.3, -0.3, 0.5)).norm(), 0, 1e-6);
      EXPECT_NEAR((ob.hi - Vec3(0.3, 0.3, 0.5)).norm(), 0, 1e-6);
    }
  }
}

// The file's own UV triangles, each on vertices of its own (no weld can merge anything), with the
// same texel-space rasteriser: the coverage an import that keeps every seam must reproduce.
std::int64_t soup_coverage(const std::vector<test_gltf::SoupTriangle>& triangles, int resolution) {
  Mesh soup;
  soup.has_uv = true;
  for (const auto& t : triangles) {
    TriMesh::VertexHandle v[3];
    for (int k = 0; k < 3; ++k) {
      v[k] = soup.mesh.add_vertex(TriMesh::Point(t.p[k].x(), t.p[k].y(), t.p[k].z()));
      soup.mesh.set_normal(v[k], TriMesh::Normal(0, 0, 1));
      soup.mesh.set_texcoord2D(v[k], TriMesh::TexCoord2D(t.uv[k].x(), t.uv[k].y()));
    }
    soup.mesh.add_face(v[0], v[1], v[2]);
  }
  return std::int64_t(rasterise_texels(soup, resolution, resolution).texels.size());
}

// scenes/suzanne/suzanne.glb (Blender: subdivided, smooth, texture UVs in channel 0, Lightmap
// Pack in channel 1, seams unlike channel 0's): both channels cover what the file's own triangles
// cover. Welding on channel 0 alone (Assimp 5.2.5's JoinIdenticalVertices) stretched channel-1
// triangles across the atlas: about twice the texels.
TEST(MeshImportScenes, LightmapUVsInChannel1KeepTheirSeams) {
  const std::string file = std::string(SB_SOURCE_DIR) + "/scenes/suzanne/suzanne.glb";
  constexpr int kResolution = 512;
  for (int channel : {0, 1}) {
    ObjectDesc obj;
    obj.name = "suzanne";
    obj.mesh = file;
    obj.uv_channel = channel;
    const auto mesh = import_mesh(obj, file);
    ASSERT_TRUE(mesh) << mesh.error().message;
    ASSERT_TRUE(mesh->has_uv);
    const auto triangles = test_gltf::read_triangles(file, channel);
    ASSERT_GT(triangles.size(), 3000u);
    EXPECT_EQ(mesh->mesh.n_faces(), triangles.size());
    const std::int64_t expected = soup_coverage(triangles, kResolution);
    const std::int64_t covered =
        std::int64_t(rasterise_texels(*mesh, kResolution, kResolution).texels.size());
    EXPECT_NEAR(double(covered), double(expected), 0.005 * double(expected))
        << "channel " << channel;
    // Welded: fewer vertices than the file's triangle corners.
    EXPECT_LT(mesh->mesh.n_vertices(), 3 * triangles.size());
  }
}

}  // namespace
}  // namespace sb
