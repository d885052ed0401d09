// Tests of the frusta of a light (light_frusta.cpp): one frustum for points within 60° of the
// axis towards their middle, none when they surround the light, and cube faces by the dominant
// direction.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include "occluders/light_frusta.h"

namespace sb {
namespace {

TEST(LightFrusta, OneFrustumServesPointsBelowTheLight) {
  const Vec3 centre(0, 0, 2);
  const std::vector<Vec3> floor = {Vec3(-1, -1, 0), Vec3(1, -1, 0), Vec3(1, 1, 0), Vec3(-1, 1, 0)};
  const std::optional<ProjectionFrame> f = central_frustum(centre, floor);
  ASSERT_TRUE(f.has_value());
  EXPECT_TRUE(f->axis.isApprox(-Vec3::UnitZ(), 1e-12));
  EXPECT_EQ(f->origin, centre);
}

TEST(LightFrusta, NoFrustumServesPointsAroundTheLight) {
  const std::vector<Vec3> around = {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0)};
  EXPECT_FALSE(central_frustum(Vec3::Zero(), around).has_value());
}

TEST(LightFrusta, HalfAngleIsSixtyDegrees) {
  EXPECT_NEAR(max_frustum_half_angle_cosine(), 0.5, 1e-15);
  // A point at 59° from the axis is served, one at 61° is not.
  const ProjectionFrame f = frame_towards(Vec3::Zero(), Vec3::UnitZ());
  const double a = 59 * std::numbers::pi / 180, b = 61 * std::numbers::pi / 180;
  EXPECT_GE(cosine_from_axis(f, Vec3(std::sin(a), 0, std::cos(a))),
            max_frustum_half_angle_cosine());
  EXPECT_LT(cosine_from_axis(f, Vec3(std::sin(b), 0, std::cos(b))),
            max_frustum_half_angle_cosine());
  EXPECT_EQ(cosine_from_axis(f, Vec3::Zero()), 1.0);
}

TEST(LightFrusta, CubeFacesFollowTheDominantDirection) {
  const Vec3 centre(1, 2, 3);
  const Vec3 dirs[kCubeFaces] = {Vec3(5, 1, -1), Vec3(-5, 1, 1), Vec3(1, 5, -1),
                                 Vec3(1, -5, 1), Vec3(1, -1, 5), Vec3(-1, 1, -5)};
  const char* names[kCubeFaces] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  for (int face = 0; face < kCubeFaces; ++face) {
    EXPECT_EQ(cube_face(centre, centre + dirs[face]), face);
    EXPECT_STREQ(cube_face_name(face), names[face]);
    const ProjectionFrame f = cube_face_frame(centre, face);
    EXPECT_EQ(f.origin, centre);
    EXPECT_GT(f.axis.dot(dirs[face]), 0);
    EXPECT_NEAR(std::abs(f.axis[face / 2]), 1.0, 1e-12);
  }
}

}  // namespace
}  // namespace sb
