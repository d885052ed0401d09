// A whole bake: load the scene's meshes, build texel space per receiver, run the chosen method,
// dilate into the margin. The CLI writes the result with write_outputs (outputs.h).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/image.h"
#include "scene/scene.h"
#include "texels/uv_checks.h"

namespace sb {

// Called from worker threads with the fraction of the bake done, in [0, 1]; must be
// thread-safe and cheap.
using ProgressFn = std::function<void(double fraction)>;

struct BakeOptions {
  int threads = 0;      // 0: all cores
  ProgressFn progress;  // may be empty
};

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

struct ReceiverBake {
  std::string name;
  int uv_channel = 0;
  Image image;                        // RGB, width × height of the bake resolution, dilated
  std::vector<std::uint8_t> covered;  // width × height: 1 where a triangle covers the texel
  std::int64_t covered_texels = 0;
  UvLayoutReport uv;   // the lightmap UV layout's checks
  double seconds = 0;  // texel space + method + dilation, this receiver only
  double seconds_texels = 0, seconds_method = 0, seconds_dilate = 0;  // its parts
  std::vector<PairReport> pairs;  // per (light part, frustum), for the convolution method
  std::string plan;               // the convolution's triples as text (describe_plan)
  // Named figures of the method for this receiver (baselines.h), e.g. adaptive PCF's fraction
  // of texels that took the full filter.
  std::vector<std::pair<std::string, double>> stats;
};

struct BakeResult {
  std::vector<ReceiverBake> receivers;  // in scene order
  std::vector<std::string> warnings;    // e.g. degenerate triangles skipped
  double load_seconds = 0;              // mesh import and acceleration structures
  double bake_seconds = 0;              // all receivers: texel space, method, dilation
  std::int64_t shadow_rays = 0;         // rays traced, for sampling methods
};

// Bakes scene.bake.method for every receiver. Errors name the scene file and the item.
Expected<BakeResult> bake(const Scene& scene, const BakeOptions& options = {});

// The convolution method's plan for every receiver (describe_plan's text, in scene order),
// without convolving: what `shadowbake plan` prints.
Expected<std::vector<std::string>> plan(const Scene& scene, const BakeOptions& options = {});

}  // namespace sb
