// Image metrics against values computed by hand on tiny images, SSIM against a direct
// implementation of its formula, masks, the penumbra set, NaN/Inf, errors, and the heat map.
#include "evaluation/image_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace {

sb::Image make(int w, int h, int c, const std::vector<float>& values) {
  sb::Image image(w, h, c);
  image.pixels.assign(values.begin(), values.end());
  return image;
}

sb::Comparison compare(const sb::Image& a, const sb::Image& reference,
                       const sb::CompareOptions& options = {}) {
  auto result = sb::compare_images(a, reference, options, "a.exr", "b.exr");
  EXPECT_TRUE(result) << (result ? "" : result.error().message);
  return result ? *result : sb::Comparison{};
}

// A deterministic pattern with structure at several scales.
sb::Image pattern(int w, int h, int c, double phase) {
  sb::Image image(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k)
        image.at(x, y)[k] = float(0.5 + 0.3 * std::sin(0.7 * x + 0.3 * y + phase + k) +
                                  0.15 * std::cos(0.23 * x * y + 2 * phase));
  return image;
}

// SSIM at (x, y) the most direct way: explicit sums over the 11 × 11 window's texels inside the
// image, Gaussian weights σ = 1.5, renormalised by the weight inside (Wang et al. 2004, eq. 13-16).
double direct_ssim(const sb::Image& a, const sb::Image& b, int channel, double dynamic_range, int x,
                   int y) {
  double weight = 0, sum_a = 0, sum_b = 0;
  for (int dy = -5; dy <= 5; ++dy) {
    for (int dx = -5; dx <= 5; ++dx) {
      const int xx = x + dx, yy = y + dy;
      if (xx < 0 || yy < 0 || xx >= a.width || yy >= a.height) continue;
      const double w = std::exp(-(dx * dx + dy * dy) / (2 * 1.5 * 1.5));
      weight += w;
      sum_a += w * a.at(xx, yy)[channel];
      sum_b += w * b.at(xx, yy)[channel];
    }
  }
  const double mean_a = sum_a / weight, mean_b = sum_b / weight;
  double var_a = 0, var_b = 0, cov = 0;
  for (int dy = -5; dy <= 5; ++dy) {
    for (int dx = -5; dx <= 5; ++dx) {
      const int xx = x + dx, yy = y + dy;
      if (xx < 0 || yy < 0 || xx >= a.width || yy >= a.height) continue;
      const double w = std::exp(-(dx * dx + dy * dy) / (2 * 1.5 * 1.5)) / weight;
      const double da = a.at(xx, yy)[channel] - mean_a, db = b.at(xx, yy)[channel] - mean_b;
      var_a += w * da * da;
      var_b += w * db * db;
      cov += w * da * db;
    }
  }
  const double c1 = std::pow(0.01 * dynamic_range, 2), c2 = std::pow(0.03 * dynamic_range, 2);
  return (2 * mean_a * mean_b + c1) * (2 * cov + c2) /
         ((mean_a * mean_a + mean_b * mean_b + c1) * (var_a + var_b + c2));
}

void expect_same_errors(const sb::ChannelErrors& e, const sb::ChannelErrors& f) {
  EXPECT_EQ(e.count, f.count);
  EXPECT_DOUBLE_EQ(e.rmse, f.rmse);
  EXPECT_DOUBLE_EQ(e.mae, f.mae);
  EXPECT_DOUBLE_EQ(e.max_abs, f.max_abs);
  EXPECT_EQ(e.max_x, f.max_x);
  EXPECT_EQ(e.max_y, f.max_y);
  EXPECT_EQ(e.max_channel, f.max_channel);
  EXPECT_DOUBLE_EQ(e.psnr, f.psnr);
  EXPECT_NEAR(e.ssim, f.ssim, 1e-12);
}

}  // namespace

TEST(ImageMetrics, HandComputedTwoByTwo) {
  // Two channels, row-major interleaved. Channel 0 errors: 0.1, 0, −0.3, 0; channel 1: 0, 0.2, 0,
  // 0.
  const auto reference = make(2, 2, 2, {0.0f, 0.2f, 0.5f, 0.2f, 1.0f, 0.2f, 0.25f, 0.2f});
  const auto a = make(2, 2, 2, {0.1f, 0.2f, 0.5f, 0.4f, 0.7f, 0.2f, 0.25f, 0.2f});
  const auto c = compare(a, reference);
  EXPECT_EQ(c.covered.texels, 4);
  ASSERT_EQ(c.covered.channels.size(), 2u);
  const auto& ch0 = c.covered.channels[0];
  EXPECT_EQ(ch0.count, 4);
  EXPECT_NEAR(ch0.rmse, std::sqrt(0.1 / 4), 1e-6);
  EXPECT_NEAR(ch0.mae, 0.4 / 4, 1e-6);
  EXPECT_NEAR(ch0.max_abs, 0.3, 1e-6);
  EXPECT_EQ(ch0.max_x, 0);
  EXPECT_EQ(ch0.max_y, 1);
  EXPECT_EQ(ch0.max_channel, 0);
  EXPECT_NEAR(ch0.psnr, 10 * std::log10(1 / 0.025), 1e-4);
  const auto& ch1 = c.covered.channels[1];
  EXPECT_NEAR(ch1.rmse, 0.1, 1e-6);
  EXPECT_NEAR(ch1.mae, 0.05, 1e-6);
  EXPECT_NEAR(ch1.max_abs, 0.2, 1e-6);
  EXPECT_EQ(ch1.max_x, 1);
  EXPECT_EQ(ch1.max_y, 0);
  EXPECT_EQ(ch1.max_channel, 1);
  // Overall pools the eight values: MSE = (0.1 + 0.04) / 8.
  const auto& all = c.covered.overall;
  EXPECT_EQ(all.count, 8);
  EXPECT_NEAR(all.rmse, std::sqrt(0.0175), 1e-6);
  EXPECT_NEAR(all.mae, 0.075, 1e-6);
  EXPECT_NEAR(all.max_abs, 0.3, 1e-6);
  EXPECT_EQ(all.max_x, 0);
  EXPECT_EQ(all.max_y, 1);
  EXPECT_EQ(all.max_channel, 0);
  EXPECT_NEAR(all.psnr, 10 * std::log10(1 / 0.0175), 1e-4);
  EXPECT_NEAR(all.ssim, (ch0.ssim + ch1.ssim) / 2, 1e-12);
  EXPECT_EQ(c.non_finite_a, 0);
  EXPECT_EQ(c.non_finite_reference, 0);
  EXPECT_DOUBLE_EQ(c.peak, 1.0);
}

TEST(ImageMetrics, PsnrPeak) {
  const auto reference = make(2, 2, 1, {0.5f, 0.25f, 0.25f, 0.25f});
  const auto a = make(2, 2, 1, {0.4f, 0.25f, 0.25f, 0.25f});  // MSE = 0.01 / 4
  EXPECT_NEAR(compare(a, reference).covered.overall.psnr, 10 * std::log10(1 / 0.0025), 1e-4);
  sb::CompareOptions largest;
  largest.peak = 0;  // the reference's largest value, 0.5
  const auto c = compare(a, reference, largest);
  EXPECT_DOUBLE_EQ(c.peak, 0.5);
  EXPECT_NEAR(c.covered.overall.psnr, 20.0, 1e-4);
  sb::CompareOptions two;
  two.peak = 2;
  EXPECT_NEAR(compare(a, reference, two).covered.overall.psnr, 10 * std::log10(4 / 0.0025), 1e-4);
}

TEST(ImageMetrics, IdenticalImagesArePerfect) {
  const auto image = pattern(16, 16, 3, 0.0);
  const auto c = compare(image, image);
  EXPECT_EQ(c.covered.overall.rmse, 0.0);
  EXPECT_EQ(c.covered.overall.max_abs, 0.0);
  EXPECT_EQ(c.covered.overall.psnr, std::numeric_limits<double>::infinity());
  EXPECT_NEAR(c.covered.overall.ssim, 1.0, 1e-12);
  for (const double v : sb::ssim_map(image, image, 1, 1.0)) EXPECT_NEAR(v, 1.0, 1e-12);
}

TEST(ImageMetrics, MaskedTexelChangesNothing) {
  const auto reference = pattern(9, 9, 3, 0.0);
  auto a = pattern(9, 9, 3, 0.2);
  std::vector<std::uint8_t> mask(81, 1);
  mask[4 * 9 + 4] = 0;
  mask[0] = 0;
  sb::CompareOptions options;
  options.mask = mask;
  const auto before = compare(a, reference, options);
  a.at(4, 4)[1] = 1000.0f;
  a.at(0, 0)[0] = -50.0f;
  const auto after = compare(a, reference, options);
  EXPECT_EQ(after.covered.texels, 79);
  expect_same_errors(before.covered.overall, after.covered.overall);
  expect_same_errors(before.penumbra.overall, after.penumbra.overall);
  for (int c = 0; c < 3; ++c)
    expect_same_errors(before.covered.channels[c], after.covered.channels[c]);
  EXPECT_LT(after.covered.overall.max_abs, 1.0);
  // Without the mask, the huge error shows.
  EXPECT_NEAR(compare(a, reference).covered.overall.max_abs, 1000 - reference.at(4, 4)[1], 1e-3);
}

TEST(ImageMetrics, PenumbraIsStrictlyInsideTheRange) {
  // Penumbra texels (reference in (0.02, 0.98)): 0.5, 0.03, 0.97; their error is 0.1, others 0.5.
  const std::vector<float> ref = {0.0f, 0.02f, 0.5f, 0.98f, 1.0f, 0.03f, 0.97f, 0.01f, 0.99f};
  std::vector<float> a_values(ref.size());
  for (std::size_t i = 0; i < ref.size(); ++i)
    a_values[i] = ref[i] + ((ref[i] > 0.02f && ref[i] < 0.98f) ? 0.1f : 0.5f);
  const auto reference = make(3, 3, 1, ref), a = make(3, 3, 1, a_values);
  auto c = compare(a, reference);
  EXPECT_EQ(c.covered.texels, 9);
  EXPECT_EQ(c.penumbra.texels, 3);
  EXPECT_NEAR(c.penumbra.overall.rmse, 0.1, 1e-6);
  EXPECT_NEAR(c.penumbra.overall.max_abs, 0.1, 1e-6);
  EXPECT_NEAR(c.covered.overall.max_abs, 0.5, 1e-6);
  // The penumbra is a subset of the covered texels.
  sb::CompareOptions options;
  options.mask.assign(9, 1);
  options.mask[2] = 0;  // the 0.5 texel
  c = compare(a, reference, options);
  EXPECT_EQ(c.covered.texels, 8);
  EXPECT_EQ(c.penumbra.texels, 2);
  // Any channel inside the range puts the texel in the penumbra.
  const auto two = make(1, 1, 2, {0.0f, 0.5f});
  EXPECT_EQ(compare(two, two).penumbra.texels, 1);
  // No penumbra at all: counted as none, its metrics undefined rather than perfect.
  const auto binary = make(2, 1, 1, {0.0f, 1.0f});
  c = compare(binary, binary);
  EXPECT_EQ(c.penumbra.texels, 0);
  EXPECT_TRUE(std::isnan(c.penumbra.overall.rmse));
}

TEST(ImageMetrics, NonFiniteTexelsCountedAndLeftOut) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  auto reference = pattern(8, 8, 2, 0.0);
  auto a = reference;
  a.at(1, 1)[0] += 0.1f;
  a.at(6, 5)[1] -= 0.3f;
  const auto clean = compare(a, reference);
  // NaN in a, +inf in the reference, −inf in a and NaN in the reference at one texel.
  a.at(0, 0)[1] = nan;
  reference.at(3, 0)[0] = inf;
  a.at(7, 7)[0] = -inf;
  reference.at(7, 7)[1] = nan;
  const auto c = compare(a, reference);
  EXPECT_EQ(c.non_finite_a, 2);
  EXPECT_EQ(c.non_finite_reference, 2);
  EXPECT_EQ(c.covered.texels, 64 - 3);
  for (const auto* e :
       {&c.covered.overall, &c.covered.channels[0], &c.covered.channels[1], &c.penumbra.overall}) {
    EXPECT_TRUE(std::isfinite(e->rmse));
    EXPECT_TRUE(std::isfinite(e->mae));
    EXPECT_TRUE(std::isfinite(e->max_abs));
    EXPECT_TRUE(std::isfinite(e->psnr));
    EXPECT_TRUE(std::isfinite(e->ssim));
  }
  EXPECT_NEAR(c.covered.overall.max_abs, 0.3, 1e-6);
  EXPECT_EQ(c.covered.overall.max_x, 6);
  // The squared errors are the same, over fewer values.
  EXPECT_NEAR(
      c.covered.overall.rmse * c.covered.overall.rmse * double(c.covered.overall.count),
      clean.covered.overall.rmse * clean.covered.overall.rmse * double(clean.covered.overall.count),
      1e-9);
  // A masked-out non-finite texel is not counted.
  sb::CompareOptions options;
  options.mask.assign(64, 1);
  options.mask[0] = 0;
  EXPECT_EQ(compare(a, reference, options).non_finite_a, 1);
}

TEST(ImageMetrics, SsimMatchesDirectWindowSums) {
  const auto a = pattern(16, 16, 2, 0.0), b = pattern(16, 16, 2, 0.4);
  for (const double range : {1.0, 2.5}) {
    for (int channel = 0; channel < 2; ++channel) {
      const auto map = sb::ssim_map(a, b, channel, range);
      ASSERT_EQ(map.size(), 256u);
      double sum = 0;
      for (int y = 0; y < 16; ++y) {
        for (int x = 0; x < 16; ++x) {
          EXPECT_NEAR(map[y * 16 + x], direct_ssim(a, b, channel, range, x, y), 1e-9)
              << "at " << x << "," << y;
          sum += map[y * 16 + x];
        }
      }
      if (range == 1.0) {
        EXPECT_NEAR(compare(a, b).covered.channels[channel].ssim, sum / 256, 1e-9);
      }
    }
  }
}

TEST(ImageMetrics, SsimPrefersNoiseToContrastLoss) {
  const auto a = pattern(32, 32, 1, 0.0);
  auto flattened = a, noisy = a;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    flattened.pixels[i] = a.pixels[i] * 0.5f + 0.25f;
    noisy.pixels[i] = a.pixels[i] + 0.002f * float(std::sin(12.9898 * double(i)));
  }
  const double ssim_flat = compare(flattened, a).covered.overall.ssim;
  const double ssim_noisy = compare(noisy, a).covered.overall.ssim;
  EXPECT_LT(ssim_flat, ssim_noisy);
  EXPECT_GT(ssim_noisy, 0.99);
  EXPECT_LT(ssim_flat, 0.95);
}

TEST(ImageMetrics, RejectsMismatchNamingBothFiles) {
  const auto small = pattern(4, 4, 3, 0.0), large = pattern(8, 4, 3, 0.0);
  auto r = sb::compare_images(small, large, {}, "cheap.exr", "ref.exr");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, sb::ErrorKind::input);
  EXPECT_NE(r.error().message.find("cheap.exr"), std::string::npos);
  EXPECT_NE(r.error().message.find("ref.exr"), std::string::npos);
  EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
  r = sb::compare_images(small, pattern(4, 4, 1, 0.0), {}, "cheap.exr", "ref.exr");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("channels"), std::string::npos);
  sb::CompareOptions options;
  options.mask.assign(15, 1);
  r = sb::compare_images(small, small, options, "cheap.exr", "ref.exr");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("mask"), std::string::npos);
}

TEST(ImageMetrics, HeatMapColours) {
  const auto reference = make(4, 1, 3, std::vector<float>(12, 0.5f));
  // Texel 0: no difference; 1: +0.05 (half the scale); 2: −0.2 (saturated); 3: masked.
  auto a = reference;
  for (int k = 0; k < 3; ++k) {
    a.at(1, 0)[k] += 0.05f;
    a.at(2, 0)[k] -= 0.2f;
    a.at(3, 0)[k] += 1.0f;
  }
  const std::vector<std::uint8_t> mask = {1, 1, 1, 0};
  const auto heat = sb::difference_heat_map(a, reference, mask, 0.1, false);
  ASSERT_EQ(heat.width, 4);
  ASSERT_EQ(heat.height, 1);
  ASSERT_EQ(heat.channels, 3);
  const float* zero = heat.at(0, 0);
  EXPECT_FLOAT_EQ(zero[0], 1.0f);
  EXPECT_FLOAT_EQ(zero[1], 1.0f);
  EXPECT_FLOAT_EQ(zero[2], 1.0f);
  const float* above = heat.at(1, 0);  // reddish, halfway to red
  EXPECT_FLOAT_EQ(above[0], 1.0f);
  EXPECT_NEAR(above[1], 0.5f, 1e-4);
  EXPECT_NEAR(above[2], 0.5f, 1e-4);
  const float* below = heat.at(2, 0);  // saturated blue
  EXPECT_NEAR(below[0], 0.0f, 1e-6);
  EXPECT_NEAR(below[1], 0.0f, 1e-6);
  EXPECT_FLOAT_EQ(below[2], 1.0f);
  const float* masked = heat.at(3, 0);
  EXPECT_FLOAT_EQ(masked[0], 0.2f);
  EXPECT_FLOAT_EQ(masked[1], 0.2f);
  EXPECT_FLOAT_EQ(masked[2], 0.2f);
}

TEST(ImageMetrics, HeatMapColourBar) {
  const auto reference = pattern(200, 50, 3, 0.0);
  const auto heat = sb::difference_heat_map(reference, reference, {}, 0.05, true);
  ASSERT_EQ(heat.width, 200);
  ASSERT_GT(heat.height, 50 + 20);  // the bar and its labels below the image
  const int bar_y = 50 + 12;
  const float* left = heat.at(0, bar_y);
  const float* middle = heat.at(100, bar_y);
  const float* right = heat.at(199, bar_y);
  EXPECT_GT(left[2], 0.9f);  // blue at −scale
  EXPECT_LT(left[0], 0.1f);
  EXPECT_GT(right[0], 0.9f);  // red at +scale
  EXPECT_LT(right[2], 0.1f);
  EXPECT_GT(middle[0], 0.95f);  // white at 0
  EXPECT_GT(middle[2], 0.95f);
  // The labels: dark pixels near the left end, the middle and the right end of the last rows.
  auto dark_in = [&](int x0, int x1) {
    for (int y = 50 + 24; y < heat.height; ++y)
      for (int x = x0; x < x1; ++x)
        if (heat.at(x, y)[0] < 0.1f) return true;
    return false;
  };
  EXPECT_TRUE(dark_in(0, 20));
  EXPECT_TRUE(dark_in(95, 105));
  EXPECT_TRUE(dark_in(180, 200));
  EXPECT_FALSE(dark_in(60, 80));
  // The image part is unchanged by the bar: white where there is no difference.
  EXPECT_FLOAT_EQ(heat.at(10, 10)[1], 1.0f);
}

TEST(ImageMetrics, HeatMapScaleIsReadable) {
  const auto reference = make(2, 1, 1, {0.5f, 0.5f});
  auto scale_for = [&](float difference) {
    return sb::heat_map_scale(make(2, 1, 1, {0.5f + difference, 0.5f}), reference, {});
  };
  EXPECT_DOUBLE_EQ(scale_for(0.0f), 0.01);
  EXPECT_DOUBLE_EQ(scale_for(0.003f), 0.01);
  EXPECT_NEAR(scale_for(0.013f), 0.02, 1e-12);
  EXPECT_NEAR(scale_for(-0.04f), 0.05, 1e-12);
  EXPECT_NEAR(scale_for(0.07f), 0.1, 1e-12);
  EXPECT_NEAR(scale_for(0.3f), 0.5, 1e-12);
  EXPECT_NEAR(scale_for(1.5f), 2.0, 1e-12);
  // A masked texel does not set the scale.
  EXPECT_DOUBLE_EQ(
      sb::heat_map_scale(make(2, 1, 1, {9.0f, 0.5f}), reference, std::vector<std::uint8_t>{0, 1}),
      0.01);
}
