// A whole bake: load the scene's meshes, build texel space per receiver, run the chosen method,
// dilate into the margin. The CLI writes the result with write_outputs (outputs.h).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "error.h"
#include "image.h"
#include "scene.h"

namespace sb {

// Called from worker threads with the fraction of the bake done, in [0, 1]; must be
// thread-safe and cheap.
using ProgressFn = std::function<void(double fraction)>;

struct BakeOptions {
  int threads = 0;      // 0: all cores
  ProgressFn progress;  // may be empty
};

struct ReceiverBake {
  std::string name;
  int uv_channel = 0;
  Image image;  // RGB, width × height of the bake resolution, dilated
  std::int64_t covered_texels = 0;
  double seconds = 0;  // texel space + method + dilation, this receiver only
};

struct BakeResult {
  std::vector<ReceiverBake> receivers;  // in scene order
  std::vector<std::string> warnings;    // e.g. degenerate triangles skipped
  double load_seconds = 0;              // mesh import and acceleration structures
  double bake_seconds = 0;              // all receivers
  std::int64_t shadow_rays = 0;         // rays traced, for sampling methods
};

// Bakes scene.bake.method for every receiver. Errors name the scene file and the item.
Expected<BakeResult> bake(const Scene& scene, const BakeOptions& options = {});

}  // namespace sb
