// Error metrics between a baked texture and a reference (image_metrics.cpp): what `shadowbake
// compare` prints and `shadowbake report` tabulates. docs/reports.md explains each.
#pragma once

#include <cstdint>
#include <vector>

#include "core/error.h"
#include "core/image.h"

namespace sb {

// Errors of one channel, or of all channels pooled, over one set of texels.
struct ChannelErrors {
  std::int64_t count = 0;                        // values compared
  double rmse = 0;                               // root mean square of (a − reference)
  double mae = 0;                                // mean of |a − reference|
  double max_abs = 0;                            // largest |a − reference| ...
  int max_x = -1, max_y = -1, max_channel = -1;  // ... and where (row 0 is the image's top)
  double psnr = 0;                               // 10·log10(peak² / MSE), dB; +inf when MSE is 0
  double ssim = 0;  // mean SSIM over the set's texels (Wang et al. 2004)
};

struct RegionErrors {
  std::int64_t texels = 0;
  ChannelErrors overall;
  std::vector<ChannelErrors> channels;  // one per channel
};

struct Comparison {
  int width = 0, height = 0, channels = 0;
  RegionErrors covered;   // texels of the mask (every texel when there is none)
  RegionErrors penumbra;  // covered texels where the reference is strictly inside (lo, hi)
  // Texels holding NaN or ±inf in either image: reported, and left out of every metric.
  std::int64_t non_finite_a = 0, non_finite_reference = 0;
  double peak = 1;  // the PSNR peak used
};

struct CompareOptions {
  // Which texels count (width × height, nonzero = counts); empty: all of them. Lightmap texels
  // that no triangle covers must not count, so bakes write their coverage (<name>.coverage.png).
  std::vector<std::uint8_t> mask;
  double penumbra_lo = 0.02, penumbra_hi = 0.98;  // on any channel of the reference
  double peak = 1.0;  // PSNR peak; 0: the reference's largest covered value (for irradiance)
};

// Compares `a` with `reference`. Errors (ErrorKind::input) for different sizes or channel
// counts, or a mask of the wrong size; `a_name` and `reference_name` name them in messages.
Expected<Comparison> compare_images(const Image& a, const Image& reference,
                                    const CompareOptions& options, const std::string& a_name,
                                    const std::string& reference_name);

// SSIM map of one channel (Wang, Bovik, Sheikh & Simoncelli, "Image Quality Assessment: From
// Error Visibility to Structural Similarity", IEEE TIP 2004): 11 × 11 Gaussian window, σ = 1.5,
// C1 = (0.01·L)², C2 = (0.03·L)² with L = dynamic_range; window weights renormalised at the
// border. Exposed for tests.
std::vector<double> ssim_map(const Image& a, const Image& b, int channel, double dynamic_range);

// A signed difference heat map, a − reference averaged over channels, as RGB: blue below zero,
// white at zero, red above, saturating at ±scale; uncovered texels (mask 0) dark grey. With
// `colour_bar`, a bar from −scale to +scale with its end values written under it is appended
// below the image.
Image difference_heat_map(const Image& a, const Image& reference,
                          const std::vector<std::uint8_t>& mask, double scale, bool colour_bar);

// A readable saturation for difference_heat_map: the largest |mean over channels of
// (a − reference)| over the texels of `mask` (all when empty) that are finite in both, rounded up
// to 1, 2 or 5 × a power of ten, and at least 0.01. Needs images of the same size and channels.
double heat_map_scale(const Image& a, const Image& reference,
                      const std::vector<std::uint8_t>& mask);

}  // namespace sb
