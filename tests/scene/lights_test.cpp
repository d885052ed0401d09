// Closed-form unoccluded irradiance (Lambert's formula, the disk's closed form, the sphere's
// silhouette) against brute-force numerical integration of docs/design.md §1 with v ≡ 1, and the
// sampling weights against the closed form.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/sampling.h"
#include "scene/lights.h"

namespace sb {
namespace {

constexpr double kPi = std::numbers::pi;

LightDesc rectangle(double w, double h) {
  LightDesc d;
  d.name = "rect";
  d.shape = LightShape::rectangle;
  d.position = Vec3(0.1, -0.2, 1.5);
  d.normal = Vec3(0, 0, -1);
  d.up = Vec3(0, 1, 0);
  d.width = w;
  d.height = h;
  d.power = 100;
  return d;
}

LightDesc tilted_disk(double r) {
  LightDesc d;
  d.name = "disk";
  d.shape = LightShape::disk;
  d.position = Vec3(0.3, 0.2, 1.0);
  d.normal = Vec3(0.3, -0.2, -1).normalized();
  d.up = (Vec3(0, 1, 0) - Vec3(0, 1, 0).dot(d.normal) * d.normal).normalized();
  d.radius = r;
  d.power = 50;
  return d;
}

LightDesc sphere(double r) {
  LightDesc d;
  d.name = "sphere";
  d.shape = LightShape::sphere;
  d.position = Vec3(-0.2, 0.1, 0.8);
  d.radius = r;
  d.power = 80;
  return d;
}

// A tilted triangle, counter-clockwise seen from below (it emits downwards and sideways).
LightDesc triangle() {
  LightDesc d;
  d.name = "triangle";
  d.shape = LightShape::polygon;
  d.corners = {Vec3(-0.3, -0.2, 1.3), Vec3(0.1, 0.35, 1.5), Vec3(0.4, -0.1, 1.2)};
  if ((d.corners[1] - d.corners[0]).cross(d.corners[2] - d.corners[0]).z() > 0)
    std::swap(d.corners[1], d.corners[2]);
  d.power = 60;
  return d;
}

// F = (1/π) ∫ cosθ_x⁺ cosθ_y⁺ / r² dA by the midpoint rule over the light's surface.
double numeric_form_factor(const Light& light, const Vec3& y, const Vec3& n) {
  const LightDesc& d = light.desc();
  double sum = 0;
  auto add = [&](const Vec3& x, const Vec3& normal_x, double area) {
    const Vec3 to = x - y;
    const double r2 = to.squaredNorm(), r = std::sqrt(r2);
    const double cos_y = to.dot(n) / r, cos_x = -to.dot(normal_x) / r;
    if (cos_y > 0 && cos_x > 0) sum += cos_x * cos_y / r2 * area;
  };
  if (d.shape == LightShape::rectangle) {
    const int k = 1500;
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j) {
        const Vec3 x = d.position + ((i + 0.5) / k - 0.5) * d.width * light.right() +
                       ((j + 0.5) / k - 0.5) * d.height * light.up();
        add(x, d.normal, d.width * d.height / (double(k) * k));
      }
  } else if (d.shape == LightShape::polygon) {
    // The midpoint rule over k² similar sub-triangles (k(k+1)/2 upright, k(k−1)/2 upside down).
    const int k = 1500;
    const Vec3 a = d.corners[0], e1 = (d.corners[1] - a) / k, e2 = (d.corners[2] - a) / k;
    const double cell = light.area() / (double(k) * k);
    for (int i = 0; i < k; ++i)
      for (int j = 0; i + j < k; ++j) {
        add(a + (i + 1.0 / 3) * e1 + (j + 1.0 / 3) * e2, light.normal(), cell);
        if (i + j + 1 < k) add(a + (i + 2.0 / 3) * e1 + (j + 2.0 / 3) * e2, light.normal(), cell);
      }
  } else if (d.shape == LightShape::disk) {
    const int kr = 1200, kp = 2400;
    for (int i = 0; i < kr; ++i)
      for (int j = 0; j < kp; ++j) {
        const double r = (i + 0.5) / kr * d.radius, phi = 2 * kPi * (j + 0.5) / kp;
        const Vec3 x =
            d.position + r * (std::cos(phi) * light.right() + std::sin(phi) * light.up());
        add(x, d.normal, r * (d.radius / kr) * (2 * kPi / kp));
      }
  } else {
    const int kt = 1500, kp = 3000;
    for (int i = 0; i < kt; ++i)
      for (int j = 0; j < kp; ++j) {
        const double t = kPi * (i + 0.5) / kt, phi = 2 * kPi * (j + 0.5) / kp;
        const Vec3 normal(std::sin(t) * std::cos(phi), std::sin(t) * std::sin(phi), std::cos(t));
        add(d.position + d.radius * normal, normal,
            d.radius * d.radius * std::sin(t) * (kPi / kt) * (2 * kPi / kp));
      }
  }
  return sum / kPi;
}

struct Point {
  Vec3 y, n;
};

// Points above, beside and cut by the horizon of each light.
std::vector<Point> probe_points() {
  return {
      {Vec3(0, 0, 0), Vec3(0, 0, 1)},                           // below, facing up
      {Vec3(1.2, 0.4, 0), Vec3(0, 0, 1)},                       // off to the side
      {Vec3(0.0, 0.0, 0.2), Vec3(0.6, 0, 0.8)},                 // tilted receiver
      {Vec3(0.05, -0.1, 1.4), Vec3(0, 0, 1)},                   // very close under the centre
      {Vec3(0.3, -0.2, 1.45), Vec3(1, 0, 0)},                   // horizon cuts the light
      {Vec3(-0.5, 0.3, 0.9), Vec3(0.70710678, 0, 0.70710678)},  // horizon cuts, tilted
  };
}

void expect_matches_numerical_integration(const LightDesc& desc) {
  const Light light(desc);
  for (const auto& p : probe_points()) {
    const double exact = light.form_factor(p.y, p.n);
    const double numeric = numeric_form_factor(light, p.y, p.n);
    EXPECT_NEAR(exact, numeric, 2e-5 + 1e-4 * numeric) << p.y.transpose();
  }
}

TEST(Lambert, RectangleMatchesNumericalIntegration) {
  expect_matches_numerical_integration(rectangle(0.5, 0.3));
}

TEST(Lambert, DiskMatchesNumericalIntegration) {
  expect_matches_numerical_integration(tilted_disk(0.25));
}

TEST(Lambert, SphereMatchesNumericalIntegration) {
  expect_matches_numerical_integration(sphere(0.2));
}

TEST(Lambert, TriangleMatchesNumericalIntegration) {
  expect_matches_numerical_integration(triangle());
}

// A rectangle cut along a diagonal into two triangles of half its power each: their form
// factors sum to the rectangle's (the rectangle's own code path) wherever the point is, the
// horizon cutting them or not, and so do their irradiances; and mesh_light_parts joins them
// into one quad, which is the rectangle again.
TEST(Lambert, TwoTrianglesMakeTheirRectangle) {
  const LightDesc rect = rectangle(0.5, 0.3);
  const Light r(rect);
  std::array<Vec3, 4> c;
  ASSERT_EQ(r.outline(c), 4);
  LightDesc half_a = rect, half_b = rect;
  half_a.shape = half_b.shape = LightShape::polygon;
  // The outline runs counter-clockwise about the rectangle's normal.
  half_a.corners = {c[0], c[1], c[2]};
  half_b.corners = {c[0], c[2], c[3]};
  half_a.power = half_b.power = 0.5 * rect.power;
  LightDesc mesh = rect;
  mesh.shape = LightShape::mesh;
  mesh.corners = {c[0], c[1], c[2], c[0], c[2], c[3]};
  const std::vector<LightDesc> parts = mesh_light_parts(mesh);
  ASSERT_EQ(parts.size(), 1u);
  ASSERT_EQ(parts[0].corners.size(), 4u);
  const Light a(half_a), b(half_b), quad(parts[0]);
  EXPECT_LT((quad.centre() - r.centre()).norm(), 1e-12);
  EXPECT_LT((quad.normal() - r.normal()).norm(), 1e-12);
  EXPECT_NEAR(quad.area(), r.area(), 1e-12);
  Rng rng(3);
  for (int i = 0; i < 2000; ++i) {
    const Vec3 y(4 * rng.next_double() - 2, 4 * rng.next_double() - 2, 3 * rng.next_double() - 1);
    const Vec3 n = Vec3(rng.next_double() - 0.5, rng.next_double() - 0.5, rng.next_double() - 0.5)
                       .normalized();
    const double h0 = r.unoccluded_irradiance(y, n).x();
    EXPECT_NEAR(a.form_factor(y, n) + b.form_factor(y, n), r.form_factor(y, n), 1e-12);
    EXPECT_NEAR((a.unoccluded_irradiance(y, n) + b.unoccluded_irradiance(y, n)).x(), h0,
                1e-9 * (1 + h0));
    EXPECT_NEAR(quad.unoccluded_irradiance(y, n).x(), h0, 1e-9 * (1 + h0));
    EXPECT_EQ(a.reaches(y, n) || b.reaches(y, n), r.reaches(y, n)) << y.transpose();
    EXPECT_EQ(quad.reaches(y, n), r.reaches(y, n)) << y.transpose();
  }
}

// Triangles that do not make a convex quad in one plane stay triangles: two of a square folded
// along its diagonal, and two that make an arrowhead.
TEST(MeshLight, OnlyConvexCoplanarPairsBecomeQuads) {
  LightDesc mesh;
  mesh.name = "m";
  mesh.shape = LightShape::mesh;
  mesh.power = 1;
  const Vec3 p(0, 0, 0), q(1, 1, 0), r(0, 1, 0);
  mesh.corners = {p, q, r, q, p, Vec3(1, 0, 0.2)};  // folded
  EXPECT_EQ(mesh_light_parts(mesh).size(), 2u);
  mesh.corners = {p, q, r, q, p, Vec3(0.4, 0.6, 0)};  // across p–q, inside the triangle's side
  EXPECT_EQ(mesh_light_parts(mesh).size(), 2u);
  mesh.corners = {p, q, r, q, p, Vec3(1, 0, 0)};  // a square
  EXPECT_EQ(mesh_light_parts(mesh).size(), 1u);
}

// make_lights: a mesh light is its triangles, each named after it and its index, each with its
// share of the power by area, all reporting the mesh light's output index.
TEST(MeshLight, MakeLightsSplitsItIntoTrianglesOfOneOutput) {
  LightDesc bulb = sphere(0.2);
  LightDesc mesh;
  mesh.name = "shade";
  mesh.shape = LightShape::mesh;
  mesh.power = 30;
  const LightDesc t = triangle();
  // The triangle and a copy twice its size, and a degenerate one that emits nothing.
  mesh.corners = t.corners;
  for (const Vec3& p : t.corners) mesh.corners.push_back(2 * p);
  mesh.corners.insert(mesh.corners.end(), {Vec3::Zero(), Vec3::UnitX(), 2 * Vec3::UnitX()});
  auto lights = make_lights({bulb, mesh}, "scene.toml");
  ASSERT_TRUE(lights) << lights.error().message;
  ASSERT_EQ(lights->size(), 3u);
  EXPECT_EQ(output_count(*lights), 2u);
  EXPECT_EQ((*lights)[0].output(), 0);
  EXPECT_EQ((*lights)[1].output(), 1);
  EXPECT_EQ((*lights)[2].output(), 1);
  EXPECT_EQ((*lights)[1].desc().name, "shade#0");
  EXPECT_EQ((*lights)[2].desc().name, "shade#1");
  EXPECT_NEAR((*lights)[1].desc().power, 6.0, 1e-9);  // area 1 : 4
  EXPECT_NEAR((*lights)[2].desc().power, 24.0, 1e-9);
  // The same exitance on both: power over area.
  EXPECT_NEAR((*lights)[1].exitance().x(), (*lights)[2].exitance().x(), 1e-9);
}

TEST(Lambert, ReachesIsFormFactorPositive) {
  Rng rng(5);
  for (const LightDesc& d : {rectangle(0.5, 0.3), tilted_disk(0.25), sphere(0.2), triangle()}) {
    const Light light(d);
    for (int i = 0; i < 20000; ++i) {
      const Vec3 y(4 * rng.next_double() - 2, 4 * rng.next_double() - 2, 3 * rng.next_double() - 1);
      const Vec3 n = Vec3(rng.next_double() - 0.5, rng.next_double() - 0.5, rng.next_double() - 0.5)
                         .normalized();
      const double f = light.form_factor(y, n);
      // Points that graze the horizon may have F below double precision noise: skip them.
      if (f > 0 && f < 1e-9) continue;
      EXPECT_EQ(light.reaches(y, n), f > 0)
          << to_string(d.shape) << " " << y.transpose() << " / " << n.transpose() << " F = " << f;
    }
  }
}

// reaches_all never claims a box the light misses a point of, and claims boxes wholly in front
// of a light (below a ceiling panel, facing up).
TEST(Lambert, ReachesAllHoldsAtEveryPointOfTheBox) {
  Rng rng(9);
  for (const LightDesc& d : {rectangle(0.5, 0.3), tilted_disk(0.25), triangle()}) {
    const Light light(d);
    int claimed = 0;
    for (int i = 0; i < 4000; ++i) {
      const Vec3 a(4 * rng.next_double() - 2, 4 * rng.next_double() - 2, 3 * rng.next_double() - 1);
      const double size = 0.3 * rng.next_double();
      const Vec3 b = a + size * Vec3(rng.next_double(), rng.next_double(), rng.next_double());
      const Vec3 n = Vec3(rng.next_double() - 0.5, rng.next_double() - 0.5, rng.next_double() - 0.5)
                         .normalized();
      Bounds3 box;
      box.extend(a);
      box.extend(b);
      if (!light.reaches_all(box, n)) continue;
      ++claimed;
      for (int k = 0; k < 64; ++k) {
        const Vec3 y =
            a + (b - a).cwiseProduct(Vec3(rng.next_double(), rng.next_double(), rng.next_double()));
        EXPECT_TRUE(light.reaches(y, n)) << to_string(d.shape) << " " << y.transpose();
      }
      for (int c = 0; c < 8; ++c)
        EXPECT_TRUE(light.reaches(
            Vec3(c & 1 ? b.x() : a.x(), c & 2 ? b.y() : a.y(), c & 4 ? b.z() : a.z()), n));
    }
    EXPECT_GT(claimed, 100) << to_string(d.shape);
  }
  // Neither a sphere nor a spot: no claim.
  Bounds3 below;
  below.extend(Vec3(-0.1, -0.1, -1));
  below.extend(Vec3(0.1, 0.1, -0.9));
  EXPECT_FALSE(Light(sphere(0.2)).reaches_all(below, Vec3::UnitZ()));
}

// Over a box of points and a box of normals (a curved receiver's piece): reaches_all claims
// only where every point reaches every normal that made the box, reaches_none only where none
// does; a sphere, ranged or not, and a ranged rectangle are claimed often both ways.
TEST(Lambert, ReachesAllAndNoneOverNormalBoxesHoldEverywhere) {
  Rng rng(11);
  LightDesc ranged = sphere(0.125), panel = rectangle(0.5, 0.3);
  ranged.range = 1.5;
  panel.range = 1.5;  // none only beyond it: a flat light's horizon is not bounded here
  for (const LightDesc& d : {sphere(0.2), ranged, panel}) {
    const Light light(d);
    int all = 0, none = 0;
    for (int i = 0; i < 4000; ++i) {
      const Vec3 a(4 * rng.next_double() - 2, 4 * rng.next_double() - 2, 3 * rng.next_double() - 1);
      const Vec3 b = a + 0.3 * rng.next_double() *
                             Vec3(rng.next_double(), rng.next_double(), rng.next_double());
      Bounds3 box, normals;
      box.extend(a);
      box.extend(b);
      const Vec3 axis =
          Vec3(rng.next_double() - 0.5, rng.next_double() - 0.5, rng.next_double() - 0.5)
              .normalized();
      // One normal in a quarter of the cases (a flat piece), else four within about 10°.
      std::vector<Vec3> ns{axis};
      if (i % 4 != 0)
        for (int k = 0; k < 3; ++k)
          ns.push_back((axis + 0.2 * Vec3(rng.next_double() - 0.5, rng.next_double() - 0.5,
                                          rng.next_double() - 0.5))
                           .normalized());
      for (const Vec3& n : ns) normals.extend(n);
      const bool claims_all = light.reaches_all(box, normals);
      const bool claims_none = light.reaches_none(box, normals);
      ASSERT_FALSE(claims_all && claims_none);
      if (!claims_all && !claims_none) continue;
      ++(claims_all ? all : none);
      for (int k = 0; k < 64; ++k) {
        const Vec3 y =
            k < 8 ? box.corner(k)
                  : Vec3(a + (b - a).cwiseProduct(
                                 Vec3(rng.next_double(), rng.next_double(), rng.next_double())));
        for (const Vec3& n : ns)
          EXPECT_EQ(light.reaches(y, n), claims_all)
              << d.name << " range " << d.range << " " << y.transpose() << " / " << n.transpose();
      }
    }
    EXPECT_GT(all, 50) << d.name << " range " << d.range;  // a rectangle: one normal only
    EXPECT_GT(none, 200) << d.name << " range " << d.range;
  }
}

TEST(Lambert, DiskOnAxisIsClassicFormula) {
  // On the axis of a disk of radius R at height h, facing it: F = R² / (R² + h²).
  LightDesc d = tilted_disk(0.4);
  d.position = Vec3(0, 0, 2);
  d.normal = Vec3(0, 0, -1);
  d.up = Vec3(0, 1, 0);
  const Light light(d);
  EXPECT_NEAR(light.form_factor(Vec3::Zero(), Vec3(0, 0, 1)), 0.16 / (0.16 + 4.0), 1e-12);
}

TEST(Lambert, BehindTheLightIsDark) {
  const Light rect(rectangle(0.5, 0.5));
  EXPECT_EQ(rect.form_factor(Vec3(0, 0, 2), Vec3(0, 0, -1)), 0.0);
  const Light disk(tilted_disk(0.2));
  EXPECT_EQ(disk.form_factor(Vec3(0.3, 0.2, 3), Vec3(0, 0, -1)), 0.0);
  // Facing away from a sphere.
  const Light sph(sphere(0.2));
  EXPECT_EQ(sph.form_factor(Vec3(-0.2, 0.1, 0), Vec3(0, 0, -1)), 0.0);
}

TEST(Lambert, IrradianceIsExitanceTimesFormFactor) {
  LightDesc d = rectangle(0.5, 0.5);
  d.color = Vec3(1, 0.5, 0.25);
  const Light light(d);
  EXPECT_NEAR(light.exitance().x(), 100.0 / 0.25, 1e-9);
  const Vec3 h0 = light.unoccluded_irradiance(Vec3::Zero(), Vec3::UnitZ());
  const double f = light.form_factor(Vec3::Zero(), Vec3::UnitZ());
  EXPECT_NEAR(h0.x(), 400.0 * f, 1e-9);
  EXPECT_NEAR(h0.y(), 200.0 * f, 1e-9);
  EXPECT_NEAR(h0.z(), 100.0 * f, 1e-9);
  // Far away a Lambertian emitter is a point of intensity P/π: H0 → P/(π d²).
  const double far = 200.0;
  d.position = Vec3(0, 0, far);
  d.color = Vec3(1, 1, 1);
  EXPECT_NEAR(Light(d).unoccluded_irradiance(Vec3::Zero(), Vec3::UnitZ()).x(),
              100.0 / (kPi * far * far), 1e-5 * 100.0 / (kPi * far * far));
}

// The sampling weights, averaged with the right measure, reproduce the closed form: this ties
// the reference's estimator to H0.
TEST(LightSampling, WeightsIntegrateToFormFactor) {
  for (const LightDesc& d : {rectangle(0.5, 0.3), tilted_disk(0.25), sphere(0.2), triangle()}) {
    const Light light(d);
    for (const auto& p : probe_points()) {
      Rng rng(7);
      std::vector<Vec2> u;
      const int n = 65536;
      stratified_samples(n, rng, u);
      double sum = 0;
      for (const auto& s : u) sum += light.sample(p.y, p.n, s).weight;
      double estimate;
      if (d.shape == LightShape::sphere) {
        const double dist = (d.position - p.y).norm();
        const double cos_max = std::sqrt(1 - d.radius * d.radius / (dist * dist));
        estimate = sum / n * 2 * kPi * (1 - cos_max) / kPi;
      } else {
        estimate = sum / n * light.area() / kPi;
      }
      const double exact = light.form_factor(p.y, p.n);
      EXPECT_NEAR(estimate, exact, 1e-4 + 2e-3 * exact)
          << to_string(d.shape) << " at " << p.y.transpose();
    }
  }
}

}  // namespace
// A spot: a sphere light whose irradiance the cone scales by glTF's falloff, the square of
// (cos θ − cos θ_outer) / (cos θ_inner − cos θ_outer), clamped; its visibility is not scaled.
TEST(SpotLight, ConeScalesTheIrradianceAsKhrLightsPunctualSays) {
  LightDesc spot;
  spot.name = "spot";
  spot.shape = LightShape::sphere;
  spot.position = Vec3(0, 0, 3);
  spot.radius = 0.05;
  spot.power = 100;
  spot.spot_axis = Vec3(0, 0, -1);
  spot.spot_inner = 20 * std::numbers::pi / 180;
  spot.spot_outer = 30 * std::numbers::pi / 180;
  LightDesc bulb = spot;
  bulb.spot_outer = 0;
  const Light a(spot), b(bulb);
  const Vec3 up(0, 0, 1);
  for (double degrees : {0.0, 10.0, 19.9, 22.0, 25.0, 29.0, 31.0, 60.0}) {
    const double theta = degrees * std::numbers::pi / 180;
    const Vec3 y(3 * std::tan(theta), 0, 0);  // on the floor, θ off the axis
    const double t = std::clamp((std::cos(theta) - std::cos(spot.spot_outer)) /
                                    (std::cos(spot.spot_inner) - std::cos(spot.spot_outer)),
                                0.0, 1.0);
    EXPECT_NEAR(a.spot_factor(y), t * t, 1e-12) << degrees;
    EXPECT_NEAR(a.unoccluded_irradiance(y, up).x(), t * t * b.unoccluded_irradiance(y, up).x(),
                1e-12)
        << degrees;
    EXPECT_EQ(a.reaches(y, up), t > 0) << degrees;
    EXPECT_EQ(a.form_factor(y, up), b.form_factor(y, up)) << degrees;
  }
}

}  // namespace sb

namespace sb {
namespace {

// A light's `range` as glTF viewers apply it (KHR_lights_punctual's recommended falloff, as
// Khronos's sample viewer computes it): the irradiance inside times clamp(1 − (d/range)⁴, 0, 1),
// none at and beyond the range; the visibility and the form factor are not scaled.
TEST(LightRange, WindowsTheIrradianceAsGltfViewersDo) {
  LightDesc bulb = sphere(0.05);
  bulb.position = Vec3(0, 0, 2);
  LightDesc ranged = bulb;
  ranged.range = 6;
  const Light a(ranged), b(bulb);
  const Vec3 up(0, 0, 1);
  for (double x : {0.0, 1.0, 3.0, 5.0, 5.6, 5.65, 5.66, 7.0}) {
    const Vec3 y(x, 0, 0);
    const double d = (y - bulb.position).norm();
    const double window = std::clamp(1 - std::pow(d / 6, 4), 0.0, 1.0);
    EXPECT_NEAR(a.range_factor(y), window, 1e-12) << x;
    EXPECT_NEAR(a.unoccluded_irradiance(y, up).x(), window * b.unoccluded_irradiance(y, up).x(),
                1e-15)
        << x;
    EXPECT_EQ(a.reaches(y, up), window > 0 && b.reaches(y, up)) << x;
    EXPECT_EQ(a.form_factor(y, up), b.form_factor(y, up)) << x;
  }
  EXPECT_EQ(b.range_factor(Vec3(1e6, 0, 0)), 1.0);  // no range: everywhere
}

// may_reach, which the light lists cull by, is false only where no point of the box is reached:
// checked against reaches at a grid of points and normals in random boxes, for each shape, with
// and without a range and a spot's cone.
TEST(LightRange, MayReachHoldsWhereverSomePointIsReached) {
  std::vector<LightDesc> lights = {rectangle(0.6, 0.4), tilted_disk(0.3), sphere(0.2), triangle()};
  LightDesc spot = sphere(0.05);
  spot.spot_axis = Vec3(0.3, 0, -1).normalized();
  spot.spot_inner = 0.2, spot.spot_outer = 0.4;
  lights.push_back(spot);
  const std::size_t shapes = lights.size();
  for (std::size_t k = 0; k < shapes; ++k) {
    LightDesc ranged = lights[k];
    ranged.range = 1.5;
    lights.push_back(ranged);
  }
  Rng rng(11);
  int culled = 0;
  for (const LightDesc& desc : lights) {
    const Light light(desc);
    for (int box_index = 0; box_index < 300; ++box_index) {
      const Vec3 centre(4 * rng.next_double() - 2, 4 * rng.next_double() - 2,
                        3 * rng.next_double() - 1);
      const Vec3 half(0.3 * rng.next_double(), 0.3 * rng.next_double(), 0.3 * rng.next_double());
      Bounds3 box;
      box.extend(centre - half);
      box.extend(centre + half);
      const Vec3 n =
          Vec3(2 * rng.next_double() - 1, 2 * rng.next_double() - 1, 2 * rng.next_double() - 1)
              .normalized();
      bool reached = false, reached_n = false;
      for (int i = 0; i <= 4; ++i)
        for (int j = 0; j <= 4; ++j)
          for (int l = 0; l <= 4; ++l) {
            const Vec3 y = box.lo + Vec3(i, j, l).cwiseProduct(box.hi - box.lo) / 4;
            reached_n = reached_n || light.reaches(y, n);
            for (const Vec3& m : {Vec3(0, 0, 1), Vec3(0, 0, -1), Vec3(1, 0, 0), Vec3(0, -1, 0)})
              reached = reached || light.reaches(y, m);
          }
      if (reached) {
        EXPECT_TRUE(light.may_reach(box)) << desc.name << " box " << box_index;
      }
      if (reached_n) {
        EXPECT_TRUE(light.may_reach(box, n)) << desc.name << " box " << box_index;
      }
      culled += !light.may_reach(box, n);
    }
  }
  EXPECT_GT(culled, 300) << "the test must see boxes culled";
}

// Under an irradiance floor a light without a range reaches where its irradiance on a surface
// facing it falls to the floor: a point's P/(4π d²), a panel's P/(π d²) along its axis.
TEST(LightRange, FloorGivesTheDistanceOfThatIrradiance) {
  LightDesc bulb = sphere(0.05);
  bulb.power = 100;
  bulb.color = Vec3(0.5, 1, 0.25);
  const double d = range_for_floor(bulb, 0.01);
  EXPECT_NEAR(100 / (4 * kPi * d * d), 0.01, 1e-12);
  bulb.range = d;
  const Light light(bulb);
  // Just inside, the closed form's irradiance facing it (the window's aside) is the floor's.
  const Vec3 y = bulb.position + Vec3(0, 0, -d * (1 - 1e-6));
  EXPECT_NEAR(light.unoccluded_irradiance(y, Vec3(0, 0, 1)).y() / light.range_factor(y), 0.01,
              1e-6);
  LightDesc panel = rectangle(0.5, 0.5);
  panel.power = 40;
  const double dp = range_for_floor(panel, 0.5);
  EXPECT_NEAR(40 / (kPi * dp * dp), 0.5, 1e-12);
  LightDesc sun = tilted_disk(1);
  sun.sun_angle_deg = 0.5;
  EXPECT_FALSE(std::isfinite(range_for_floor(sun, 0.5)));
  EXPECT_FALSE(std::isfinite(range_for_floor(bulb, 0)));
}

}  // namespace
}  // namespace sb
