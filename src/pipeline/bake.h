// A whole bake: load the scene's meshes, size each receiver's lightmap (and pack them into
// atlases), build texel space per receiver, run the chosen method, dilate into the margin. The
// CLI writes the result with write_outputs (outputs.h).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/image.h"
#include "lightmaps/gltf_export.h"
#include "methods/method.h"
#include "scene/scene.h"
#include "texels/atlas_packing.h"
#include "texels/uv_checks.h"

namespace sb {

struct BakeOptions {
  int threads = 0;  // 0: all cores
  // Called from worker threads with the fraction of the bake done, in [0, 1]; may be empty.
  ProgressFn progress;
  // Per-light images to keep beyond what the scene's [output] asks for (per_light: values,
  // shadowmask: visibility).
  KeepPerLight keep_per_light;
};

struct ReceiverBake {
  std::string name;
  int uv_channel = 0;
  Image image;  // RGB, the receiver's side² (resolution, or its texels_per_metre size), dilated
  std::vector<std::uint8_t> covered;  // width × height: 1 where a triangle covers the texel
  std::int64_t covered_texels = 0;
  UvLayoutReport uv;   // the lightmap UV layout's checks
  double seconds = 0;  // texel space + method + dilation, this receiver only
  double seconds_texels = 0, seconds_method = 0, seconds_dilate = 0;  // its parts
  // Per light, in scene order, when kept: its own V (or H0·V), dilated like the image; and what
  // its shadow mask needs (MixedImages::per_light_visibility, its influence cleared beyond its
  // shadowmask_range), dilated too.
  std::vector<Image> per_light;
  std::vector<Image> per_light_visibility;
  // The receiver's mesh as a glTF carries it, when [output] gltf.
  std::shared_ptr<const GltfMesh> gltf_mesh;
  // What the method reports beyond its values: named figures, its own manifest entries and
  // what --explain prints (its warnings are in BakeResult::warnings).
  MethodReport report;
};

struct BakeResult {
  std::vector<ReceiverBake> receivers;  // in scene order
  std::vector<std::string> warnings;    // e.g. degenerate triangles skipped
  // The receivers' places in atlases ([output] atlas), placements in receiver order.
  std::optional<AtlasLayout> atlas;
  // With [output] shadowmask, each light's channel (lightmaps/shadowmask.h); the lights left
  // out are warnings.
  std::vector<int> shadowmask_channels;
  // With [output] gltf, the objects that are blockers only, in scene order, as a glTF shows them.
  std::vector<std::pair<std::string, std::shared_ptr<const GltfMesh>>> gltf_blockers;
  double load_seconds = 0;       // mesh import and acceleration structures
  double bake_seconds = 0;       // all receivers: texel space, method, dilation
  std::int64_t shadow_rays = 0;  // rays traced, for sampling methods
};

// Bakes scene.bake.method for every receiver. Errors name the scene file and the item.
Expected<BakeResult> bake(const Scene& scene, const BakeOptions& options = {});

// The convolution method's plan for every receiver (describe_plan's text, in scene order),
// without convolving: what `shadowbake plan` prints.
Expected<std::vector<std::string>> plan(const Scene& scene, const BakeOptions& options = {});

}  // namespace sb
