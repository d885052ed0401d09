// Memory estimates against [bake] max_memory (memory_budget.h).
#include "pipeline/memory_budget.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "methods/method.h"
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
  // The method's own arrays and maps (its registry entry says what they are).
  if (const MethodEntry* method = find_method(b.method); method && method->memory) {
    for (MemoryItem& item : method->memory(scene)) items.push_back(std::move(item));
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
