// Tests of LightMix (src/methods/light_mix.h) through every method of the registry: the per-light
// images a bake keeps are each light's own values, and the combined image is the mix of them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "methods/method.h"
#include "pipeline/bake.h"
#include "support/test_scenes.h"

namespace sb {
namespace {

using test_scenes::load;

BakeResult bake_or_fail(const Scene& scene, bool keep_per_light) {
  BakeOptions options;
  options.keep_per_light.values = keep_per_light;
  auto result = bake(scene, options);
  EXPECT_TRUE(result) << result.error().message;
  if (!result) throw std::runtime_error(result.error().message);
  return std::move(*result);
}

// Largest |a − b| over covered texels, relative to max(1, |b|).
double worst_difference(const Image& a, const Image& b, const std::vector<std::uint8_t>& covered) {
  double worst = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      if (!covered[std::size_t(y) * std::size_t(a.width) + std::size_t(x)]) continue;
      for (int c = 0; c < 3; ++c) {
        const double va = a.at(x, y)[c], vb = b.at(x, y)[c];
        worst = std::max(worst, std::abs(va - vb) / std::max(1.0, std::abs(vb)));
      }
    }
  return worst;
}

// Every receiver's per-light image of light l in `all` is `one`'s combined image, to `tolerance`.
void expect_per_light_is(const BakeResult& all, std::size_t l, const BakeResult& one,
                         double tolerance, const std::string& light) {
  ASSERT_EQ(one.receivers.size(), all.receivers.size());
  for (std::size_t r = 0; r < all.receivers.size(); ++r) {
    const ReceiverBake& rb = all.receivers[r];
    ASSERT_GT(rb.per_light.size(), l) << rb.name;
    EXPECT_LE(worst_difference(rb.per_light.dense(l), one.receivers[r].image, rb.covered),
              tolerance)
        << rb.name << ", light " << light;
  }
}

class PerLight : public ::testing::TestWithParam<std::string> {};

// The showcase's two lights (a tilted panel and a sphere), irradiance: light l's per-light image
// is H0_l·V_l, which is what the scene gives with every other light dimmed a trillion-fold (the
// same lights in the same order, so the same random streams and shadow maps: only the mix
// changes). To float rounding, for every method.
TEST_P(PerLight, EachLightsImageIsThatLightAlone) {
  Scene scene = load("showcase", 32, GetParam());
  scene.bake.quantity = Quantity::irradiance;
  scene.bake.samples = 8;
  set_setting(scene.bake, "shadow_map", 256);
  ASSERT_EQ(scene.lights.size(), 2u);
  const BakeResult all = bake_or_fail(scene, true);
  for (std::size_t l = 0; l < scene.lights.size(); ++l) {
    Scene alone = scene;
    for (std::size_t k = 0; k < alone.lights.size(); ++k)
      if (k != l) alone.lights[k].power *= 1e-12;
    expect_per_light_is(all, l, bake_or_fail(alone, false), 1e-5, scene.lights[l].name);
  }
  // And the combined image is the sum of the per-light ones (irradiance), as the method gives
  // them: each image's seams are stitched on its own and kept within its own baked values
  // (texels/seams.h), which is not linear where the texel grid cannot match a seam.
  scene.bake.seams = false;
  const BakeResult unstitched = bake_or_fail(scene, true);
  for (const ReceiverBake& rb : unstitched.receivers) {
    Image sum = rb.per_light.dense(0);
    const Image second = rb.per_light.dense(1);
    for (std::size_t i = 0; i < sum.pixels.size(); ++i) sum.pixels[i] += second.pixels[i];
    EXPECT_LE(worst_difference(sum, rb.image, rb.covered), 1e-5) << rb.name;
  }
}

// Light l's per-light visibility is what the scene gives with light l alone in it (the others
// removed, so light l may stand at another index): to float rounding, for every method.
TEST_P(PerLight, EachLightsVisibilityIsTheSceneWithThatLightAlone) {
  Scene scene = load("showcase", 32, GetParam());
  scene.bake.samples = 8;
  set_setting(scene.bake, "shadow_map", 256);
  ASSERT_EQ(scene.lights.size(), 2u);
  const BakeResult all = bake_or_fail(scene, true);
  for (std::size_t l = 0; l < scene.lights.size(); ++l) {
    Scene alone = scene;
    alone.lights = {scene.lights[l]};
    expect_per_light_is(all, l, bake_or_fail(alone, false), 1e-6, scene.lights[l].name);
  }
}

// Keeping the per-light images changes nothing in the combined one.
TEST_P(PerLight, KeepingThemLeavesTheMixAlone) {
  Scene scene = load("showcase", 32, GetParam());
  scene.bake.samples = 8;
  set_setting(scene.bake, "shadow_map", 256);
  const BakeResult with = bake_or_fail(scene, true), without = bake_or_fail(scene, false);
  for (std::size_t r = 0; r < with.receivers.size(); ++r) {
    EXPECT_EQ(with.receivers[r].image.pixels, without.receivers[r].image.pixels);
    EXPECT_TRUE(without.receivers[r].per_light.empty());
  }
}

// Every method that bakes lights (ambient occlusion has none).
std::vector<std::string> lit_methods() {
  std::vector<std::string> out;
  for (const std::string& m : known_methods())
    if (m != "ambient-occlusion") out.push_back(m);
  return out;
}

INSTANTIATE_TEST_SUITE_P(EveryMethod, PerLight, ::testing::ValuesIn(lit_methods()),
                         [](const auto& info) {
                           std::string name = info.param;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

}  // namespace
}  // namespace sb
