// Error metrics between a baked texture and a reference (docs/reports.md): RMSE, mean absolute
// error, the largest error and where it is, PSNR, and SSIM (Wang, Bovik, Sheikh & Simoncelli,
// "Image Quality Assessment: From Error Visibility to Structural Similarity", IEEE TIP 13(4),
// 2004: eq. 13 with the 11 × 11 Gaussian window, σ = 1.5, K1 = 0.01, K2 = 0.03 of §III.C and the
// weighted statistics of eqs. 14–16), over the covered texels and over the penumbra; and a signed
// difference heat map with a colour bar.
#include "evaluation/image_metrics.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace sb {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kSsimRadius = 5;  // an 11 × 11 window
constexpr int kSsimTaps = 2 * kSsimRadius + 1;
constexpr double kSsimSigma = 1.5;

std::array<double, kSsimTaps> ssim_weights() {
  std::array<double, kSsimTaps> w{};
  for (int i = 0; i < kSsimTaps; ++i) {
    const double t = i - kSsimRadius;
    w[i] = std::exp(-t * t / (2 * kSsimSigma * kSsimSigma));
  }
  return w;  // unnormalised: every window statistic is divided by its own weight sum
}

// SSIM at every texel where `valid` is nonzero, NaN elsewhere. A window's statistics are weighted
// by the Gaussian and taken over its valid texels only, renormalised by their weight: texels
// beyond the border, outside the mask or holding NaN never enter a neighbour's window. Each
// weighted sum is a separable convolution of (valid · value), so rows are filtered first, then
// columns, strip by strip (a strip keeps its rows' filtered sums in cache and bounds memory).
std::vector<double> masked_ssim_map(const Image& a, const Image& b, int channel,
                                    double dynamic_range, const std::vector<std::uint8_t>& valid) {
  const int width = a.width, height = a.height;
  const auto weights = ssim_weights();
  const double c1 = (0.01 * dynamic_range) * (0.01 * dynamic_range);
  const double c2 = (0.03 * dynamic_range) * (0.03 * dynamic_range);
  std::vector<double> map(std::size_t(width) * height, kNaN);
  // Per texel: valid, valid·a, valid·b, valid·a², valid·b², valid·a·b.
  constexpr int kFields = 6;
  constexpr int kStripRows = 32;
  const int strips = (height + kStripRows - 1) / kStripRows;
  tbb::parallel_for(tbb::blocked_range<int>(0, strips), [&](const tbb::blocked_range<int>& range) {
    const std::size_t padded = std::size_t(width) + 2 * kSsimRadius;
    std::vector<double> row_values(kFields * padded, 0.0);
    std::vector<double> row_sums;  // kFields × strip rows (with the window's margin) × width
    std::vector<double> column_sums(kFields * std::size_t(width));
    for (int strip = range.begin(); strip != range.end(); ++strip) {
      const int y0 = strip * kStripRows, y1 = std::min(height, y0 + kStripRows);
      const int first = std::max(0, y0 - kSsimRadius), last = std::min(height, y1 + kSsimRadius);
      const std::size_t rows = std::size_t(last - first);
      row_sums.assign(kFields * rows * width, 0.0);
      for (int y = first; y < last; ++y) {
        for (int x = 0; x < width; ++x) {
          const std::size_t i = std::size_t(y) * width + x;
          double* v = &row_values[x + kSsimRadius];
          if (!valid[i]) {
            for (int f = 0; f < kFields; ++f) v[f * padded] = 0.0;
            continue;
          }
          const double va = a.pixels[i * a.channels + channel];
          const double vb = b.pixels[i * b.channels + channel];
          v[0] = 1.0;
          v[padded] = va;
          v[2 * padded] = vb;
          v[3 * padded] = va * va;
          v[4 * padded] = vb * vb;
          v[5 * padded] = va * vb;
        }
        for (int f = 0; f < kFields; ++f) {
          const double* in = &row_values[f * padded];
          double* out = &row_sums[(f * rows + std::size_t(y - first)) * width];
          for (int x = 0; x < width; ++x) {
            double s = 0.0;
            for (int k = 0; k < kSsimTaps; ++k) s += weights[k] * in[x + k];
            out[x] = s;
          }
        }
      }
      for (int y = y0; y < y1; ++y) {
        std::fill(column_sums.begin(), column_sums.end(), 0.0);
        for (int k = 0; k < kSsimTaps; ++k) {
          const int yy = y + k - kSsimRadius;
          if (yy < first || yy >= last) continue;
          for (int f = 0; f < kFields; ++f) {
            const double* in = &row_sums[(f * rows + std::size_t(yy - first)) * width];
            double* out = &column_sums[std::size_t(f) * width];
            for (int x = 0; x < width; ++x) out[x] += weights[k] * in[x];
          }
        }
        for (int x = 0; x < width; ++x) {
          const std::size_t i = std::size_t(y) * width + x;
          if (!valid[i]) continue;
          const double weight = column_sums[x];
          const double mean_a = column_sums[std::size_t(width) + x] / weight;
          const double mean_b = column_sums[2 * std::size_t(width) + x] / weight;
          const double var_a = column_sums[3 * std::size_t(width) + x] / weight - mean_a * mean_a;
          const double var_b = column_sums[4 * std::size_t(width) + x] / weight - mean_b * mean_b;
          const double cov = column_sums[5 * std::size_t(width) + x] / weight - mean_a * mean_b;
          map[i] = ((2 * mean_a * mean_b + c1) * (2 * cov + c2)) /
                   ((mean_a * mean_a + mean_b * mean_b + c1) * (var_a + var_b + c2));
        }
      }
    }
  });
  return map;
}

// Sums of one channel's (or all channels') errors over one set of texels.
struct ErrorSums {
  std::int64_t count = 0;
  double squares = 0, absolutes = 0, max_abs = -1;
  int max_x = -1, max_y = -1, max_channel = -1;

  void add(double difference, int x, int y, int channel) {
    const double e = std::abs(difference);
    ++count;
    squares += difference * difference;
    absolutes += e;
    if (e > max_abs) {
      max_abs = e;
      max_x = x;
      max_y = y;
      max_channel = channel;
    }
  }
  // Merged in scan order, so that the first of equal maxima is the one reported.
  void merge(const ErrorSums& later) {
    count += later.count;
    squares += later.squares;
    absolutes += later.absolutes;
    if (later.max_abs > max_abs) {
      max_abs = later.max_abs;
      max_x = later.max_x;
      max_y = later.max_y;
      max_channel = later.max_channel;
    }
  }
};

ChannelErrors finish(const ErrorSums& sums, double peak, double ssim) {
  ChannelErrors e;
  e.count = sums.count;
  if (sums.count == 0) {  // no texels, no error to speak of: undefined rather than perfect
    e.rmse = e.mae = e.max_abs = e.psnr = e.ssim = kNaN;
    return e;
  }
  const double mse = sums.squares / double(sums.count);
  e.rmse = std::sqrt(mse);
  e.mae = sums.absolutes / double(sums.count);
  e.max_abs = sums.max_abs;
  e.max_x = sums.max_x;
  e.max_y = sums.max_y;
  e.max_channel = sums.max_channel;
  e.psnr = mse == 0 ? std::numeric_limits<double>::infinity() : 10 * std::log10(peak * peak / mse);
  e.ssim = ssim;
  return e;
}

bool texel_finite(const Image& image, std::size_t texel) {
  const float* v = &image.pixels[texel * image.channels];
  for (int c = 0; c < image.channels; ++c)
    if (!std::isfinite(v[c])) return false;
  return true;
}

std::string describe(const Image& image) {
  return std::to_string(image.width) + "×" + std::to_string(image.height) + ", " +
         std::to_string(image.channels) + (image.channels == 1 ? " channel" : " channels");
}

// The colour of a signed difference: white at 0, towards red above and blue below, saturated
// at ±scale.
std::array<float, 3> difference_colour(double difference, double scale) {
  const float t = float(std::clamp(std::abs(difference) / scale, 0.0, 1.0));
  if (difference > 0) return {1.0f, 1.0f - t, 1.0f - t};
  if (difference < 0) return {1.0f - t, 1.0f - t, 1.0f};
  return {1.0f, 1.0f, 1.0f};
}

// A 3 × 5 bitmap font for the colour bar's labels (what "%g" writes): each glyph is five rows
// of three bits, the high bit on the left. OIIO's text rendering needs fonts that may be missing.
const std::array<std::uint8_t, 5>* glyph(char c) {
  static const std::array<std::uint8_t, 5> digits[10] = {
      {7, 5, 5, 5, 7}, {2, 6, 2, 2, 7}, {7, 1, 7, 4, 7}, {7, 1, 7, 1, 7}, {5, 5, 7, 1, 1},
      {7, 4, 7, 1, 7}, {7, 4, 7, 5, 7}, {7, 1, 1, 1, 1}, {7, 5, 7, 5, 7}, {7, 5, 7, 1, 7}};
  static const std::array<std::uint8_t, 5> dot = {0, 0, 0, 0, 2}, minus = {0, 0, 7, 0, 0},
                                           plus = {0, 2, 7, 2, 0}, e = {2, 5, 7, 4, 3};
  if (c >= '0' && c <= '9') return &digits[c - '0'];
  if (c == '.') return &dot;
  if (c == '-') return &minus;
  if (c == '+') return &plus;
  if (c == 'e') return &e;
  return nullptr;
}

constexpr int kBarHeight = 24, kLabelHeight = 12;

// Text drawn with each font bit as scale × scale pixels, one bit's gap between glyphs.
int text_width(const std::string& text, int scale) {
  return text.empty() ? 0 : (int(text.size()) * 4 - 1) * scale;
}

// Draws `text` in black with its top-left corner at (x0, y0), clipped to the image.
void draw_text(Image& image, const std::string& text, int x0, int y0, int scale) {
  for (std::size_t n = 0; n < text.size(); ++n) {
    const auto* rows = glyph(text[n]);
    if (!rows) continue;
    for (int gy = 0; gy < 5 * scale; ++gy) {
      for (int gx = 0; gx < 3 * scale; ++gx) {
        if (!((*rows)[gy / scale] >> (2 - gx / scale) & 1)) continue;
        const int x = x0 + int(n) * 4 * scale + gx, y = y0 + gy;
        if (x < 0 || y < 0 || x >= image.width || y >= image.height) continue;
        float* p = image.at(x, y);
        p[0] = p[1] = p[2] = 0.0f;
      }
    }
  }
}

// The bar's labels, "-scale" at the left, "0" in the middle, "+scale" at the right, on the
// label row starting at row y0: font bits of 2 × 2 pixels where all three fit, else 1 × 1; the
// "0" is left out where it does not fit, and on images narrower than the end labels they clip.
void draw_labels(Image& image, double scale, int y0) {
  char number[32];
  std::snprintf(number, sizeof number, "%g", scale);
  const std::string low = std::string("-") + number, high = std::string("+") + number;
  constexpr int kMargin = 1, kGap = 4;
  for (int font = 2; font >= 1; --font) {
    const int low_end = kMargin + text_width(low, font);
    const int high_start = image.width - kMargin - text_width(high, font);
    const int zero_start = (image.width - text_width("0", font)) / 2;
    const bool zero_fits =
        zero_start >= low_end + kGap && zero_start + text_width("0", font) + kGap <= high_start;
    if (!zero_fits && font > 1) continue;
    const int y = y0 + (kLabelHeight - 5 * font) / 2;
    draw_text(image, low, kMargin, y, font);
    if (zero_fits) draw_text(image, "0", zero_start, y, font);
    draw_text(image, high, high_start, y, font);
    return;
  }
}

}  // namespace

Expected<Comparison> compare_images(const Image& a, const Image& reference,
                                    const CompareOptions& options, const std::string& a_name,
                                    const std::string& reference_name) {
  if (a.width != reference.width || a.height != reference.height ||
      a.channels != reference.channels) {
    return input_error(a_name + " (" + describe(a) + ") and " + reference_name + " (" +
                       describe(reference) + ") differ in size or channels; compare a texture " +
                       "with a reference of the same resolution and channels");
  }
  const int width = a.width, height = a.height, channels = a.channels;
  const std::size_t texels = std::size_t(width) * height;
  if (!options.mask.empty() && options.mask.size() != texels) {
    return input_error("the mask has " + std::to_string(options.mask.size()) + " texels, but " +
                       a_name + " and " + reference_name + " are " + std::to_string(width) + "×" +
                       std::to_string(height));
  }
  if (!(options.peak >= 0) || !std::isfinite(options.peak)) {
    return input_error("the PSNR peak must be a finite value ≥ 0 (0: the reference's largest)");
  }

  Comparison result;
  result.width = width;
  result.height = height;
  result.channels = channels;

  // Which texels count: covered by the mask and finite in both images.
  std::vector<std::uint8_t> covered(texels, 0), penumbra(texels, 0);
  double reference_max = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < texels; ++i) {
    if (!options.mask.empty() && !options.mask[i]) continue;
    const bool finite_a = texel_finite(a, i), finite_reference = texel_finite(reference, i);
    result.non_finite_a += !finite_a;
    result.non_finite_reference += !finite_reference;
    if (!finite_a || !finite_reference) continue;
    covered[i] = 1;
    const float* r = &reference.pixels[i * channels];
    for (int c = 0; c < channels; ++c) {
      reference_max = std::max(reference_max, double(r[c]));
      if (r[c] > options.penumbra_lo && r[c] < options.penumbra_hi) penumbra[i] = 1;
    }
  }
  // Peak 0: the reference's largest covered value (irradiance has no natural peak); 1 when that
  // is not positive, so that PSNR and SSIM's constants stay defined.
  result.peak = options.peak > 0 ? options.peak : reference_max > 0 ? reference_max : 1.0;

  // Error sums per row (in parallel), then merged in row order: the same result on any number of
  // threads. Per row: [region][channel], with index `channels` for all channels pooled.
  const int per_region = channels + 1;
  std::vector<ErrorSums> row_sums(std::size_t(height) * 2 * per_region);
  std::vector<std::int64_t> row_texels(std::size_t(height) * 2, 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      ErrorSums* sums = &row_sums[std::size_t(y) * 2 * per_region];
      for (int x = 0; x < width; ++x) {
        const std::size_t i = std::size_t(y) * width + x;
        if (!covered[i]) continue;
        for (int region = 0; region < 2; ++region) {
          if (region == 1 && !penumbra[i]) continue;
          ++row_texels[std::size_t(y) * 2 + region];
          for (int c = 0; c < channels; ++c) {
            const double d =
                double(a.pixels[i * channels + c]) - reference.pixels[i * channels + c];
            sums[region * per_region + c].add(d, x, y, c);
            sums[region * per_region + channels].add(d, x, y, c);
          }
        }
      }
    }
  });
  std::vector<ErrorSums> totals(2 * per_region);
  std::int64_t region_texels[2] = {0, 0};
  for (int y = 0; y < height; ++y) {
    for (int k = 0; k < 2 * per_region; ++k)
      totals[k].merge(row_sums[std::size_t(y) * 2 * per_region + k]);
    for (int region = 0; region < 2; ++region)
      region_texels[region] += row_texels[std::size_t(y) * 2 + region];
  }

  // SSIM per channel over the covered texels' windows, averaged over each region.
  std::vector<double> ssim[2];
  for (int c = 0; c < channels; ++c) {
    const auto map = masked_ssim_map(a, reference, c, result.peak, covered);
    double sum[2] = {0, 0};
    for (std::size_t i = 0; i < texels; ++i) {
      if (!covered[i]) continue;
      sum[0] += map[i];
      if (penumbra[i]) sum[1] += map[i];
    }
    for (int region = 0; region < 2; ++region)
      ssim[region].push_back(region_texels[region] > 0 ? sum[region] / double(region_texels[region])
                                                       : kNaN);
  }

  for (int region = 0; region < 2; ++region) {
    RegionErrors& out = region == 0 ? result.covered : result.penumbra;
    out.texels = region_texels[region];
    double ssim_sum = 0;
    for (int c = 0; c < channels; ++c) {
      out.channels.push_back(finish(totals[region * per_region + c], result.peak, ssim[region][c]));
      ssim_sum += ssim[region][c];
    }
    out.overall = finish(totals[region * per_region + channels], result.peak,
                         channels > 0 ? ssim_sum / channels : kNaN);
  }
  return result;
}

std::vector<double> ssim_map(const Image& a, const Image& b, int channel, double dynamic_range) {
  assert(a.width == b.width && a.height == b.height && a.channels == b.channels);
  assert(channel >= 0 && channel < a.channels);
  // Texels where either image is not finite in this channel are left out of every window.
  std::vector<std::uint8_t> valid(std::size_t(a.width) * a.height);
  for (std::size_t i = 0; i < valid.size(); ++i) {
    valid[i] = std::isfinite(a.pixels[i * a.channels + channel]) &&
               std::isfinite(b.pixels[i * b.channels + channel]);
  }
  return masked_ssim_map(a, b, channel, dynamic_range, valid);
}

Image difference_heat_map(const Image& a, const Image& reference,
                          const std::vector<std::uint8_t>& mask, double scale, bool colour_bar) {
  assert(a.width == reference.width && a.height == reference.height &&
         a.channels == reference.channels);
  assert(mask.empty() || mask.size() == std::size_t(a.width) * a.height);
  if (!(scale > 0)) scale = std::numeric_limits<double>::min();
  const int width = a.width, height = a.height, channels = a.channels;
  Image out(width, height + (colour_bar ? kBarHeight + kLabelHeight : 0), 3, 1.0f);
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      for (int x = 0; x < width; ++x) {
        const std::size_t i = std::size_t(y) * width + x;
        float* p = out.at(x, y);
        if (!mask.empty() && !mask[i]) {
          p[0] = p[1] = p[2] = 0.2f;  // uncovered: dark grey
          continue;
        }
        double sum = 0;
        for (int c = 0; c < channels; ++c)
          sum += double(a.pixels[i * channels + c]) - reference.pixels[i * channels + c];
        if (!std::isfinite(sum)) {
          p[0] = p[1] = p[2] = 0.0f;  // NaN or infinity in an input: black
          continue;
        }
        const auto colour = difference_colour(channels > 0 ? sum / channels : 0.0, scale);
        std::copy(colour.begin(), colour.end(), p);
      }
    }
  });
  if (!colour_bar) return out;

  // The bar: −scale at the left edge, 0 in the middle, +scale at the right edge.
  for (int x = 0; x < width; ++x) {
    const double value = scale * (2.0 * (x + 0.5) / width - 1.0);
    const auto colour = difference_colour(value, scale);
    for (int y = height; y < height + kBarHeight; ++y)
      std::copy(colour.begin(), colour.end(), out.at(x, y));
  }
  draw_labels(out, scale, height + kBarHeight);
  return out;
}

double heat_map_scale(const Image& a, const Image& reference,
                      const std::vector<std::uint8_t>& mask) {
  assert(a.width == reference.width && a.height == reference.height &&
         a.channels == reference.channels);
  const std::size_t texels = std::size_t(a.width) * a.height;
  double largest = 0;
  for (std::size_t i = 0; i < texels; ++i) {
    if (!mask.empty() && !mask[i]) continue;
    double sum = 0;
    for (int c = 0; c < a.channels; ++c)
      sum += double(a.pixels[i * a.channels + c]) - reference.pixels[i * a.channels + c];
    const double mean = a.channels > 0 ? std::abs(sum / a.channels) : 0.0;
    if (std::isfinite(mean)) largest = std::max(largest, mean);
  }
  constexpr double kSmallest = 0.01;
  if (largest <= kSmallest * (1 + 1e-4)) return kSmallest;
  // 1, 2 or 5 × 10^k; the tolerance keeps a difference of 0.05 in float images (0.0500001)
  // from rounding up to 0.1.
  const double decade = std::pow(10.0, std::floor(std::log10(largest)));
  for (const double step : {1.0, 2.0, 5.0}) {
    if (step * decade >= largest * (1 - 1e-4)) return step * decade;
  }
  return 10 * decade;
}

}  // namespace sb
