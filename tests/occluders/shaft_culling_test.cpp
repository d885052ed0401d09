// Tests of ShaftCuller (shaft_culling.cpp): a texel it calls clear of a light has no blocker in
// any shadow ray towards that light, on the realistic corpus scenes (Blender exports: walls that
// cross the light's plane, lights flush with a ceiling or among columns, curved and non-convex
// receivers, a dense blocker) and on the closed-form parallel scene; and it calls clear most of
// what is lit, so that methods may skip it.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "core/sampling.h"
#include "occluders/ray_scene.h"
#include "occluders/shadow_rays.h"
#include "occluders/shaft_culling.h"
#include "pipeline/bake.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "scene/scene.h"
#include "support/built_scene.h"
#include "support/test_scenes.h"
#include "texels/texel_space.h"

namespace sb {
namespace {

struct Counts {
  std::int64_t lit = 0, clear = 0, wrong = 0;
};

// A corpus scene file, loaded.
Scene corpus_scene(const std::string& name) {
  auto scene = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/" + name);
  if (!scene) throw std::runtime_error(scene.error().message);
  return std::move(*scene);
}

// A corpus scene, and its parts as the bake builds them.
struct Loaded : test_scenes::Built {
  Scene scene;
  explicit Loaded(Scene loaded) : Built(loaded), scene(std::move(loaded)) {}
};

// Per light and receiver texel the light reaches: how many are clear, and how many of those a
// shadow ray (of `samples` stratified ones) finds blocked.
Counts check_scene(const std::string& name, int resolution, int samples) {
  const Loaded in(corpus_scene(name));
  const std::vector<Mesh>& meshes = in.meshes;
  const RayScene* rays = &*in.rays;
  const std::vector<Light>* lights = &in.lights;
  const ShaftCuller& culler = *in.culler;
  const double offset = rays->surface_offset();
  Counts counts;
  for (std::size_t r = 0; r < meshes.size(); ++r) {
    if (!in.scene.objects[r].receiver) continue;
    const TexelSpace space = rasterise_texels(meshes[r], resolution, resolution);
    for (std::size_t l = 0; l < lights->size(); ++l) {
      const Light& light = (*lights)[l];
      const std::vector<std::uint8_t> maybe = culler.maybe_blocked(space, light, offset);
      std::atomic<std::int64_t> lit{0}, clear{0}, wrong{0};
      tbb::parallel_for(std::size_t(0), space.texels.size(), [&](std::size_t i) {
        const Texel& t = space.texels[i];
        const Vec3 p = t.position.cast<double>(), n = t.normal.cast<double>();
        if (light.unoccluded_irradiance(p, n).maxCoeff() <= 0) return;
        ++lit;
        if (maybe[i]) return;
        ++clear;
        Rng rng(stream_seed(7, l, i));
        std::vector<Vec2> strata;
        stratified_samples(samples, rng, strata);
        ShadowRays batch(samples);
        const Vec3 origin = space.ray_origin(i, offset);
        for (const Vec2& u : strata) batch.add(origin, light.sample(p, n, u), offset);
        Vec3 v;
        if (batch.visible_fraction(*rays, &v) && v.minCoeff() < 1) ++wrong;
      });
      counts.lit += lit;
      counts.clear += clear;
      counts.wrong += wrong;
    }
  }
  return counts;
}

class ShaftCulling : public ::testing::TestWithParam<std::string> {};

TEST_P(ShaftCulling, ClearTexelsHaveNoBlockedRay) {
  const Counts c = check_scene(GetParam(), 128, 64);
  ASSERT_GT(c.lit, 0);
  EXPECT_EQ(c.wrong, 0) << c.wrong << " of " << c.clear << " clear texels have a blocked ray";
  // Most of what a light reaches in these scenes is clear of blockers.
  EXPECT_GT(double(c.clear) / double(c.lit), 0.3) << c.clear << " of " << c.lit;
  std::printf("%s: %lld of %lld lit (light, texel) pairs clear\n", GetParam().c_str(),
              (long long)c.clear, (long long)c.lit);
}

// A tile's candidates found among those of a box holding it (its group of tiles, as the
// backprojection bake asks) are some of those the whole hierarchy gives (the two boxes' tests are
// conservative each in its own way, so a triangle outside the tile's shaft may be in one list and
// not the other), and they hold every triangle in the shaft of any texel of the tile: what the
// bake's evaluations search among. Every tile of 8 × 8 texels in every group of 4 × 4, for every
// light of the scene.
TEST_P(ShaftCulling, TileCandidatesAmongALargerBoxsHoldTheirTexelsBlockers) {
  const Loaded in(corpus_scene(GetParam()));
  const double offset = in.rays->surface_offset();
  std::int64_t listed = 0, texels = 0;
  for (std::size_t r = 0; r < in.meshes.size(); ++r) {
    if (!in.scene.objects[r].receiver) continue;
    const TexelSpace space = rasterise_texels(in.meshes[r], 128, 128);
    constexpr int kTile = 8, kGroup = 4;
    const int tiles_x = 128 / kTile;
    std::vector<Bounds3> boxes(std::size_t(tiles_x * tiles_x));
    std::vector<std::vector<std::size_t>> texels_of(boxes.size());
    for (std::size_t i = 0; i < space.texels.size(); ++i) {
      const Texel& t = space.texels[i];
      const std::size_t tile = std::size_t(t.y / kTile * tiles_x + t.x / kTile);
      boxes[tile].extend(space.ray_origin(i, offset));
      texels_of[tile].push_back(i);
    }
    for (const Light& light : in.lights)
      for (int gy = 0; gy < tiles_x; gy += kGroup)
        for (int gx = 0; gx < tiles_x; gx += kGroup) {
          Bounds3 joint;
          for (int ty = gy; ty < gy + kGroup; ++ty)
            for (int tx = gx; tx < gx + kGroup; ++tx)
              if (!boxes[std::size_t(ty * tiles_x + tx)].empty())
                joint.extend(boxes[std::size_t(ty * tiles_x + tx)]);
          std::vector<std::uint32_t> group, own, among;
          if (joint.empty() || !in.culler->tile_candidates(joint, light, 1 << 16, group) ||
              group.empty())
            continue;
          for (int ty = gy; ty < gy + kGroup; ++ty)
            for (int tx = gx; tx < gx + kGroup; ++tx) {
              const std::size_t tile = std::size_t(ty * tiles_x + tx);
              if (boxes[tile].empty()) continue;
              const bool any = in.culler->tile_candidates(boxes[tile], light, 1 << 16, own);
              // Clear among the group's: no texel of the tile has a blocker (checked below).
              if (!in.culler->tile_candidates(boxes[tile], light, 1 << 16, among, &group))
                among.clear();
              EXPECT_TRUE(any || among.empty());
              std::sort(own.begin(), own.end());
              std::sort(among.begin(), among.end());
              EXPECT_TRUE(std::includes(own.begin(), own.end(), among.begin(), among.end()))
                  << "tile " << tx << ", " << ty;
              listed += !among.empty();
              std::vector<ShaftPolygon> polygons;
              for (std::size_t i : texels_of[tile]) {
                const Texel& t = space.texels[i];
                in.culler->shaft_polygons(space.ray_origin(i, offset), t.position.cast<double>(),
                                          t.normal.cast<double>(), light, nullptr, 1 << 16,
                                          polygons);
                ++texels;
                for (const ShaftPolygon& p : polygons)
                  EXPECT_TRUE(std::binary_search(among.begin(), among.end(), p.triangle))
                      << "texel " << t.x << ", " << t.y << ": triangle " << p.triangle;
              }
            }
        }
  }
  EXPECT_GT(listed, 0) << "no tile listed candidates";
  std::printf("%lld texels of %lld listed tiles checked\n", (long long)texels, (long long)listed);
}

INSTANTIATE_TEST_SUITE_P(Corpus, ShaftCulling,
                         ::testing::Values("room/scene.toml", "room/scene_disk.toml",
                                           "atrium/scene_sconce.toml", "atrium/scene_bulb.toml",
                                           "shelf/scene.toml", "dense/scene.toml",
                                           "showcase/scene.toml", "parallel/scene.toml"),
                         [](const auto& info) {
                           std::string n = info.param;
                           for (char& ch : n)
                             if (ch == '/' || ch == '.') ch = '_';
                           return n;
                         });

}  // namespace
}  // namespace sb

namespace sb {
namespace {

// The convolution method without its convolution (convolve = false): the shaft test's clear
// pairs are V = 1 and every other pair takes the reference's own estimate, so the bake is the
// reference's, texel for texel, on a scene with two lights and contact.
TEST(ShaftCullingBake, WithoutConvolutionEqualsTheReference) {
  Scene reference = test_scenes::load("showcase", 64, "reference");
  reference.bake.samples = 16;
  Scene shaft = reference;
  shaft.bake.method = "convolution";
  set_setting(shaft.bake, "trace", true);
  set_setting(shaft.bake, "convolve", false);
  auto a = bake(reference);
  auto b = bake(shaft);
  ASSERT_TRUE(a) << a.error().message;
  ASSERT_TRUE(b) << b.error().message;
  ASSERT_EQ(a->receivers.size(), b->receivers.size());
  for (std::size_t r = 0; r < a->receivers.size(); ++r) {
    const Image& x = a->receivers[r].image;
    const Image& y = b->receivers[r].image;
    ASSERT_EQ(x.pixels.size(), y.pixels.size());
    double worst = 0;
    for (std::size_t i = 0; i < x.pixels.size(); ++i)
      worst = std::max(worst, double(std::abs(x.pixels[i] - y.pixels[i])));
    EXPECT_LT(worst, 1e-5) << a->receivers[r].name;
  }
  EXPECT_LT(b->shadow_rays, a->shadow_rays);  // the clear pairs took none

  set_setting(shaft.bake, "trace", false);
  auto neither = bake(shaft);
  ASSERT_FALSE(neither);
  EXPECT_NE(neither.error().message.find("convolve = false needs trace = true"), std::string::npos)
      << neither.error().message;
}

}  // namespace
}  // namespace sb
