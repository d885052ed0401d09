// Stress test of the convolution method against the reference on seeded random scenes
// (tests/support/random_scenes.h): per receiver, its RMSE against the reference at 512 samples
// (covered texels) must not exceed the reference's own at 64 samples (with rays where the
// convolution cannot vouch for its values). The default suite runs 8 scenes; `ctest -L stress` runs
// 50 (RandomScenesStress) and also requires the convolution without any ray to be within the
// reference at 16 samples, the goal for it, which it does not meet on every scene today
// (docs/performance.md).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "pipeline/bake.h"
#include "scene/scene.h"
#include "support/image_errors.h"
#include "support/method_bakes.h"
#include "support/random_scenes.h"

namespace sb {
namespace {

namespace fs = std::filesystem;

// Over the texels `a` covers, every channel.
double rmse(const ReceiverBake& a, const ReceiverBake& truth) {
  return image_errors::errors(a, truth).rmse;
}

// `alone`: also require the convolution without rays to be within the reference at 16 samples.
void check_seed(std::uint32_t seed, bool alone_too) {
  const fs::path dir =
      fs::temp_directory_path() /
      ("shadowbake_random_" + std::to_string(::getpid()) + "_" + std::to_string(seed));
  const fs::path file = random_scenes::write_random_scene(seed, dir, 64);
  auto scene = load_scene(file);
  ASSERT_TRUE(scene) << scene.error().message;
  const BakeResult truth = bake_with(*scene, "reference", 512, false, 12345);
  const BakeResult ref16 = bake_with(*scene, "reference", 16, false);
  const BakeResult ref64 = bake_with(*scene, "reference", 64, false);
  const BakeResult conv = bake_with(*scene, "convolution", 64, true);
  const BakeResult alone = bake_with(*scene, "convolution", 64, false);
  ASSERT_EQ(conv.receivers.size(), truth.receivers.size());
  for (std::size_t r = 0; r < truth.receivers.size(); ++r) {
    const double e16 = rmse(ref16.receivers[r], truth.receivers[r]);
    const double e64 = rmse(ref64.receivers[r], truth.receivers[r]);
    const double ec = rmse(conv.receivers[r], truth.receivers[r]);
    const double ea = rmse(alone.receivers[r], truth.receivers[r]);
    std::printf("seed %u %-8s ref16 %.4f ref64 %.4f convolution %.4f alone %.4f\n", seed,
                truth.receivers[r].name.c_str(), e16, e64, ec, ea);
    // A few texels' worth of slack: both are measured against a noisy truth.
    EXPECT_LE(ec, e64 * 1.05 + 5e-4) << "seed " << seed << " " << truth.receivers[r].name;
    if (alone_too) {
      EXPECT_LE(ea, e16 * 1.05 + 5e-4) << "seed " << seed << " " << truth.receivers[r].name;
    }
  }
  fs::remove_all(dir);
}

class RandomScenes : public ::testing::TestWithParam<int> {};
TEST_P(RandomScenes, ConvolutionIsAsAccurateAsTheRaysItReplaces) {
  check_seed(std::uint32_t(GetParam()), false);
}
INSTANTIATE_TEST_SUITE_P(Seeds, RandomScenes, ::testing::Range(1, 9));

class RandomScenesStress : public ::testing::TestWithParam<int> {};
TEST_P(RandomScenesStress, ConvolutionIsAsAccurateAsTheRaysItReplaces) {
  check_seed(std::uint32_t(GetParam()), true);
}
INSTANTIATE_TEST_SUITE_P(Seeds, RandomScenesStress, ::testing::Range(1, 51));

}  // namespace
}  // namespace sb
