// Tests of TangentBounds (tangent_bounds.h): the box of points' central projections, and the
// half side of the square about the axis that holds them.
#include <gtest/gtest.h>

#include <vector>

#include "occluders/tangent_bounds.h"

namespace sb {
namespace {

TEST(TangentBounds, EmptyUntilExtended) {
  TangentBounds b;
  EXPECT_TRUE(b.empty());
  EXPECT_EQ(b.widest(), 0.0);
  b.extend(Vec2(0.5, -0.25));
  EXPECT_FALSE(b.empty());
  EXPECT_EQ(b.lo, Vec2(0.5, -0.25));
  EXPECT_EQ(b.hi, Vec2(0.5, -0.25));
}

TEST(TangentBounds, BoundsCentralProjections) {
  // Seen from the origin along +z, (x, y, z) projects to (x/z, y/z).
  const ProjectionFrame f = frame_towards(Vec3::Zero(), Vec3::UnitZ());
  const std::vector<Vec3> points = {Vec3(1, 0, 2), Vec3(0, -3, 3), Vec3(-2, 1, 4)};
  const TangentBounds b = tangent_bounds(f, points);
  TangentBounds expected;
  for (const Vec3& p : points) expected.extend(f.tangent(p));
  EXPECT_EQ(b.lo, expected.lo);
  EXPECT_EQ(b.hi, expected.hi);
  // |coordinates| of the projections are 1/2, 1 and 1/2, 1/4 (and 0): the widest is 1.
  EXPECT_NEAR(b.widest(), 1.0, 1e-15);
}

TEST(TangentBounds, UnionHoldsBoth) {
  TangentBounds a, b;
  a.extend(Vec2(0, 0));
  a.extend(Vec2(1, 1));
  b.extend(Vec2(-1, 2));
  a.extend(b);
  EXPECT_EQ(a.lo, Vec2(-1, 0));
  EXPECT_EQ(a.hi, Vec2(1, 2));
  EXPECT_EQ(a.centre(), Vec2(0, 1));
  EXPECT_EQ(tangent_bounds(std::vector<Vec2>{Vec2(0, 0), Vec2(1, 1), Vec2(-1, 2)}).lo, a.lo);
}

}  // namespace
}  // namespace sb
