// The example scenes' meshes (scenes/, written by tests/tools/make_scenes.py) as import_mesh
// reads them: lightmap UVs without overlaps, normals on the outside, the floors' UVs following
// position, and UV seams kept in a second UV channel.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "scene/mesh_import_fixture.h"
#include "support/test_gltf.h"
#include "texels/texel_space.h"

namespace sb::mesh_import_test {
namespace {

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
}  // namespace sb::mesh_import_test
