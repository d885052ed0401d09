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
#include "methods/method.h"
#include "scene/scene.h"
#include "texels/uv_checks.h"

namespace sb {

struct BakeOptions {
  int threads = 0;  // 0: all cores
  // Called from worker threads with the fraction of the bake done, in [0, 1]; may be empty.
  ProgressFn progress;
  bool keep_per_light = false;  // ReceiverBake::per_light wanted
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
  // Per light, in scene order, when BakeOptions::keep_per_light: its own V (or H0·V), dilated
  // like the image.
  std::vector<Image> per_light;
  // What the method reports beyond its values: named figures, its own manifest entries and
  // what --explain prints (its warnings are in BakeResult::warnings).
  MethodReport report;
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
