// Tests of lightmap sizes from a texel density (src/texels/lightmap_sizes.h): a receiver's side
// gives its surface the density asked for, scaled by its lightmap_scale, clamped with a warning.
#include "texels/lightmap_sizes.h"

#include <gtest/gtest.h>

#include "scene/mesh.h"

namespace sb {
namespace {

// A w × h metre rectangle whose UVs cover [0, uv_extent]².
Mesh rectangle(double w, double h, double uv_extent) {
  Mesh mesh;
  mesh.has_uv = true;
  TriMesh::VertexHandle v[4];
  const double corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int i = 0; i < 4; ++i) {
    v[i] = mesh.mesh.add_vertex(TriMesh::Point(corners[i][0] * w, corners[i][1] * h, 0));
    mesh.mesh.set_texcoord2D(
        v[i], TriMesh::TexCoord2D(corners[i][0] * uv_extent, corners[i][1] * uv_extent));
    mesh.mesh.set_normal(v[i], TriMesh::Normal(0, 0, 1));
  }
  mesh.mesh.add_face(v[0], v[1], v[2]);
  mesh.mesh.add_face(v[0], v[2], v[3]);
  return mesh;
}

TEST(LightmapSizes, SideGivesTheSurfaceTheDensity) {
  // 4 m² over the whole unit square at 50 texels per metre: 2 m a side, 100 texels.
  EXPECT_EQ(lightmap_side(rectangle(2, 2, 1), 50, 8192).side, 100);
  // The same surface on a quarter of the square needs twice the side for the same density.
  EXPECT_EQ(lightmap_side(rectangle(2, 2, 0.5), 50, 8192).side, 200);
  // A 4 × 1 m wall: √4 m per side of its square, 2 m, at 32 texels per metre: 64.
  EXPECT_EQ(lightmap_side(rectangle(4, 1, 1), 32, 8192).side, 64);
}

TEST(LightmapSizes, ClampedToTheSmallestAndLargestSide) {
  const LightmapSide tiny = lightmap_side(rectangle(0.05, 0.05, 1), 20, 8192);
  EXPECT_EQ(tiny.side, kMinLightmapSide);
  EXPECT_TRUE(tiny.clamped);
  const LightmapSide huge = lightmap_side(rectangle(100, 100, 1), 64, 2044);
  EXPECT_EQ(huge.side, 2044);
  EXPECT_TRUE(huge.clamped);
  EXPECT_NEAR(huge.wanted, 6400, 1e-6);
}

TEST(LightmapSizes, ObjectsScaleTheirDensityAndClampsAreWarned) {
  Scene scene;
  scene.file = "s.toml";
  scene.bake.texels_per_metre = 50;
  scene.output.atlas = AtlasSettings{512, 2};
  ObjectDesc floor, cup, wall;
  floor.name = "floor";
  floor.line = 3;
  cup.name = "cup";
  cup.lightmap_scale = 2;
  wall.name = "wall";
  wall.line = 9;
  scene.objects = {floor, cup, wall};
  const std::vector<Mesh> meshes = {rectangle(20, 20, 1), rectangle(0.5, 0.5, 1),
                                    rectangle(2, 2, 1)};
  std::vector<std::string> warnings;
  const std::vector<int> sides = lightmap_sides(scene, meshes, &warnings);
  EXPECT_EQ(sides, (std::vector<int>{508, 50, 100}));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0],
            "s.toml:3: object 'floor': at 50 texels per metre its lightmap would be 1000² texels; "
            "it gets 508² (25.4 texels per metre), the atlas's size less its padding");
}

}  // namespace
}  // namespace sb
