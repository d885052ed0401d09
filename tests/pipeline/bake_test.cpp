// The whole pipeline (scene file → import → texel space → reference → dilation) on the bundled
// parallel-plane scene, against its closed form texel by texel; with the blocker moved off-centre
// so a flipped or transposed lightmap cannot pass.
#include <gtest/gtest.h>

#include <chrono>

#include <cmath>

#include "pipeline/bake.h"
#include "support/closed_forms.h"
#include "support/image_errors.h"

namespace sb {
namespace {

Scene parallel_scene(int resolution, int samples) {
  auto scene = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/parallel/scene.toml");
  EXPECT_TRUE(scene) << scene.error().message;
  scene->bake.resolution = resolution;
  scene->bake.samples = samples;
  scene->bake.margin = 0;
  return *scene;
}

TEST(Bake, ParallelSceneMatchesClosedFormWithOffsetBlocker) {
  Scene scene = parallel_scene(32, 256);
  const double bx = 0.15, by = 0.3;  // blocker centre; the umbra moves to 1.5 × that
  for (auto& obj : scene.objects)
    if (obj.name == "blocker") obj.transform = Affine3(Eigen::Translation3d(bx, by, 0));
  auto result = bake(scene);
  ASSERT_TRUE(result) << result.error().message;
  ASSERT_EQ(result->receivers.size(), 1u);
  const Image& img = result->receivers[0].image;
  ASSERT_EQ(img.width, 32);
  const image_errors::Errors e = image_errors::errors_against(img, 0, [&](int x, int y) {
    // The floor's UVs are u = (x + 1)/2, v = (y + 1)/2; row 0 is v = 1.
    const double u = (x + 0.5) / img.width, v = 1.0 - (y + 0.5) / img.height;
    return closed_forms::parallel_weighted_visibility(2 * u - 1, 2 * v - 1, bx, by, 600);
  });
  const double rmse = e.rmse, max_err = e.max;
  EXPECT_LT(rmse, 0.005);
  EXPECT_LT(max_err, 0.04);
  RecordProperty("rmse", std::to_string(rmse));
  RecordProperty("max_error", std::to_string(max_err));
  // The umbra is in the upper half of the image (v > 0.5) and the right half (u > 0.5).
  EXPECT_EQ(img.at(20, 9)[0], 0.0f);
}

// The times are the stages' own: each positive, the receiver's within the bake's, the bake's
// within the call's wall time.
TEST(Bake, ReportsRaysAndTimes) {
  Scene scene = parallel_scene(16, 16);
  const auto start = std::chrono::steady_clock::now();
  auto result = bake(scene);
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(result) << result.error().message;
  EXPECT_GT(result->shadow_rays, 0);
  const ReceiverBake& r = result->receivers[0];
  EXPECT_EQ(r.covered_texels, 16 * 16);
  EXPECT_GT(r.seconds_method, 0.0);
  EXPECT_GE(r.seconds, r.seconds_texels + r.seconds_method);
  EXPECT_GE(result->bake_seconds, r.seconds);
  EXPECT_GT(result->load_seconds, 0.0);
  EXPECT_LE(result->load_seconds + result->bake_seconds, wall);
}

// Ambient occlusion through the whole pipeline, with the scene's light taken away: at the floor's
// centre, under the 0.6 m square blocker 0.5 m up, the occluded fraction is the square's form
// factor, four corner rectangles of X = Y = 0.3 / 0.5 each F = (1/π)·X/√(1+X²)·atan(Y/√(1+X²)).
TEST(Bake, AmbientOcclusionNeedsNoLightAndMatchesTheFormFactor) {
  Scene scene = parallel_scene(32, 1024);
  scene.lights.clear();
  scene.bake.quantity = Quantity::ambient_occlusion;
  auto mismatched = bake(scene);
  ASSERT_FALSE(mismatched);
  EXPECT_NE(mismatched.error().message.find("do not go together"), std::string::npos);
  scene.bake.method = "ambient-occlusion";
  auto result = bake(scene);
  ASSERT_TRUE(result) << result.error().message;
  const Image& img = result->receivers[0].image;
  const double x = 0.6, k = x / std::sqrt(1 + x * x);
  const double expected = 1 - 4 * k * std::atan(k) / M_PI;
  double centre = 0;
  for (int y = 15; y <= 16; ++y)
    for (int xx = 15; xx <= 16; ++xx) centre += img.at(xx, y)[0] / 4.0;
  EXPECT_NEAR(centre, expected, 0.02);
  EXPECT_GT(img.at(0, 0)[0], centre);  // a corner of the floor sees more of the sky
  EXPECT_TRUE(result->warnings.empty()) << result->warnings.front();
  // Per-light images have no light to be of.
  scene.output.per_light = true;
  auto per_light = bake(scene);
  ASSERT_FALSE(per_light);
  EXPECT_NE(per_light.error().message.find("[output]"), std::string::npos);
}

TEST(Bake, UnknownMethodIsAnError) {
  Scene scene = parallel_scene(16, 16);
  scene.bake.method = "nonsense";
  auto result = bake(scene);
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("nonsense"), std::string::npos);
  EXPECT_NE(result.error().message.find("scene.toml"), std::string::npos);
}

// A [bake] key the chosen method does not read is reported with its line and the methods that
// read it; keys every bake reads (the lightmap's size, margin and seams too) and keys the method
// reads are not.
TEST(Bake, ReportsSettingsTheMethodIgnores) {
  Scene scene = parallel_scene(16, 16);
  scene.bake.method = "pcf";
  scene.bake_keys = {{"samples", 7},          {"resolution", 5}, {"shadow_map", 9},
                     {"texels_per_metre", 6}, {"seams", 10},     {"margin", 11}};
  auto result = bake(scene);
  ASSERT_TRUE(result) << result.error().message;
  std::vector<std::string> ignored;
  for (const auto& w : result->warnings)
    if (w.find("does not use it") != std::string::npos) ignored.push_back(w);
  ASSERT_EQ(ignored.size(), 1u);
  EXPECT_NE(ignored[0].find("scene.toml:7: [bake] samples: method 'pcf' does not use it (read by "
                            "backprojection, convolution, accumulation, adaptive-pcf, reference, "
                            "ambient-occlusion)"),
            std::string::npos)
      << ignored[0];
  scene.bake.method = "reference";
  result = bake(scene);
  ASSERT_TRUE(result) << result.error().message;
  ignored.clear();
  for (const auto& w : result->warnings)
    if (w.find("does not use it") != std::string::npos) ignored.push_back(w);
  ASSERT_EQ(ignored.size(), 1u);
  EXPECT_NE(ignored[0].find("[bake] shadow_map: method 'reference' does not use it"),
            std::string::npos)
      << ignored[0];
}

}  // namespace
}  // namespace sb
