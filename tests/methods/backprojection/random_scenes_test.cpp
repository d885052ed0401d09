// Stress test of the default method, backprojection, on seeded random scenes
// (tests/support/random_scenes.h): per receiver, its RMSE against the reference at 2048 samples
// (covered texels) must not exceed the reference's own at 256 samples. The default suite runs 8
// scenes; `ctest -L stress` runs 50 (BackprojectionRandomScenesStress, with the convolution's).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <string>

#include "pipeline/bake.h"
#include "scene/scene.h"
#include "support/image_errors.h"
#include "support/method_bakes.h"
#include "support/random_scenes.h"

namespace sb {
namespace {

namespace fs = std::filesystem;

void check_seed(std::uint32_t seed) {
  const fs::path dir =
      fs::temp_directory_path() /
      ("shadowbake_random_bp_" + std::to_string(::getpid()) + "_" + std::to_string(seed));
  const fs::path file = random_scenes::write_random_scene(seed, dir, 64);
  auto scene = load_scene(file);
  ASSERT_TRUE(scene) << scene.error().message;
  const BakeResult truth = bake_with(*scene, "reference", 2048, true, 12345);
  const BakeResult ref256 = bake_with(*scene, "reference", 256, true);
  const BakeResult ours = bake_with(*scene, "backprojection", 256, true);
  ASSERT_EQ(ours.receivers.size(), truth.receivers.size());
  for (std::size_t r = 0; r < truth.receivers.size(); ++r) {
    const double e256 = image_errors::errors(ref256.receivers[r], truth.receivers[r]).rmse;
    const double e = image_errors::errors(ours.receivers[r], truth.receivers[r]).rmse;
    std::printf("seed %u %-8s reference-256 %.4f backprojection %.4f\n", seed,
                truth.receivers[r].name.c_str(), e256, e);
    // A few texels' worth of slack: both are measured against a truth with its own noise.
    EXPECT_LE(e, e256 * 1.05 + 2e-4) << "seed " << seed << " " << truth.receivers[r].name;
  }
  fs::remove_all(dir);
}

class BackprojectionRandomScenes : public ::testing::TestWithParam<int> {};
TEST_P(BackprojectionRandomScenes, AsAccurateAsTheReferenceAt256Samples) {
  check_seed(std::uint32_t(GetParam()));
}
INSTANTIATE_TEST_SUITE_P(Seeds, BackprojectionRandomScenes, ::testing::Range(1, 9));

class BackprojectionRandomScenesStress : public ::testing::TestWithParam<int> {};
TEST_P(BackprojectionRandomScenesStress, AsAccurateAsTheReferenceAt256Samples) {
  check_seed(std::uint32_t(GetParam()));
}
INSTANTIATE_TEST_SUITE_P(Seeds, BackprojectionRandomScenesStress, ::testing::Range(1, 51));

}  // namespace
}  // namespace sb
