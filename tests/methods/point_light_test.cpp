// Point lights (a sphere light of radius 0, baked as a sphere of kPointLightRadius) against their
// closed form, for the methods that shade each texel exactly: the irradiance of every lit texel is
// Φ cos θ / (4π d²), every shadowed texel is 0, and the shadow is hard (no penumbra wider than
// the texels its outline crosses).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "pipeline/bake.h"
#include "scene/mesh.h"
#include "support/test_scenes.h"
#include "texels/texel_space.h"

namespace sb {
namespace {

TEST(PointLight, InverseSquareIrradianceAndHardShadowsForEveryExactMethod) {
  for (const std::string method : {"reference", "backprojection", "convolution", "accumulation"}) {
    SCOPED_TRACE(method);
    Scene scene = test_scenes::load("sphere", 128, method);
    scene.lights[0].radius = kPointLightRadius;
    scene.bake.quantity = Quantity::irradiance;
    scene.bake.samples = 4;
    auto baked = bake(scene);
    ASSERT_TRUE(baked) << baked.error().message;
    const ObjectDesc& floor = test_scenes::object(scene, "floor");
    auto mesh = import_mesh(floor, scene.file);
    ASSERT_TRUE(mesh) << mesh.error().message;
    const TexelSpace space = rasterise_texels(*mesh, 128, 128);
    const Image& image = baked->receivers.at(0).image;
    const LightDesc& light = scene.lights[0];
    int lit = 0, shadowed = 0, between = 0;
    for (const Texel& t : space.texels) {
      const Vec3 y = t.position.cast<double>(), n = t.normal.cast<double>();
      const Vec3 to_light = light.position - y;
      const double d = to_light.norm();
      const double h0 =
          light.power * std::max(0.0, n.dot(to_light) / d) / (4 * std::numbers::pi * d * d);
      const double h = image.at(t.x, t.y)[0];
      if (std::abs(h - h0) <= 1e-3 * h0) {
        ++lit;
      } else if (h <= 1e-3 * h0) {
        ++shadowed;
      } else {
        ++between;
      }
    }
    const double texels = double(space.texels.size());
    EXPECT_GT(lit, 0.2 * texels);
    EXPECT_GT(shadowed, 0.02 * texels);
    // The outline crosses a few hundred of the 16,384 texels; a 0.25 m sphere's penumbra covers
    // thousands.
    EXPECT_LT(between, 0.02 * texels) << lit << " lit, " << shadowed << " shadowed";
  }
}

}  // namespace
}  // namespace sb
