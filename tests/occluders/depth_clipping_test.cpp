// Tests of clip_to_depth (depth_clipping.cpp) against closed forms: a triangle cut by a depth
// plane keeps exactly the part on the kept side, with its crossing points on the plane.
#include <gtest/gtest.h>

#include <vector>

#include "occluders/depth_clipping.h"

namespace sb {
namespace {

// Frame at the origin looking along +z: depth is the z coordinate.
const ProjectionFrame kAlongZ = frame_towards(Vec3::Zero(), Vec3::UnitZ());

TEST(DepthClipping, KeepsAWholeTriangleOnTheKeptSide) {
  const std::vector<Vec3> tri = {Vec3(0, 0, 2), Vec3(1, 0, 3), Vec3(0, 1, 4)};
  EXPECT_EQ(clip_to_depth(tri, kAlongZ, 1.0, KeepDepth::at_least), tri);
  EXPECT_EQ(clip_to_depth(tri, kAlongZ, 5.0, KeepDepth::at_most), tri);
  EXPECT_TRUE(clip_to_depth(tri, kAlongZ, 5.0, KeepDepth::at_least).empty());
  EXPECT_TRUE(clip_to_depth(tri, kAlongZ, 1.0, KeepDepth::at_most).empty());
}

TEST(DepthClipping, CutsAtThePlane) {
  // One vertex beyond depth 2, two before it: the far side is a triangle, the near a quad.
  const std::vector<Vec3> tri = {Vec3(0, 0, 1), Vec3(2, 0, 1), Vec3(0, 0, 3)};
  const std::vector<Vec3> far = clip_to_depth(tri, kAlongZ, 2.0, KeepDepth::at_least);
  ASSERT_EQ(far.size(), 3u);
  const std::vector<Vec3> near = clip_to_depth(tri, kAlongZ, 2.0, KeepDepth::at_most);
  ASSERT_EQ(near.size(), 4u);
  int on_plane = 0;
  for (const Vec3& p : far) {
    EXPECT_GE(p.z(), 2.0 - 1e-12);
    if (std::abs(p.z() - 2.0) < 1e-12) ++on_plane;
  }
  EXPECT_EQ(on_plane, 2);
  for (const Vec3& p : near) EXPECT_LE(p.z(), 2.0 + 1e-12);
  // The crossing points of the edges (2,0,1)–(0,0,3) and (0,0,3)–(0,0,1).
  EXPECT_TRUE(far[0].isApprox(Vec3(1, 0, 2), 1e-12));
  EXPECT_TRUE(far[2].isApprox(Vec3(0, 0, 2), 1e-12));
}

}  // namespace
}  // namespace sb
