// Lights with a reach (LightDesc::range) and the lists that cull by it (light_lists.h): every
// light that reaches a texel is on its block's list; a light beyond every texel changes no byte
// of any method's bake; and the default method and the reference agree on ranged lights, which
// every method takes by one light model.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "core/sampling.h"
#include "methods/light_lists.h"
#include "pipeline/bake.h"
#include "support/built_scene.h"
#include "support/image_errors.h"
#include "support/test_scenes.h"
#include "texels/texel_space.h"

namespace sb {
namespace {

// The hall (scenes/hall) with `extra` sphere lights scattered through it, each with a range of
// 1–4 m, and its own lights given ranges too.
Scene hall_with_ranged_lights(int extra, int resolution, const std::string& method) {
  Scene scene = test_scenes::load("hall", resolution, method);
  Rng rng(3);
  for (LightDesc& l : scene.lights)
    if (l.sun_angle_deg == 0) l.range = 2 + 4 * rng.next_double();
  for (int k = 0; k < extra; ++k) {
    LightDesc l;
    l.name = "extra" + std::to_string(k);
    l.shape = LightShape::sphere;
    l.position = Vec3(-4.5 + 9 * rng.next_double(), -2.5 + 5 * rng.next_double(),
                      0.2 + 3 * rng.next_double());
    l.radius = 0.05 + 0.1 * rng.next_double();
    l.power = 50;
    l.range = 1 + 3 * rng.next_double();
    scene.lights.push_back(l);
  }
  return scene;
}

// Every (texel, light) pair the light reaches is on the texel's block's list, and each light's
// blocks are the blocks whose lists name it; ranges leave most pairs off the lists.
TEST(LightLists, EveryLightThatReachesATexelIsOnItsBlocksList) {
  const Scene scene = hall_with_ranged_lights(40, 128, "backprojection");
  const test_scenes::Built built(scene);
  std::size_t pairs = 0, listed = 0;
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    if (!scene.objects[o].receiver) continue;
    const TexelSpace space = rasterise_texels(built.meshes[o], 128, 128);
    const LightLists lists(space, built.lights);
    for (const Texel& t : space.texels) {
      const auto on = lists.lights_of(lists.block_of(t.x, t.y));
      for (std::size_t l = 0; l < built.lights.size(); ++l) {
        if (!built.lights[l].reaches(t.position.cast<double>(), t.normal.cast<double>())) continue;
        ++pairs;
        EXPECT_TRUE(std::binary_search(on.begin(), on.end(), std::uint32_t(l)))
            << scene.objects[o].name << " texel (" << t.x << ", " << t.y << ") light "
            << built.lights[l].desc().name;
      }
    }
    for (std::size_t l = 0; l < built.lights.size(); ++l)
      for (const std::uint32_t b : lists.blocks_of(l)) {
        const auto on = lists.lights_of(b);
        EXPECT_TRUE(std::binary_search(on.begin(), on.end(), std::uint32_t(l)));
      }
    listed += lists.pairs() * std::size_t(LightLists::kSide * LightLists::kSide);
  }
  const std::size_t every = [&] {
    std::size_t texels = 0;
    for (std::size_t o = 0; o < scene.objects.size(); ++o)
      if (scene.objects[o].receiver)
        texels += rasterise_texels(built.meshes[o], 128, 128).texels.size();
    return texels * built.lights.size();
  }();
  std::printf(
      "hall with 49 ranged lights at 128²: %zu pairs reached, %zu texel slots listed, of "
      "%zu (texels × lights)\n",
      pairs, listed, every);
  EXPECT_GT(pairs, 0u);
  EXPECT_LT(listed, every / 3) << "the ranges must leave most pairs off the lists";
}

// A light whose range ends before any texel adds nothing anywhere: each method's images equal,
// byte for byte, those of the scene without it.
TEST(LightLists, ALightBeyondEveryTexelChangesNothing) {
  for (const std::string method : {"backprojection", "reference"}) {
    Scene without = test_scenes::load("hall", 64, method);
    without.bake.samples = 16;
    Scene with = without;
    LightDesc far = test_scenes::sphere_light("far", Vec3(40, 40, 40), 0.2, 1e6);
    far.range = 5;
    with.lights.insert(with.lights.begin() + 2, far);
    auto a = bake(without), b = bake(with);
    ASSERT_TRUE(a && b);
    for (std::size_t r = 0; r < a->receivers.size(); ++r)
      EXPECT_EQ(a->receivers[r].image.pixels, b->receivers[r].image.pixels)
          << method << " " << a->receivers[r].name;
  }
}

// With ranges, the default method and the reference at 1024 samples bake the same visibility
// (the reference's noise apart): one light model, windows and all.
TEST(LightLists, DefaultAndReferenceAgreeOnRangedLights) {
  Scene ours = hall_with_ranged_lights(12, 64, "backprojection");
  Scene truth = ours;
  truth.bake.method = "reference";
  truth.bake.samples = 1024;
  auto a = bake(ours), b = bake(truth);
  ASSERT_TRUE(a && b);
  const image_errors::Errors e = image_errors::errors(*a, *b);
  std::printf("hall with 21 ranged lights at 64²: RMSE %.4f against the reference at 1024\n",
              e.rmse);
  EXPECT_LT(e.rmse, 0.01);
}

}  // namespace
}  // namespace sb
