// Tests of the back-projection estimator (penumbra_estimator.cpp) against an exact oracle
// (tests/support/exact_visibility.h: inclusion–exclusion over Lambert's formula) on random
// triangles between a texel and a rectangle, a disk and a sphere's silhouette, and a check that
// a wrong estimator (a triangle dropped, a weight off by a percent) fails that comparison.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "methods/backprojection/penumbra_estimator.h"
#include "methods/backprojection/umbra_proofs.h"
#include "support/exact_visibility.h"

namespace sb {
namespace {

using exact_visibility::PlaneFrame;
using exact_visibility::Polygon2;
using Triangle3 = std::array<Vec3, 3>;

LightDesc rectangle_light() {
  LightDesc d;
  d.name = "panel";
  d.shape = LightShape::rectangle;
  d.position = Vec3(0.1, -0.2, 2.0);
  d.normal = Vec3(0, 0, -1);
  d.up = Vec3(0, 1, 0);
  d.width = 1.2;
  d.height = 0.6;
  d.power = 100;
  return d;
}

LightDesc disk_light() {
  LightDesc d = rectangle_light();
  d.name = "disk";
  d.shape = LightShape::disk;
  d.radius = 0.4;
  return d;
}

// The light's outline as the oracle takes it (a disk as a 1024-gon of equal area).
Polygon2 outline(const Light& light) {
  Polygon2 p;
  if (light.shape() == LightShape::rectangle) {
    const double w = 0.5 * light.desc().width, h = 0.5 * light.desc().height;
    p = {Vec2(-w, -h), Vec2(w, -h), Vec2(w, h), Vec2(-w, h)};
  } else {
    const int sides = 1024;
    const double r =
        light.desc().radius *
        std::sqrt(2 * std::numbers::pi / (sides * std::sin(2 * std::numbers::pi / sides)));
    for (int k = 0; k < sides; ++k) {
      const double a = 2 * std::numbers::pi * k / sides;
      p.push_back(Vec2(r * std::cos(a), r * std::sin(a)));
    }
  }
  return p;
}

struct Case {
  Vec3 y, n;
  std::vector<Triangle3> triangles;
};

// A texel on or near the floor with 1 to 4 triangles between it and the light, most of them
// across the line from the texel to the light's centre, so that most cases are penumbra.
Case random_case(std::mt19937& rng, const Light& light) {
  std::uniform_real_distribution<double> u(0, 1);
  Case c;
  c.y = Vec3(-1.5 + 3 * u(rng), -1.5 + 3 * u(rng), 0.2 * u(rng));
  const double tilt = 0.6 * u(rng), turn = 2 * std::numbers::pi * u(rng);
  c.n = Vec3(std::sin(tilt) * std::cos(turn), std::sin(tilt) * std::sin(turn), std::cos(tilt));
  const int count = 1 + int(4 * u(rng));
  const Vec3 to_light = light.centre() - c.y;
  for (int k = 0; k < count; ++k) {
    const double along = 0.1 + 0.8 * u(rng);
    const Vec3 centre = c.y + along * to_light +
                        Vec3(0.6 * (u(rng) - 0.5), 0.6 * (u(rng) - 0.5), 0.0) * (0.3 + along);
    Triangle3 t;
    const double size = 0.1 + 0.5 * u(rng);
    for (Vec3& p : t) {
      p = centre + size * Vec3(u(rng) - 0.5, u(rng) - 0.5, 0.3 * (u(rng) - 0.5));
      // Strictly between the texel's height and the light's plane.
      p.z() = std::clamp(p.z(), c.y.z() + 0.05, light.centre().z() - 0.05);
    }
    c.triangles.push_back(t);
  }
  return c;
}

// The triangles as the estimator takes them (pointing into `triangles`, which must outlive them).
std::vector<BlockerPolygon> polygons(const std::vector<Triangle3>& triangles) {
  std::vector<BlockerPolygon> out;
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const Triangle3& t = triangles[i];
    out.push_back({t.data(), 3, (t[1] - t[0]).cross(t[2] - t[0]).normalized(), std::uint32_t(i)});
  }
  return out;
}

double oracle(const Light& light, const Case& c) {
  const PlaneFrame frame{light.centre(), light.right(), light.up(), light.normal()};
  return exact_visibility::visibility(frame, outline(light), c.y, c.n, c.triangles);
}

struct Errors {
  double rmse = 0, max = 0;
  int penumbra = 0;
};

// Over `count` random cases whose exact V is strictly between 0.01 and 0.99.
Errors compare(const Light& light, const PenumbraEstimator& estimator, int count,
               bool drop_one = false) {
  std::mt19937 rng(7);
  Errors e;
  double sum = 0;
  while (e.penumbra < count) {
    Case c = random_case(rng, light);
    const double truth = oracle(light, c);
    if (truth <= 0.01 || truth >= 0.99) continue;
    if (drop_one) c.triangles.pop_back();
    const PenumbraSample s = estimator.visibility(c.y, c.n, c.y, polygons(c.triangles));
    EXPECT_TRUE(s.contributes);
    const double d = s.visibility - truth;
    sum += d * d;
    e.max = std::max(e.max, std::abs(d));
    ++e.penumbra;
  }
  e.rmse = std::sqrt(sum / e.penumbra);
  return e;
}

TEST(PenumbraEstimator, UnblockedIsOneAndCoveredIsZeroExactly) {
  const Light light(rectangle_light());
  const PenumbraEstimator estimator(light, 32, 1e-4);
  const Vec3 y(0.3, 0.2, 0), n(0, 0, 1);
  EXPECT_EQ(estimator.visibility(y, n, y, Blockers{}).visibility, 1.0);
  // A large square between the texel and the light hides all of it.
  const std::vector<Triangle3> cover = {Triangle3{Vec3(-3, -3, 1), Vec3(3, -3, 1), Vec3(3, 3, 1)},
                                        Triangle3{Vec3(-3, -3, 1), Vec3(3, 3, 1), Vec3(-3, 3, 1)}};
  EXPECT_EQ(estimator.visibility(y, n, y, polygons(cover)).visibility, 0.0);
  // Behind the light: nothing arrives.
  EXPECT_FALSE(estimator.visibility(Vec3(0, 0, 3), n, Vec3(0, 0, 3), Blockers{}).contributes);
}

// A single polygon that hides the whole light by itself is the sample's umbra (refinement may
// interpolate between samples in one umbra: a convex blocker's is convex); two that hide it only
// together are not.
TEST(PenumbraEstimator, OnePolygonCoveringTheLightIsAnUmbra) {
  const Light light(rectangle_light());
  const PenumbraEstimator estimator(light, 32, 1e-4);
  const Vec3 n(0, 0, 1);
  // The light's centre (0.1, −0.2, 2) seen from y = (0.1, −0.2, 0) through z = 1: the cone's
  // section there is the light's rectangle halved, 0.6 × 0.3 about (0.1, −0.2).
  const Vec3 y(0.1, -0.2, 0);
  const std::vector<Triangle3> one = {Triangle3{Vec3(-3, -3, 1), Vec3(3, -3, 1), Vec3(0, 3, 1)}};
  const PenumbraSample covered = estimator.visibility(y, n, y, polygons(one));
  EXPECT_EQ(covered.visibility, 0.0);
  EXPECT_EQ(covered.umbra, 0u);
  // A square split along a line through the cone's axis: each half hides half the light.
  const std::vector<Triangle3> halves = {
      Triangle3{Vec3(-2.9, -3.2, 1), Vec3(3.1, -3.2, 1), Vec3(3.1, 2.8, 1)},
      Triangle3{Vec3(-2.9, -3.2, 1), Vec3(3.1, 2.8, 1), Vec3(-2.9, 2.8, 1)}};
  const PenumbraSample together = estimator.visibility(y, n, y, polygons(halves));
  EXPECT_EQ(together.visibility, 0.0);
  EXPECT_EQ(together.umbra, PenumbraSample::kNoUmbra);
  // Part of the light hidden: no umbra.
  const std::vector<Triangle3> part = {Triangle3{Vec3(0.1, -3, 1), Vec3(3, -3, 1), Vec3(3, 3, 1)}};
  const PenumbraSample partly = estimator.visibility(y, n, y, polygons(part));
  EXPECT_GT(partly.visibility, 0.0);
  EXPECT_EQ(partly.umbra, PenumbraSample::kNoUmbra);
}

// Where the ray to the light's centre is hidden (Blockers::centre_hidden), the nearest polygons
// of a crowded shaft are tried first for a wall that hides all of the light: behind a whole wall
// of 72 triangles (none hiding the light alone) V is 0, as the whole rasterisation finds it, and
// what the sample reports of its blockers bounds what the whole pass reports (the nearest no
// farther, every key it lists listed). Through a hole in the wall, V is the whole pass's,
// exactly.
TEST(PenumbraEstimator, AWallTriedNearestFirstGivesTheWholePasssV) {
  const Light light(rectangle_light());
  const PenumbraEstimator estimator(light, 32, 1e-4);
  const Vec3 n(0, 0, 1);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  for (const bool hole : {false, true}) {
    // Squares of 0.2 m at z = 1 over [-1.5, 1.5]², less the one over the axis for a hole; and
    // small triangles behind the wall, off the hole.
    std::vector<Triangle3> triangles;
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) {
        const double x = -1.5 + 0.5 * i, y = -1.5 + 0.5 * j;
        if (hole && i == 3 && j == 2) continue;  // [0, 0.5] × [-0.5, 0]
        triangles.push_back({Vec3(x, y, 1), Vec3(x + 0.5, y, 1), Vec3(x + 0.5, y + 0.5, 1)});
        triangles.push_back({Vec3(x, y, 1), Vec3(x + 0.5, y + 0.5, 1), Vec3(x, y + 0.5, 1)});
      }
    for (int k = 0; k < 40; ++k) {
      const Vec3 c(-0.6 + 1.2 * u(rng), -0.3 - 0.6 * u(rng), 1.2 + 0.6 * u(rng));
      triangles.push_back({c, c + Vec3(0.1, 0, 0.02), c + Vec3(0, 0.1, -0.02)});
    }
    const std::vector<BlockerPolygon> polys = polygons(triangles);
    for (int k = 0; k < 10; ++k) {
      const Vec3 y(0.15 + 0.05 * u(rng), -0.25 + 0.05 * u(rng), 0.0);
      std::vector<std::uint32_t> whole_keys, nearest_keys;
      const PenumbraSample whole = estimator.visibility(
          y, n, y, Blockers{&polys, nullptr, nullptr, /*centre_hidden=*/false}, 0, &whole_keys);
      const PenumbraSample nearest = estimator.visibility(
          y, n, y, Blockers{&polys, nullptr, nullptr, /*centre_hidden=*/true}, 0, &nearest_keys);
      ASSERT_TRUE(whole.contributes && nearest.contributes);
      if (hole) {
        EXPECT_EQ(nearest.visibility, whole.visibility) << "texel " << k;
        EXPECT_GT(whole.visibility, 0.01);
        continue;
      }
      EXPECT_EQ(whole.visibility, 0.0) << "texel " << k;
      EXPECT_EQ(nearest.visibility, 0.0) << "texel " << k;
      EXPECT_LE(nearest.nearest_blocker, whole.nearest_blocker);
      EXPECT_TRUE(std::includes(nearest_keys.begin(), nearest_keys.end(), whole_keys.begin(),
                                whole_keys.end()))
          << "every blocker the whole pass lists is listed";
      // The short way was taken: it lists every polygon of the shaft, the whole pass those whose
      // projection reaches the light (the triangles behind the wall reach past its edge).
      EXPECT_GT(nearest_keys.size(), whole_keys.size());
    }
  }
}

// A polygon listed by a key that names many triangles (a dense mesh's: ShaftCuller::kMeshKey)
// reports the triangle it comes from as its umbra: samples that report one umbra lie in one
// convex umbra, which a mesh's union is not (zdm2's wrong texels: a lit slit between two of a
// mesh's triangles, interpolated over as 0).
TEST(PenumbraEstimator, AMeshsPolygonReportsItsOwnTriangleAsTheUmbra) {
  const Light light(rectangle_light());
  const PenumbraEstimator estimator(light, 32, 1e-4);
  const Vec3 n(0, 0, 1), y(0.1, -0.2, 0);
  const std::array<Vec3, 3> corners = {Vec3(-3, -3, 1), Vec3(3, -3, 1), Vec3(0, 3, 1)};
  constexpr std::uint32_t kMesh = 0x40000000u;  // ShaftCuller::kMeshKey | 0
  const std::vector<BlockerPolygon> of_mesh = {
      {corners.data(), 3, Vec3(0, 0, 1), kMesh, /*source=*/42}};
  std::vector<std::uint32_t> blocking;
  const PenumbraSample covered =
      estimator.visibility(y, n, y, Blockers{&of_mesh, nullptr, nullptr}, 0, &blocking);
  EXPECT_EQ(covered.visibility, 0.0);
  EXPECT_EQ(covered.umbra, 42u);
  EXPECT_EQ(blocking, std::vector<std::uint32_t>{kMesh}) << "listed by its key";
}

// triangle_hides_light, the refinement's proof that a cell lies in one triangle's umbra: never
// where the exact oracle sees any of the light, and for most of the triangles that hide it all.
TEST(PenumbraEstimator, ATriangleHidesTheLightOnlyWhereTheOracleSeesNone) {
  for (const LightDesc& desc : {rectangle_light(), disk_light()}) {
    const Light light(desc);
    std::mt19937 rng(11);
    int hidden = 0, said = 0;
    for (int i = 0; i < 4000; ++i) {
      Case c = random_case(rng, light);
      c.triangles.resize(1);
      // Grown about its centroid, so that some hide all of the light.
      Triangle3& t = c.triangles[0];
      const Vec3 mid = (t[0] + t[1] + t[2]) / 3;
      const double grow = 1 + 6 * std::uniform_real_distribution<double>(0, 1)(rng);
      for (Vec3& p : t)
        p = mid + grow * Vec3(p.x() - mid.x(), p.y() - mid.y(), 0) + Vec3(0, 0, p.z() - mid.z());
      for (Vec3& p : t) p.z() = std::clamp(p.z(), c.y.z() + 0.05, light.centre().z() - 0.05);
      const bool says = triangle_hides_light(light, t.data(), c.y, 1e-4);
      const double truth = oracle(light, c);
      hidden += truth < 1e-12;
      said += says;
      if (says) {
        EXPECT_LT(truth, 1e-12) << desc.name << " case " << i;
      }
    }
    std::printf("%s: %d of 4000 triangles hide all of the light, %d found so\n", desc.name.c_str(),
                hidden, said);
    EXPECT_GT(said, hidden / 2) << desc.name;
  }
  // Shifted by a hair past the light's edge, the square that hid it no longer does.
  const Light light(rectangle_light());
  const Vec3 y(0.1, -0.2, 0);
  // The cone's section at z = 1 is the light halved: s in [−0.2, 0.4], t in [−0.35, −0.05].
  const Triangle3 just = {Vec3(-0.2, -0.35, 1), Vec3(2.0, -0.35, 1), Vec3(-0.2, 1.85, 1)};
  EXPECT_FALSE(triangle_hides_light(light, just.data(), y, 1e-4));  // its corner on the cone
  const Triangle3 over = {Vec3(-0.21, -0.36, 1), Vec3(2.0, -0.36, 1), Vec3(-0.21, 1.85, 1)};
  EXPECT_TRUE(triangle_hides_light(light, over.data(), y, 1e-4));
}

// A ball hides the light only where every segment from the origin to the light passes through
// it: on random balls between texels and a rectangle, a disk and a sun (a disk 1000 m away, 0.53°
// across), against segments to a dense grid of the light's points; and it finds most of those
// whose ball covers the light with a margin.
TEST(PenumbraEstimator, ABallHidesTheLightOnlyWhereEverySegmentMeetsIt) {
  LightDesc sun = disk_light();
  sun.name = "sun";
  sun.position = Vec3(300, 100, 950);
  sun.normal = -sun.position.normalized();
  sun.up = sun.normal.cross(Vec3::UnitX()).normalized();
  sun.radius = 1000 * std::tan(0.265 * std::numbers::pi / 180);
  for (const LightDesc& desc : {rectangle_light(), disk_light(), sun}) {
    const Light light(desc);
    // The light's points: a grid over its rectangle, or rings over its disk.
    std::vector<Vec3> points;
    for (int i = 0; i <= 24; ++i)
      for (int j = 0; j <= 24; ++j) {
        const double a = i / 24.0 - 0.5, b = j / 24.0 - 0.5;
        if (desc.shape == LightShape::rectangle) {
          points.push_back(light.centre() + a * desc.width * light.right() +
                           b * desc.height * light.up());
        } else {
          const double r = desc.radius * (i / 24.0), phi = 2 * std::numbers::pi * j / 24.0;
          points.push_back(light.centre() + r * std::cos(phi) * light.right() +
                           r * std::sin(phi) * light.up());
        }
      }
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(0, 1);
    int covered = 0, said = 0;
    for (int i = 0; i < 4000; ++i) {
      const Vec3 origin(-1.5 + 3 * u(rng), -1.5 + 3 * u(rng), 0.2 * u(rng));
      const Vec3 to_light = (light.centre() - origin).normalized();
      const double along = 0.2 + 1.4 * u(rng);
      const Vec3 centre = origin + along * to_light + 0.3 * Vec3(u(rng) - 0.5, u(rng) - 0.5, 0);
      const double radius = 0.05 + 0.6 * u(rng);
      // How near the ball's centre each segment passes, relative to its radius: the most.
      double worst = 0;
      for (const Vec3& q : points) {
        const Vec3 d = q - origin;
        const double t = std::clamp((centre - origin).dot(d) / d.squaredNorm(), 0.0, 1.0);
        worst = std::max(worst, (origin + t * d - centre).norm() / radius);
      }
      const bool says = ball_hides_light(light, centre, radius, origin, 1e-4);
      const bool clear_of_both =
          centre.z() - radius > origin.z() && light.normal().dot(centre - light.centre()) > radius;
      said += says;
      covered += worst < 0.95 && clear_of_both;
      if (says) {
        EXPECT_LT(worst, 1.0) << desc.name << " case " << i;
      }
    }
    std::printf("%s: %d of 4000 balls cover the light with a margin, %d found to hide it\n",
                desc.name.c_str(), covered, said);
    EXPECT_GT(covered, 100) << desc.name;
    EXPECT_GT(said, covered / 2) << desc.name;
  }
}

// The bake's 32 rows, and 64 (rows are the estimator's one approximation that matters: its error
// falls about threefold per doubling).
TEST(PenumbraEstimator, MatchesTheExactOracleOnRandomTriangles) {
  for (const LightDesc& desc : {rectangle_light(), disk_light()})
    for (const int rows : {32, 64}) {
      const Light light(desc);
      const PenumbraEstimator estimator(light, rows, 1e-4);
      const Errors e = compare(light, estimator, 400);
      std::printf("%s, %d rows: %d penumbra cases, RMSE %.5f, max %.5f\n", desc.name.c_str(), rows,
                  e.penumbra, e.rmse, e.max);
      EXPECT_LT(e.rmse, rows == 32 ? 0.002 : 0.0007) << desc.name << " " << rows;
      EXPECT_LT(e.max, rows == 32 ? 0.02 : 0.007) << desc.name << " " << rows;
    }
}

// At 64 rows, where the estimator's own RMSE is under 0.0007, a triangle dropped from every shaft
// is far beyond it.
TEST(PenumbraEstimator, ATriangleDroppedFailsTheComparison) {
  const Light light(rectangle_light());
  const PenumbraEstimator estimator(light, 64, 1e-4);
  const Errors right = compare(light, estimator, 400);
  const Errors dropped = compare(light, estimator, 400, /*drop_one=*/true);
  std::printf("right: RMSE %.5f; one triangle dropped: %.5f\n", right.rmse, dropped.rmse);
  EXPECT_LT(right.rmse, 0.0007);
  EXPECT_GT(dropped.rmse, 0.01);
}

// A straight edge across the light, through its centre along the rows' direction, hides half of
// it from texels below: no row holds a corner of the blocker, so the estimator is exact but for
// the light's own corners, and a weight off by 1 % on half the light (which shifts V by about
// 0.01·V·(1 − V)) is 20 times its error.
TEST(PenumbraEstimator, AWeightOffByAPercentFailsOnAStraightEdge) {
  const Light light(rectangle_light());
  PenumbraEstimator estimator(light, 32, 1e-4);
  const double c = std::cos(kRowAngle), s = std::sin(kRowAngle);
  const Vec3 s_axis = c * light.right() + s * light.up(),
             t_axis = -s * light.right() + c * light.up();
  const auto worst = [&](const PenumbraEstimator& e) {
    double out = 0;
    for (const Vec3& y : {Vec3(0.1, -0.2, 0), Vec3(0.6, 0.3, 0.1), Vec3(-0.7, -0.9, 0)}) {
      const Vec3 n(0, 0, 1), centre = light.centre();
      // The half s < 0 of the light's plane, lifted half way towards the texel.
      const Triangle3 shadow = {centre + 5 * t_axis, centre - 5 * t_axis, centre - 5 * s_axis};
      Triangle3 blocker;
      for (int k = 0; k < 3; ++k) blocker[std::size_t(k)] = y + 0.5 * (shadow[std::size_t(k)] - y);
      const Case cs{y, n, {blocker}};
      const double v = e.visibility(y, n, y, polygons(cs.triangles)).visibility;
      out = std::max(out, std::abs(v - oracle(light, cs)));
    }
    return out;
  };
  const double right = worst(estimator);
  estimator.weight_bias = 1.01;
  const double biased = worst(estimator);
  std::printf("straight edge: worst error %.6f; weight off by 1 %% on half the light: %.6f\n",
              right, biased);
  EXPECT_LT(right, 1e-4);
  EXPECT_GT(biased, 20 * right);
  EXPECT_GT(biased, 1e-3);
}

}  // namespace
}  // namespace sb
