// Tests of what import_mesh (mesh_import.cpp) refuses or repairs: missing, garbage and
// triangle-less files, a missing mesh reader, a receiver without its UV channel, non-finite
// vertices, and degenerate and non-manifold triangles.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <stdlib.h>

#include "scene/mesh_import_fixture.h"

namespace sb::mesh_import_test {
namespace {

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

}  // namespace
}  // namespace sb::mesh_import_test
