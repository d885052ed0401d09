// The whole pipeline (scene file → import → texel space → reference → dilation) on the bundled
// parallel-plane scene, against its closed form texel by texel; with the blocker moved off-centre
// so a flipped or transposed lightmap cannot pass.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "pipeline/bake.h"
#include "support/closed_forms.h"
#include "support/image_errors.h"
#include "support/test_scenes.h"

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

namespace sb {
namespace {

// The parallel scene with `lights` added, each a small sphere at the given place.
Scene with_bulbs(const std::vector<Vec3>& places) {
  Scene scene = parallel_scene(16, 16);
  for (std::size_t k = 0; k < places.size(); ++k) {
    LightDesc bulb;
    bulb.name = "bulb" + std::to_string(k);
    bulb.shape = LightShape::sphere;
    bulb.position = places[k];
    bulb.radius = 0.01;
    bulb.power = 10;
    bulb.line = int(100 + k);
    scene.lights.push_back(bulb);
  }
  return scene;
}

bool has_warning(const BakeResult& r, const std::string& text) {
  return std::any_of(r.warnings.begin(), r.warnings.end(),
                     [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

// A light inside a closed blocker (a cube over the parallel scene's floor) reaches nothing, in
// every method: a warning names it, and the bake is that of the scene without it.
TEST(Bake, ALightInsideSolidGeometryReachesNothing) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("sb_enclosed_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  // A 0.4 m cube centred at (0.3, 0.2, 0.9), above the scene's blocker, its faces
  // counter-clockwise seen from outside.
  std::ofstream(dir / "cube.obj") << "v 0.1 0 0.7\nv 0.5 0 0.7\nv 0.5 0.4 0.7\nv 0.1 0.4 0.7\n"
                                     "v 0.1 0 1.1\nv 0.5 0 1.1\nv 0.5 0.4 1.1\nv 0.1 0.4 1.1\n"
                                     "f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\n"
                                     "f 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";
  for (const std::string method : {"backprojection", "reference"}) {
    Scene without = parallel_scene(16, 16);
    without.bake.method = method;
    ObjectDesc cube;
    cube.name = "cube";
    cube.mesh = dir / "cube.obj";
    cube.receiver = false;
    without.objects.push_back(cube);
    Scene with = without;
    with.lights.push_back(test_scenes::sphere_light("bulb", Vec3(0.3, 0.2, 0.9), 0.05, 10));
    auto a = bake(without), b = bake(with);
    ASSERT_TRUE(a && b) << (a ? b.error().message : a.error().message);
    EXPECT_TRUE(has_warning(*b, "light 'bulb': its centre lies inside solid geometry")) << method;
    EXPECT_FALSE(has_warning(*a, "inside solid geometry")) << method;
    EXPECT_EQ(a->receivers[0].image.pixels, b->receivers[0].image.pixels) << method;
  }
  std::filesystem::remove_all(dir);
}

// Many lights that reach nothing are one warning naming the first five; where no light reaches
// any receiver, a warning says the lightmaps are black.
TEST(Bake, ManyLightsThatReachNothingAreOneWarning) {
  std::vector<Vec3> below;
  for (int k = 0; k < 8; ++k) below.push_back(Vec3(0.1 * k, 0, -5));  // under the floor
  auto some = bake(with_bulbs(below));
  ASSERT_TRUE(some) << some.error().message;
  EXPECT_TRUE(has_warning(*some, "8 lights reach no texel of any receiver"));
  EXPECT_TRUE(has_warning(*some, "'bulb0', 'bulb1', 'bulb2', 'bulb3', 'bulb4' and 3 more"));
  EXPECT_FALSE(has_warning(*some, "every lightmap is black"));
  Scene none = with_bulbs({Vec3(0, 0, -5)});
  none.lights.erase(none.lights.begin());  // the panel: only the bulb under the floor is left
  auto dark = bake(none);
  ASSERT_TRUE(dark) << dark.error().message;
  EXPECT_TRUE(has_warning(*dark, "light 'bulb0': reaches no texel of any receiver"));
  EXPECT_TRUE(has_warning(*dark, "none of the scene's 1 light(s) reaches any receiver"));
}

}  // namespace
}  // namespace sb
