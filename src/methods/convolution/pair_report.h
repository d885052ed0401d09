// What the convolution method decided and measured for one (light part, frustum) of a receiver:
// printed by --explain and written to the manifest (convolution_method.cpp).
#pragma once

#include <any>
#include <cstdint>
#include <string>
#include <vector>

namespace sb {

// What the convolution method decided and measured for one (light, receiver) pair: printed by
// `--explain` and written to the manifest.
struct PairReport {
  std::string light, receiver;
  std::string part;            // "" for one frustum; "+x" ... "-z" for cube faces
  double axis[3] = {0, 0, 0};  // D
  double blocker_depth_lo = 0, blocker_depth_hi = 0;    // along D, metres (0, 0: no blockers)
  double receiver_depth_lo = 0, receiver_depth_hi = 0;  // along D, metres
  double blocker_plane = 0, receiver_plane = 0;         // d*, r*, metres (source plane at 0)
  double rho_lo = 1, rho_hi = 1, rho = 1;
  double light_extent = 0;                  // L, metres
  double penumbra_error = 0;                // ε, metres on the receiver
  double penumbra_error_texels = 0;         // ε in receiver texels
  double pixel = 0;                         // blocker-image pixel, tangent units
  int image_width = 0, image_height = 0;    // blocker image, pixels
  int kernel_width = 0, kernel_height = 0;  // source kernel, pixels (odd)
  int fft_width = 0, fft_height = 0;        // transform size
  int convolutions = 0;                     // FFT convolutions done (3 per coloured leaf)
  int triples = 0;                          // leaf triples convolved
  std::int64_t lit_texels = 0;              // texels this light reaches (H0 > 0)
  std::int64_t outside_texels = 0;          // lit texels at or behind the light's plane across D
  double seconds_configure = 0, seconds_source = 0, seconds_blocker = 0, seconds_fft = 0,
         seconds_lookup = 0;
};

// A convolution bake's pair reports from MethodReport::details (empty for other methods).
inline const std::vector<PairReport>& convolution_pairs(const std::any& details) {
  static const std::vector<PairReport> none;
  const auto* pairs = std::any_cast<std::vector<PairReport>>(&details);
  return pairs ? *pairs : none;
}

}  // namespace sb
