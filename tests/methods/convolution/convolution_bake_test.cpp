// The convolution method (Soler & Sillion) against closed forms in the exact parallel case,
// against the ray-traced reference elsewhere, and for a coloured light.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>

#include "core/image_io.h"
#include "methods/convolution/pair_report.h"
#include "pipeline/bake.h"
#include "support/closed_forms.h"
#include "support/image_errors.h"
#include "support/test_scenes.h"

namespace sb {
namespace {

using test_scenes::load;
using test_scenes::object;

Image bake_floor(const Scene& scene, std::vector<PairReport>* pairs = nullptr) {
  auto result = bake(scene);
  EXPECT_TRUE(result) << result.error().message;
  if (pairs) *pairs = convolution_pairs(result->receivers[0].report.details);
  return result->receivers[0].image;
}

using image_errors::Errors;

// Error of channel `c` of a floor image (UV (u, v) = ((x + 1)/2, (y + 1)/2)) against expected(x,
// y), over every `stride`-th texel.
Errors floor_errors(const Image& img, int c, const std::function<double(double, double)>& expected,
                    int stride = 1) {
  return image_errors::errors_against(
      img, c,
      [&](int i, int j) {
        return expected(2 * (i + 0.5) / img.width - 1, 1 - 2 * (j + 0.5) / img.height);
      },
      stride);
}

// Channel `c` of `a` against `b`, over every texel.
Errors image_errors(const Image& a, const Image& b, int c = 0) {
  return image_errors::errors(a, b, {}, {.channel = c});
}

// Exact case (docs/design.md §2): a square light, a parallel square blocker, at three distance
// ratios and off-centre; 512². With weighting = "emission" the bake computes V_u, which the
// convolution gets exactly: against its closed form within 0.002 RMSE (pixel-scale rasterising
// only). The default irradiance weighting (docs/design.md §6) is first order across the light: its
// V = H/H0 against the exact closed form, within 0.004 RMSE (the second-order remainder grows
// with the penumbra, largest with the blocker nearest the light).
TEST(ConvolutionBake, ParallelSquareLightMatchesClosedForm) {
  for (const double height : {0.25, 0.5, 1.0}) {
    Scene scene = load("parallel", 512, "convolution");
    const double bx = 0.1, by = -0.05;
    object(scene, "blocker").transform = Affine3(Eigen::Translation3d(bx, by, height - 0.5));
    const Errors weighted = floor_errors(bake_floor(scene), 0, [&](double x, double y) {
      return closed_forms::square_light_weighted_visibility(x, y, bx, by, height);
    });
    set_setting(scene.bake, "weighting", "emission");
    const Errors e = floor_errors(bake_floor(scene), 0, [&](double x, double y) {
      return closed_forms::square_light_unweighted_visibility(x, y, bx, by, height);
    });
    EXPECT_LE(e.rmse, 0.002) << "blocker at " << height;
    EXPECT_LE(e.max, 0.02) << "blocker at " << height;
    EXPECT_LE(weighted.rmse, 0.004) << "blocker at " << height;
    EXPECT_LE(weighted.max, 0.02) << "blocker at " << height;
    RecordProperty("rmse_h" + std::to_string(height), std::to_string(e.rmse));
    RecordProperty("max_h" + std::to_string(height), std::to_string(e.max));
    std::printf("square light, blocker at %.2f m: V_u RMSE %.5f, max %.5f; V RMSE %.5f, max %.5f\n",
                height, e.rmse, e.max, weighted.rmse, weighted.max);
  }
}

TEST(ConvolutionBake, ParallelDiskLightMatchesClosedForm) {
  for (const double height : {0.5, 1.0}) {
    Scene scene = load("disk", 512, "convolution");
    object(scene, "blocker").transform = Affine3(Eigen::Translation3d(0, 0, height - 0.5));
    const Errors weighted = floor_errors(
        bake_floor(scene), 0,
        [&](double x, double y) {
          return closed_forms::disk_light_weighted_visibility(x, y, 0, 0, height, 0.25);
        },
        4);
    set_setting(scene.bake, "weighting", "emission");
    const Errors e = floor_errors(
        bake_floor(scene), 0,
        [&](double x, double y) {
          return closed_forms::disk_light_unweighted_visibility(x, y, 0, 0, height, 0.25);
        },
        4);
    EXPECT_LE(e.rmse, 0.002) << "blocker at " << height;
    EXPECT_LE(e.max, 0.02) << "blocker at " << height;
    EXPECT_LE(weighted.rmse, 0.004) << "blocker at " << height;
    EXPECT_LE(weighted.max, 0.02) << "blocker at " << height;
    std::printf("disk light, blocker at %.2f m: V_u RMSE %.5f, max %.5f; V RMSE %.5f, max %.5f\n",
                height, e.rmse, e.max, weighted.rmse, weighted.max);
  }
}

// Against the reference, the emission-weighted convolution (V_u) differs by the V_u / V split of
// docs/design.md §1 (plus the reference's own noise), and by no more; the default irradiance
// weighting removes most of the split.
TEST(ConvolutionBake, AgreesWithReferenceWithinTheWeightingSplit) {
  Scene conv = load("parallel", 256, "convolution");
  Scene ref = load("parallel", 256, "reference");
  ref.bake.samples = 256;
  const Image weighted = bake_floor(conv);
  set_setting(conv.bake, "weighting", "emission");
  const Image c = bake_floor(conv), r = bake_floor(ref);
  const Errors against_reference = image_errors(c, r);
  const Errors weighted_against_reference = image_errors(weighted, r);
  // The split alone: V_u against V = H/H0, both in closed form, on the same texels.
  const Errors split = floor_errors(
      c, 0,
      [](double x, double y) {
        return closed_forms::parallel_unweighted_visibility(x, y) -
               closed_forms::parallel_weighted_visibility(x, y, 0, 0, 300) +
               closed_forms::parallel_unweighted_visibility(x, y);
      },
      4);
  // (floor_errors of "2 V_u − V" against the convolution's ≈ V_u is |V_u − V|.)
  const Errors conv_exact = floor_errors(
      c, 0, [](double x, double y) { return closed_forms::parallel_unweighted_visibility(x, y); },
      4);
  const Errors ref_exact = floor_errors(
      r, 0,
      [](double x, double y) {
        return closed_forms::parallel_weighted_visibility(x, y, 0, 0, 300);
      },
      4);
  std::printf("convolution vs V_u %.4f (max %.4f), reference vs V %.4f (max %.4f)\n",
              conv_exact.rmse, conv_exact.max, ref_exact.rmse, ref_exact.max);
  std::printf(
      "emission-weighted convolution vs reference RMSE %.4f (max %.4f); V_u vs V RMSE "
      "%.4f (max %.4f); irradiance-weighted convolution vs reference RMSE %.4f (max %.4f)\n",
      against_reference.rmse, against_reference.max, split.rmse, split.max,
      weighted_against_reference.rmse, weighted_against_reference.max);
  EXPECT_LE(against_reference.rmse, split.rmse + conv_exact.rmse + ref_exact.rmse);
  EXPECT_GE(against_reference.rmse, 0.5 * split.rmse);            // the split is really there
  EXPECT_LE(weighted_against_reference.rmse, 0.25 * split.rmse);  // and the weighting removes it
}

// A receiver that is also a blocker does not shadow itself through the convolution.
TEST(ConvolutionBake, ReceiverDoesNotShadowItself) {
  Scene scene = load("parallel", 64, "convolution");
  const Image without = bake_floor(scene);
  object(scene, "floor").blocker = true;
  const Image with = bake_floor(scene);
  EXPECT_EQ(without.pixels, with.pixels);
}

TEST(ConvolutionBake, ReportsConfiguration) {
  Scene scene = load("parallel", 128, "convolution");
  std::vector<PairReport> pairs;
  bake_floor(scene, &pairs);
  ASSERT_EQ(pairs.size(), 1u);
  const PairReport& p = pairs[0];
  EXPECT_NEAR(p.blocker_plane, 1.0, 1e-9);   // light at 1.5, blocker at 0.5
  EXPECT_NEAR(p.receiver_plane, 1.5, 1e-9);  // floor at 0
  EXPECT_NEAR(p.rho, 1.5, 1e-9);
  EXPECT_NEAR(p.penumbra_error, 0.0, 1e-9);  // exact: every depth is one plane
  EXPECT_NEAR(p.axis[2], -1.0, 1e-9);
  EXPECT_EQ(p.kernel_width % 2, 1);
  EXPECT_GE(p.fft_width, p.image_width);
}

// Tilted blocker and off-axis light: the error against the reference, and the metric's
// predicted penumbra-width error beside the measured one. The measured one: along the row
// through the shadow's middle, the width of each 10%–90% transition, scaled to the whole
// penumbra (÷ 0.8, exact for a square light's linear ramp), convolution against reference.
struct Transition {
  double lo = 0, hi = 0;  // metres along x where V crosses 0.1 and 0.9
};
std::vector<double> transition_widths(const Image& img, int row) {
  std::vector<double> widths;
  const double texel = 2.0 / img.width;
  auto v = [&](int i) { return double(img.at(i, row)[0]); };
  // Walk the row and measure each monotone run from below 0.1 to above 0.9 or back.
  int i = 0;
  while (i + 1 < img.width) {
    if ((v(i) <= 0.1 && v(i + 1) > 0.1) || (v(i) >= 0.9 && v(i + 1) < 0.9)) {
      const bool rising = v(i) <= 0.1;
      const double from = rising ? 0.1 : 0.9, to = rising ? 0.9 : 0.1;
      auto crossing = [&](int k, double level) {
        return (k + (level - v(k)) / (v(k + 1) - v(k))) * texel;
      };
      const double start = crossing(i, from);
      int k = i + 1;
      while (k + 1 < img.width && (rising ? v(k + 1) < to : v(k + 1) > to)) ++k;
      if (k + 1 >= img.width) break;
      widths.push_back((crossing(k, to) - start) / 0.8);
      i = k + 1;
    } else {
      ++i;
    }
  }
  return widths;
}

void general_case(const char* label, Scene conv, Scene ref, double max_rmse) {
  ref.bake.samples = 256;
  std::vector<PairReport> pairs;
  const Image c = bake_floor(conv, &pairs), r = bake_floor(ref);
  const Errors e = image_errors(c, r);
  const auto wc = transition_widths(c, c.height / 2), wr = transition_widths(r, r.height / 2);
  // The shadow's two edges on the middle row, in both bakes: with none found, the width check
  // below would hold for nothing.
  EXPECT_GE(wc.size(), 2u);
  EXPECT_EQ(wc.size(), wr.size());
  double measured = 0;
  for (std::size_t k = 0; k < std::min(wc.size(), wr.size()); ++k)
    measured = std::max(measured, std::abs(wc[k] - wr[k]));
  ASSERT_FALSE(pairs.empty());
  std::printf(
      "%s: RMSE vs reference %.4f, max %.4f; penumbra error predicted %.4f m, measured %.4f m "
      "(%zu edges)\n",
      label, e.rmse, e.max, pairs[0].penumbra_error, measured, std::min(wc.size(), wr.size()));
  ::testing::Test::RecordProperty(std::string(label) + "_rmse", std::to_string(e.rmse));
  ::testing::Test::RecordProperty(std::string(label) + "_predicted",
                                  std::to_string(pairs[0].penumbra_error));
  ::testing::Test::RecordProperty(std::string(label) + "_measured", std::to_string(measured));
  EXPECT_LE(e.rmse, max_rmse);
  EXPECT_GT(pairs[0].penumbra_error, 0.0);
  // The metric bounds the width error, up to two texels of measurement.
  EXPECT_LE(measured, pairs[0].penumbra_error + 2 * 2.0 / c.width);
}

TEST(ConvolutionBake, TiltedBlockerAgainstReference) {
  Scene conv = load("parallel", 128, "convolution"), ref = load("parallel", 128, "reference");
  // Tilted 30° about y through its centre: its edges at x = ±0.26 sit 0.15 m apart in height.
  const Affine3 tilt = Affine3(Eigen::Translation3d(0, 0, 0.5)) *
                       Eigen::AngleAxisd(30 * 3.14159265358979 / 180, Vec3::UnitY()) *
                       Affine3(Eigen::Translation3d(0, 0, -0.5));
  object(conv, "blocker").transform = tilt;
  object(ref, "blocker").transform = tilt;
  // ε is 10 texels here: the single blocker plane's error, which blocker subdivision removes.
  general_case("tilted blocker", conv, ref, 0.06);
}

TEST(ConvolutionBake, OffAxisLightAgainstReference) {
  Scene conv = load("parallel", 128, "convolution"), ref = load("parallel", 128, "reference");
  for (Scene* s : {&conv, &ref}) {
    s->lights[0].position = Vec3(-0.6, 0.0, 1.5);
    s->lights[0].normal = Vec3(0.5, 0, -1.5).normalized();
    s->lights[0].up = Vec3(0, 1, 0);
  }
  general_case("off-axis light", conv, ref, 0.03);
}

// A rectangle light, red on its left half and blue on its right, behind the blocker: the
// penumbrae are coloured, and each channel matches the reference's channel.
TEST(ConvolutionBake, ColouredLightGivesColouredPenumbrae) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("shadowbake_coloured_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  Image texture(2, 1, 3, 0.0f);
  texture.at(0, 0)[0] = 1.0f;  // left: red
  texture.at(1, 0)[2] = 1.0f;  // right: blue
  ASSERT_TRUE(write_image(dir / "half.exr", texture, PixelFormat::float32));
  Scene conv = load("parallel", 96, "convolution"), ref = load("parallel", 96, "reference");
  for (Scene* s : {&conv, &ref}) s->lights[0].texture = dir / "half.exr";
  ref.bake.samples = 1024;
  const Image c = bake_floor(conv), r = bake_floor(ref);
  std::filesystem::remove_all(dir);
  // The two halves of a 2-texel image blend bilinearly over the middle; both methods see the
  // same texture, so compare channel by channel.
  for (int ch : {0, 2}) {
    const Errors e = image_errors(c, r, ch);
    std::printf("coloured light, channel %d: RMSE vs reference %.4f, max %.4f\n", ch, e.rmse,
                e.max);
    EXPECT_LE(e.rmse, 0.03) << "channel " << ch;
  }
  // Coloured penumbra: somewhere red and blue visibility differ strongly, in both methods.
  double most_red = 0, most_blue = 0;
  for (int j = 0; j < c.height; ++j)
    for (int i = 0; i < c.width; ++i) {
      most_red = std::max(most_red, double(c.at(i, j)[0] - c.at(i, j)[2]));
      most_blue = std::max(most_blue, double(c.at(i, j)[2] - c.at(i, j)[0]));
    }
  EXPECT_GT(most_red, 0.3);
  EXPECT_GT(most_blue, 0.3);
  EXPECT_EQ(c.at(0, 0)[1], 0.0f);  // no green light, no green visibility
}

}  // namespace
}  // namespace sb

namespace sb {
namespace {

// The box of the showcase stands on the floor, which is a blocker too: the floor lies behind the
// box's faces as seen from the lights, so it must not shadow them (ShadowCaster culling). The box
// is unshadowed in the reference; the convolution must agree.
TEST(ConvolutionBake, BlockersBehindTheReceiverDoNotShadowIt) {
  auto load_showcase = [](const std::string& method) {
    auto scene = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/showcase/scene.toml");
    EXPECT_TRUE(scene) << scene.error().message;
    scene->bake.resolution = 64;
    scene->bake.method = method;
    scene->bake.samples = 64;
    scene->bake.margin = 0;
    for (auto& o : scene->objects) o.receiver = o.name == "box";
    return *scene;
  };
  auto conv = bake(load_showcase("convolution"));
  auto ref = bake(load_showcase("reference"));
  ASSERT_TRUE(conv && ref);
  const Image& c = conv->receivers[0].image;
  const Image& r = ref->receivers[0].image;
  double worst = 0;
  for (std::size_t i = 0; i < c.pixels.size(); ++i)
    worst = std::max(worst, double(std::abs(c.pixels[i] - r.pixels[i])));
  EXPECT_LT(worst, 0.05);
}

}  // namespace
}  // namespace sb
