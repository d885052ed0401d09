// Memory estimates against [bake] max_memory (memory_budget.h).
#include "pipeline/memory_budget.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "texels/texel_space.h"

namespace sb {

namespace {

// Bytes per texel of the arrays rasterise_texels holds while it works: `covered` and the owner
// code per texel of the image (uv_rasterizer.cpp), and a Texel per covered texel.
constexpr double kRasterBytesPerTexel = 1 + 4 + sizeof(Texel);
// A receiver's result until it is written: RGB float lightmap and the coverage byte.
constexpr double kResultBytesPerTexel = 3 * 4 + 1;
// Writing one receiver: the preview's tone-mapped copy (RGB float), its 8-bit bytes and the
// coverage mask as float and bytes (outputs.cpp, image_io.cpp).
constexpr double kWriteBytesPerTexel = 3 * 4 + 3 + 4 + 1;
// The convolution's arrays per receiver texel: the planner's frames (add_frames: tangents,
// depths, groups and indices of a light part's whole and halves at once; heaptrack measured 755 MB
// at peak for the 4.2 M texels of a floor at 2048², 180 B per texel), and while a frame is
// convolved its occlusion, largest, Euler's counts and weight gradient (about 90 B, of frames'
// texels that are the receiver's); and per light part the texel's V (12) and whether it is
// reached (1).
constexpr double kConvolutionBytesPerTexel = 180 + 90;
constexpr double kConvolutionBytesPerTexelAndLightPart = 12 + 1;

}  // namespace

std::uint64_t memory_budget(const BakeSettings& settings) {
  return settings.max_memory > 0 ? settings.max_memory : default_max_memory();
}

double total_bytes(const std::vector<MemoryItem>& items) {
  double total = 0;
  for (const MemoryItem& item : items) total += item.bytes;
  return total;
}

std::vector<MemoryItem> bake_memory_estimate(const Scene& scene) {
  const BakeSettings& b = scene.bake;
  const double texels = double(b.resolution) * double(b.resolution);
  int receivers = 0;
  for (const auto& obj : scene.objects) receivers += obj.receiver ? 1 : 0;
  std::vector<MemoryItem> items;
  items.push_back({"texel space", texels * kRasterBytesPerTexel});
  items.push_back({"lightmaps", texels * kResultBytesPerTexel * receivers});
  items.push_back({"writing", texels * kWriteBytesPerTexel});
  const double lights = double(scene.lights.size());
  if (b.method == "convolution") {
    // Parts of a light: at least light_parts; a sphere light's receiver may be seen through up to
    // six cube faces, each a frame of its own.
    const double parts = lights * std::max(b.light_parts, 1);
    items.push_back(
        {"convolution texel arrays",
         texels * (kConvolutionBytesPerTexel + kConvolutionBytesPerTexelAndLightPart * parts)});
  } else if (b.method != "reference" && b.method != "accumulation") {
    // Shadow-map baselines: a depth map (float) per light and cube face at shadow_map².
    const double map = double(b.shadow_map) * double(b.shadow_map) * 4;
    items.push_back({"shadow maps", map * lights * 6});
  }
  return items;
}

Status check_memory(const Scene& scene, const std::vector<MemoryItem>& items, std::uint64_t budget,
                    const std::string& advice) {
  const double total = total_bytes(items);
  if (total <= double(budget)) return Ok{};
  std::string parts;
  for (const MemoryItem& item : items) {
    if (item.bytes < 0.01 * total) continue;
    parts += (parts.empty() ? "" : ", ") + item.what + " " + format_bytes(item.bytes);
  }
  return scene_error(fmt::format(
      "{}: [bake] max_memory: the bake needs about {} ({}), more than max_memory = {}; {}",
      scene.file.string(), format_bytes(total), parts, format_bytes(double(budget)), advice));
}

}  // namespace sb
