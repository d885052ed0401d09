// Memory estimates against [bake] max_memory (memory_budget.h).
#include "pipeline/memory_budget.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "methods/method.h"
#include "texels/lightmap_sizes.h"
#include "texels/texel_space.h"

namespace sb {

namespace {

// Bytes per texel of the arrays rasterise_texels holds while it works: `covered` and the owner
// code per texel of the image (uv_rasterizer.cpp), and a Texel per covered texel, with its shadow
// origin's lift where the mesh is curved.
constexpr double kRasterBytesPerTexel = 1 + 4 + sizeof(Texel) + sizeof(Vec3f);
// A receiver's result until it is written: RGB float lightmap and the coverage byte.
constexpr double kResultBytesPerTexel = 3 * 4 + 1;
// Writing one receiver or atlas: the preview's tone-mapped copy (RGB float), its 8-bit bytes
// and the coverage mask as float and bytes (outputs.cpp, image_io.cpp); an atlas's image is
// composed first (RGB float).
constexpr double kWriteBytesPerTexel = 3 * 4 + 3 + 4 + 1;
constexpr double kAtlasBytesPerTexel = 3 * 4;
// Per receiver, texel and light, at the texels the light reaches (by tiles, TiledImages): what
// its shadow mask needs (visibility and influence, 2 floats), counted as if kept in memory
// until written (they spill to a scratch file: an estimate from above). Its values (RGB float)
// spill as each light is finished: in memory, a whole image per light being finished or
// written, one per thread and one in the writer.
constexpr double kPerLightMaskBytesPerTexel = 2 * 4;
constexpr double kPerLightValueBytesPerTexel = 3 * 4;
constexpr double kPerLightWholeValueImages = 3;
// Faces per piece of a receiver's surface whose box a light's reach is tested against.
constexpr std::size_t kFacesPerPiece = 64;

}  // namespace

std::uint64_t memory_budget(const BakeSettings& settings) {
  return settings.max_memory > 0 ? settings.max_memory : default_max_memory();
}

double total_bytes(const std::vector<MemoryItem>& items) {
  double total = 0;
  for (const MemoryItem& item : items) total += item.bytes;
  return total;
}

std::vector<int> sides_from_settings(const Scene& scene) {
  if (scene.bake.texels_per_metre > 0) return {};
  const int side = std::min(scene.bake.resolution, largest_lightmap_side(scene));
  std::vector<int> sides;
  for (const auto& obj : scene.objects)
    if (obj.receiver) sides.push_back(side);
  return sides;
}

std::vector<MemoryItem> bake_memory_estimate(const Scene& scene, const std::vector<int>& sides) {
  const BakeSettings& b = scene.bake;
  double largest = 0, all = 0;
  for (const int side : sides) {
    const double texels = double(side) * double(side);
    largest = std::max(largest, texels);
    all += texels;
  }
  // What a file written at once holds: the largest receiver's, or an atlas.
  const double written =
      scene.output.atlas ? double(scene.output.atlas->size) * scene.output.atlas->size : largest;
  std::vector<MemoryItem> items;
  items.push_back({"texel space", largest * kRasterBytesPerTexel});
  items.push_back({"lightmaps", all * kResultBytesPerTexel});
  items.push_back({"writing", written * (kWriteBytesPerTexel +
                                         (scene.output.atlas ? kAtlasBytesPerTexel : 0))});
  // The method's own arrays and maps (its registry entry says what they are).
  if (const MethodEntry* method = find_method(b.method); method && method->memory) {
    for (MemoryItem& item : method->memory(scene, largest)) items.push_back(std::move(item));
  }
  return items;
}

std::optional<MemoryItem> per_light_memory(const Scene& scene,
                                           const std::vector<const Mesh*>& receivers,
                                           const std::vector<int>& sides,
                                           const std::vector<Light>& lights) {
  if (!scene.output.per_light && !scene.output.shadowmask) return std::nullopt;
  double total = 0;
  if (scene.output.per_light)
    for (const int side : sides)
      total = std::max(total, kPerLightWholeValueImages * kPerLightValueBytesPerTexel *
                                  double(side) * double(side));
  if (!scene.output.shadowmask) return MemoryItem{"per-light images", total};
  const double bytes = kPerLightMaskBytesPerTexel;
  for (std::size_t r = 0; r < receivers.size(); ++r) {
    // The receiver's surface in pieces of consecutive faces (a level's file keeps a room's
    // faces together), each a box and an area.
    const TriMesh& m = receivers[r]->mesh;
    std::vector<std::pair<Bounds3, double>> pieces;
    double area = 0;
    std::size_t in_piece = 0;
    for (const auto f : m.faces()) {
      if (in_piece++ % kFacesPerPiece == 0) pieces.emplace_back();
      Vec3 corner[3];
      int k = 0;
      for (const auto v : m.fv_range(f)) {
        const auto& p = m.point(v);
        corner[k] = Vec3(p[0], p[1], p[2]);
        pieces.back().first.extend(corner[k++]);
      }
      const double a = 0.5 * (corner[1] - corner[0]).cross(corner[2] - corner[0]).norm();
      pieces.back().second += a;
      area += a;
    }
    if (!(area > 0)) continue;
    // Each light's share: the pieces it may reach.
    double shares = 0;
    for (const Light& light : lights) {
      double reached = 0;
      for (const auto& [box, piece_area] : pieces)
        if (light.may_reach(box)) reached += piece_area;
      shares += reached / area;
    }
    total += double(sides[r]) * double(sides[r]) * shares * bytes;
  }
  return MemoryItem{"per-light images", total};
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
