// Tests of the closed solids' inner balls (blocker_solids.h, BlockerSolid::inner_centre): inside
// the solid and clear of its every triangle on a cube and on a lumpy ball as Blender's displaced
// icospheres are, and none where the volume's centroid lies outside the solid (a torus's hole).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "occluders/blocker_solids.h"

namespace sb {
namespace {

using Triangles = std::vector<std::array<Vec3, 3>>;

// A unit cube's twelve triangles, normals out.
Triangles cube() {
  const auto corner = [](int i) { return Vec3(i & 1, (i >> 1) & 1, (i >> 2) & 1); };
  // Each face's corners counter-clockwise seen from outside.
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  Triangles out;
  for (const auto& f : faces) {
    out.push_back({corner(f[0]), corner(f[1]), corner(f[2])});
    out.push_back({corner(f[0]), corner(f[2]), corner(f[3])});
  }
  return out;
}

// A sphere of latitude and longitude bands whose corners lie at radius(direction), normals out.
template <class Radius>
Triangles sphere(int bands, Radius radius) {
  const auto at = [&](int i, int j) {
    const double theta = std::numbers::pi * i / bands, phi = 2 * std::numbers::pi * j / bands;
    const Vec3 d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
    return Vec3(radius(i, j % bands) * d);
  };
  Triangles out;
  for (int i = 0; i < bands; ++i)
    for (int j = 0; j < bands; ++j) {
      const Vec3 a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      if (i > 0) out.push_back({a, b, d});
      if (i + 1 < bands) out.push_back({b, c, d});
    }
  return out;
}

// A torus about z (radii 1 and 0.3), normals out.
Triangles torus() {
  constexpr int n = 24;
  const auto at = [](int i, int j) {
    const double u = 2 * std::numbers::pi * i / n, v = 2 * std::numbers::pi * j / n;
    return Vec3((1 + 0.3 * std::cos(v)) * std::cos(u), (1 + 0.3 * std::cos(v)) * std::sin(u),
                0.3 * std::sin(v));
  };
  Triangles out;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Vec3 a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      out.push_back({a, b, c});
      out.push_back({a, c, d});
    }
  return out;
}

// The distance from p to triangle t, by dense sampling (an upper bound, a hair above the truth).
double sampled_distance(const std::array<Vec3, 3>& t, const Vec3& p) {
  double best = INFINITY;
  constexpr int k = 40;
  for (int i = 0; i <= k; ++i)
    for (int j = 0; i + j <= k; ++j) {
      const double a = double(i) / k, b = double(j) / k;
      best = std::min(best, (t[0] + a * (t[1] - t[0]) + b * (t[2] - t[0]) - p).norm());
    }
  return best;
}

// Whether p lies inside the closed surface: a ray along an irrational direction crosses it an odd
// number of times.
bool inside(const Triangles& triangles, const Vec3& p) {
  const Vec3 d = Vec3(0.3127, 0.7219, 0.6173).normalized();
  int crossings = 0;
  for (const auto& t : triangles) {
    const Vec3 e1 = t[1] - t[0], e2 = t[2] - t[0], h = d.cross(e2);
    const double a = e1.dot(h);
    if (std::abs(a) < 1e-15) continue;
    const Vec3 s = p - t[0];
    const double u = s.dot(h) / a;
    const Vec3 q = s.cross(e1);
    const double v = d.dot(q) / a;
    crossings += u >= 0 && v >= 0 && u + v <= 1 && e2.dot(q) / a > 0;
  }
  return crossings % 2 == 1;
}

// The solid's ball: clear of every triangle, inside, with every corner within the outer radius.
void expect_ball_inside(const Triangles& triangles, const BlockerSolid& solid) {
  ASSERT_GT(solid.inner_radius, 0);
  for (const auto& t : triangles) {
    EXPECT_GE(sampled_distance(t, solid.inner_centre), solid.inner_radius);
    for (const Vec3& v : t) EXPECT_LE((v - solid.inner_centre).norm(), solid.outer_radius);
  }
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  for (int i = 0; i < 200; ++i) {
    const Vec3 p =
        solid.inner_centre + solid.inner_radius *
                                 std::cbrt(std::uniform_real_distribution<double>(0, 1)(rng)) *
                                 Vec3(g(rng), g(rng), g(rng)).normalized();
    EXPECT_TRUE(inside(triangles, p)) << p.transpose();
  }
}

TEST(BlockerSolids, ACubesBallIsItsInscribedOne) {
  const Triangles t = cube();
  const BlockerSolids found = find_solids(t, {t.size()});
  ASSERT_EQ(found.solids.size(), 1u);
  const BlockerSolid& s = found.solids[0];
  EXPECT_TRUE(s.convex);
  EXPECT_NEAR((s.inner_centre - Vec3(0.5, 0.5, 0.5)).norm(), 0, 1e-12);
  EXPECT_NEAR(s.inner_radius, 0.5, 1e-5);
  EXPECT_NEAR(s.outer_radius, std::sqrt(3.0) / 2, 1e-12);
  expect_ball_inside(t, s);
}

// A ball dented and bulged by a fifth of its radius, as the outdoor scene's tree crowns are:
// not convex, and its ball nearly as large as its deepest dent allows.
TEST(BlockerSolids, ALumpyBallHasABallInside) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.8, 1.2);
  std::vector<double> radii(32 * 33);
  for (double& r : radii) r = u(rng);
  const Triangles t = sphere(
      32, [&](int i, int j) { return i == 0 || i == 32 ? 1.0 : radii[std::size_t(i * 32 + j)]; });
  const BlockerSolids found = find_solids(t, {t.size()});
  ASSERT_EQ(found.solids.size(), 1u);
  const BlockerSolid& s = found.solids[0];
  EXPECT_FALSE(s.convex);
  EXPECT_GT(s.inner_radius, 0.5);
  expect_ball_inside(t, s);
}

// A torus's volume centroid is in its hole, outside it: no ball.
TEST(BlockerSolids, NoBallWhereTheCentroidIsOutside) {
  const Triangles t = torus();
  const BlockerSolids found = find_solids(t, {t.size()});
  ASSERT_EQ(found.solids.size(), 1u);
  EXPECT_EQ(found.solids[0].inner_radius, 0);
  // And an open surface is no solid at all.
  Triangles open = cube();
  open.pop_back();
  open.pop_back();
  EXPECT_TRUE(find_solids(open, {open.size()}).solids.empty());
}

}  // namespace
}  // namespace sb
