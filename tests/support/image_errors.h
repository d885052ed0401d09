// Errors of a bake against a reference or a closed form, for tests and test tools: RMSE and the
// largest absolute error, measured by compare_images (evaluation/image_metrics.h) so that tests
// and `shadowbake compare` count errors the same way. A value that should count but is NaN or
// ±inf in either image makes both figures NaN, so that a test's bound on them fails.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <stdexcept>
#include <vector>

#include "core/image.h"
#include "evaluation/image_metrics.h"
#include "pipeline/bake.h"

namespace image_errors {

struct Errors {
  double rmse = 0;         // root mean square of (image − reference); NaN when count is 0
  double max = 0;          // largest |image − reference|; NaN when count is 0
  std::int64_t count = 0;  // values compared
};

// Which texels count, beyond the mask.
enum class Region {
  covered,   // every texel of the mask
  penumbra,  // those where the reference lies strictly inside (0.02, 0.98) on some channel
};

struct Options {
  int channel = -1;  // the one channel compared; -1: every channel, pooled
  Region region = Region::covered;
};

// `image` against `reference` (same size and channels) over the texels `mask` marks (width ×
// height, nonzero counts; empty: all). A size mismatch is a broken test: it throws.
inline Errors errors(const sb::Image& image, const sb::Image& reference,
                     const std::vector<std::uint8_t>& mask = {}, const Options& options = {}) {
  sb::CompareOptions compare;
  compare.mask = mask;
  auto comparison = sb::compare_images(image, reference, compare, "the image", "its reference");
  if (!comparison) throw std::invalid_argument(comparison.error().message);
  const sb::RegionErrors& region =
      options.region == Region::covered ? comparison->covered : comparison->penumbra;
  const sb::ChannelErrors& measured =
      options.channel < 0 ? region.overall : region.channels.at(std::size_t(options.channel));
  Errors e{measured.rmse, measured.max_abs, measured.count};
  if (comparison->non_finite_a > 0 || comparison->non_finite_reference > 0)
    e.rmse = e.max = std::numeric_limits<double>::quiet_NaN();
  return e;
}

// Errors over several comparisons pooled: the RMSE of every value they compared, the largest
// error. Parts that compared nothing add nothing; a NaN part makes the pool NaN.
inline Errors pooled(const std::vector<Errors>& parts) {
  double squares = 0;
  Errors pool;
  for (const Errors& part : parts) {
    if (part.count == 0) continue;
    squares += part.rmse * part.rmse * double(part.count);
    pool.max = std::isnan(part.max) || part.max > pool.max ? part.max : pool.max;
    pool.count += part.count;
  }
  if (pool.count == 0)
    return {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(), 0};
  pool.rmse = std::sqrt(squares / double(pool.count));
  return pool;
}

// A receiver's lightmap against a reference bake's, over the texels the receiver covers.
inline Errors errors(const sb::ReceiverBake& bake, const sb::ReceiverBake& reference,
                     const Options& options = {}) {
  return errors(bake.image, reference.image, bake.covered, options);
}

// Every receiver of `bake` against the same receiver of `reference`, each over the texels it
// covers, pooled.
inline Errors errors(const sb::BakeResult& bake, const sb::BakeResult& reference,
                     const Options& options = {}) {
  if (bake.receivers.size() != reference.receivers.size())
    throw std::invalid_argument("the bakes have different receivers");
  std::vector<Errors> parts;
  for (std::size_t r = 0; r < bake.receivers.size(); ++r)
    parts.push_back(errors(bake.receivers[r], reference.receivers[r], options));
  return pooled(parts);
}

// Channel `channel` of `image` against a closed form, `expected(x, y)` at texel (x, y) (row 0 is
// the image's top), over every `stride`-th texel along both axes from (0, 0).
inline Errors errors_against(const sb::Image& image, int channel,
                             const std::function<double(int x, int y)>& expected, int stride = 1) {
  sb::Image reference = image;
  std::vector<std::uint8_t> mask(std::size_t(image.width) * std::size_t(image.height), 0);
  for (int y = 0; y < image.height; y += stride)
    for (int x = 0; x < image.width; x += stride) {
      reference.at(x, y)[channel] = float(expected(x, y));
      mask[std::size_t(y) * std::size_t(image.width) + std::size_t(x)] = 1;
    }
  return errors(image, reference, mask, {.channel = channel});
}

}  // namespace image_errors
