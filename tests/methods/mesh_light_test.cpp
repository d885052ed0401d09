// Mesh lights (an emissive mesh of a level that is no rectangle or disc) in every method: a mesh
// light is baked as its triangles (make_lights), so a bent panel given as triangles must bake as
// the same two panels given as rectangle lights, whose closed form and code paths are separate:
// the unoccluded irradiance exactly, the shadows within each method's own error, and its per-light
// image as one light of the scene.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "pipeline/bake.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "support/test_scenes.h"
#include "texels/texel_space.h"

namespace sb {
namespace {

// One panel of a tent 1.5 m above the floor: from its ridge (y = 0) down to y = ±0.35, 0.2 m
// lower, 0.6 m along x; its underside emits (down and in, towards the ridge's line).
struct Panel {
  Vec3 origin, slope, across;
  Vec3 normal() const { return across.cross(slope).normalized() * (side < 0 ? 1.0 : -1.0); }
  double side = -1;
};

Panel panel(double side) {
  Panel p;
  p.side = side;
  p.origin = Vec3(-0.3, 0, 1.5);
  p.slope = Vec3(0, 0.35 * side, -0.2);
  p.across = Vec3(0.6, 0, 0);
  return p;
}

LightDesc rectangle_of(const Panel& p, const std::string& name, double power) {
  LightDesc d;
  d.name = name;
  d.shape = LightShape::rectangle;
  d.position = p.origin + 0.5 * p.slope + 0.5 * p.across;
  d.normal = p.normal();
  d.up = p.across.normalized();
  d.height = p.across.norm();
  d.width = p.slope.norm();
  d.power = power;
  return d;
}

// The panel as k × k quads, two triangles each, counter-clockwise about its normal.
void add_triangles(const Panel& p, int k, std::vector<Vec3>& corners) {
  const auto at = [&](int i, int j) {
    return p.origin + (double(i) / k) * p.slope + (double(j) / k) * p.across;
  };
  const auto add = [&](Vec3 a, Vec3 b, Vec3 c) {
    if ((b - a).cross(c - a).dot(p.normal()) < 0) std::swap(b, c);
    corners.insert(corners.end(), {a, b, c});
  };
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) {
      add(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      add(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
}

LightDesc tent_mesh_light(double power) {
  LightDesc d;
  d.name = "tent";
  d.shape = LightShape::mesh;
  add_triangles(panel(-1), 2, d.corners);
  add_triangles(panel(1), 2, d.corners);
  d.position = Vec3(0, 0, 1.4);
  d.power = power;
  return d;
}

// The sphere scene (a floor, a square blocker 0.5 m up) lit by the tent, as triangles or as
// two rectangles.
Scene tent_scene(const std::string& method, bool as_mesh, int resolution) {
  Scene scene = test_scenes::load("sphere", resolution, method);
  scene.bake.samples = 64;
  if (as_mesh) {
    scene.lights = {tent_mesh_light(100)};
  } else {
    scene.lights = {rectangle_of(panel(-1), "tent-a", 50), rectangle_of(panel(1), "tent-b", 50)};
  }
  return scene;
}

const char* const kMethods[] = {"reference", "backprojection", "convolution", "accumulation", "pcf",
                                "pcss",      "adaptive-pcf",   "erosion",     "chun-oh"};

TEST(MeshLight, UnoccludedIrradianceIsTheRectanglesClosedFormInEveryMethod) {
  for (const char* method : kMethods) {
    SCOPED_TRACE(method);
    Scene scene = tent_scene(method, true, 32);
    test_scenes::object(scene, "blocker").blocker = false;
    scene.bake.quantity = Quantity::irradiance;
    auto baked = bake(scene);
    ASSERT_TRUE(baked) << baked.error().message;
    auto mesh = import_mesh(test_scenes::object(scene, "floor"), scene.file);
    ASSERT_TRUE(mesh) << mesh.error().message;
    const TexelSpace space = rasterise_texels(*mesh, 32, 32);
    const Light a(rectangle_of(panel(-1), "a", 50)), b(rectangle_of(panel(1), "b", 50));
    const Image& image = baked->receivers.at(0).image;
    for (const Texel& t : space.texels) {
      const Vec3 y = t.position.cast<double>(), n = t.normal.cast<double>();
      const double h0 = (a.unoccluded_irradiance(y, n) + b.unoccluded_irradiance(y, n)).x();
      ASSERT_NEAR(image.at(t.x, t.y)[0], h0, 1e-5 * h0) << t.x << ", " << t.y;
    }
  }
}

double rmse(const Image& a, const Image& b) {
  double sum = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    const double d = double(a.pixels[i]) - b.pixels[i];
    sum += d * d;
  }
  return std::sqrt(sum / double(a.pixels.size()));
}

// Each method's shadows of the tent as triangles against the reference's shadows of the tent as
// rectangles (at 1,024 samples per light, RMSE ~0.003 from its limit): a method that is exact in
// its limit or a ray-traced estimate (reference, backprojection, convolution, accumulation) is
// within its own error of it; a shadow-map baseline, which filters by the light's size, errs
// on the 16 triangles as it does on the 2 rectangles, within a quarter more.
TEST(MeshLight, ShadowsMatchTheSamePanelsAsRectanglesInEveryMethod) {
  Scene truth_scene = tent_scene("reference", false, 64);
  truth_scene.bake.samples = 1024;
  auto truth = bake(truth_scene);
  ASSERT_TRUE(truth) << truth.error().message;
  const Image& t = truth->receivers.at(0).image;
  double shadowed = 0;
  for (float v : t.pixels) shadowed += v < 0.5 ? 1 : 0;
  EXPECT_GT(shadowed, 0.02 * double(t.pixels.size()));  // the blocker's shadow is there
  for (const char* method : kMethods) {
    SCOPED_TRACE(method);
    auto as_mesh = bake(tent_scene(method, true, 64));
    auto as_rectangles = bake(tent_scene(method, false, 64));
    ASSERT_TRUE(as_mesh) << as_mesh.error().message;
    ASSERT_TRUE(as_rectangles) << as_rectangles.error().message;
    const double mesh_error = rmse(as_mesh->receivers.at(0).image, t);
    const double rectangles_error = rmse(as_rectangles->receivers.at(0).image, t);
    const std::string name = method;
    if (name == "reference" || name == "backprojection" || name == "convolution" ||
        name == "accumulation") {
      EXPECT_LT(mesh_error, 0.015) << "as rectangles: " << rectangles_error;
    } else {
      EXPECT_LT(mesh_error, 1.25 * rectangles_error + 0.005)
          << "as rectangles: " << rectangles_error;
    }
    std::printf("%-15s RMSE against the reference: mesh light %.4f, rectangles %.4f\n", method,
                mesh_error, rectangles_error);
  }
}

// A mesh light's per-light image is one light's (its triangles together): beside a sphere light
// it is the bake of the mesh light alone, and there are as many per-light images as lights.
TEST(MeshLight, PerLightImageIsTheMeshLightAlone) {
  for (const char* method : {"reference", "backprojection"}) {
    SCOPED_TRACE(method);
    Scene both = tent_scene(method, true, 32);
    LightDesc bulb;
    bulb.name = "bulb";
    bulb.shape = LightShape::sphere;
    bulb.position = Vec3(0.6, 0.4, 1.2);
    bulb.radius = 0.1;
    bulb.power = 40;
    both.lights.push_back(bulb);
    both.output.per_light = true;
    auto baked_both = bake(both);
    ASSERT_TRUE(baked_both) << baked_both.error().message;
    auto alone = bake(tent_scene(method, true, 32));
    ASSERT_TRUE(alone) << alone.error().message;
    const ReceiverBake& r = baked_both->receivers.at(0);
    ASSERT_EQ(r.per_light.size(), 2u);
    const Image tent = r.per_light.dense(0);
    const Image& expected = alone->receivers.at(0).image;
    for (std::size_t i = 0; i < tent.pixels.size(); ++i)
      ASSERT_NEAR(tent.pixels[i], expected.pixels[i], 1e-5) << i;
  }
}

}  // namespace
}  // namespace sb
