// Atlas packing (atlas_packing.h) with stb_rect_pack from Debian's libstb-dev: a skyline
// bottom-left packer, which is what lightmap atlases want (squares of many sizes, no rotation).
#include "texels/atlas_packing.h"

#include <algorithm>
#include <cassert>
#include <cstddef>
#include <cstring>
#include <vector>

namespace {

// stb_rect_pack sorts with qsort, which leaves rectangles of equal size in an order the C library
// chooses; this stable sort keeps them in the order given, so a layout depends on the sides alone.
void stable_sort_rects(void* base, std::size_t count, std::size_t size,
                       int (*compare)(const void*, const void*));

}  // namespace

#define STBRP_SORT stable_sort_rects
#define STBRP_ASSERT assert
#define STB_RECT_PACK_IMPLEMENTATION
#define STBRP_STATIC
#include <stb/stb_rect_pack.h>

namespace {

void stable_sort_rects(void* base, std::size_t count, std::size_t size,
                       int (*compare)(const void*, const void*)) {
  assert(size == sizeof(stbrp_rect));
  auto* rects = static_cast<stbrp_rect*>(base);
  std::stable_sort(rects, rects + count, [compare](const stbrp_rect& a, const stbrp_rect& b) {
    return compare(&a, &b) < 0;
  });
}

}  // namespace

namespace sb {

bool RectanglePacking::all_packed() const {
  return std::all_of(packed.begin(), packed.end(), [](bool b) { return b; });
}

RectanglePacking pack_rectangles(const std::vector<std::array<int, 2>>& sizes, int width,
                                 int height) {
  std::vector<stbrp_rect> rects(sizes.size());
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    rects[i].id = int(i);
    rects[i].w = sizes[i][0];
    rects[i].h = sizes[i][1];
  }
  std::vector<stbrp_node> nodes(std::size_t(std::max(width, 1)));
  stbrp_context context;
  stbrp_init_target(&context, width, height, nodes.data(), int(nodes.size()));
  stbrp_pack_rects(&context, rects.data(), int(rects.size()));
  // stb_rect_pack returns the rectangles in the order given (it sorts back by id).
  RectanglePacking out;
  for (const stbrp_rect& r : rects) {
    out.x.push_back(r.x);
    out.y.push_back(r.y);
    out.packed.push_back(r.was_packed != 0);
  }
  return out;
}

namespace {

// Packs the padded squares of `items` (indices into sides) into one size² atlas.
RectanglePacking pack_one(const std::vector<int>& sides, const std::vector<std::size_t>& items,
                          int size, int padding) {
  std::vector<std::array<int, 2>> sizes;
  for (const std::size_t item : items)
    sizes.push_back({sides[item] + 2 * padding, sides[item] + 2 * padding});
  return pack_rectangles(sizes, size, size);
}

}  // namespace

AtlasLayout pack_atlases(const std::vector<int>& sides, const AtlasSettings& settings) {
  AtlasLayout layout;
  layout.padding = settings.padding;
  layout.placements.resize(sides.size());
  std::vector<std::size_t> remaining(sides.size());
  for (std::size_t i = 0; i < sides.size(); ++i) remaining[i] = i;
  while (!remaining.empty()) {
    const int atlas = int(layout.sizes.size());
    RectanglePacking result = pack_one(sides, remaining, settings.size, settings.padding);
    std::vector<std::size_t> placed, left;
    for (std::size_t i = 0; i < remaining.size(); ++i)
      (result.packed[i] ? placed : left).push_back(remaining[i]);
    // Every side fits an empty atlas (lightmap_sizes.h clamps them), so each round places one.
    assert(!placed.empty());
    if (placed.empty()) break;
    int size = settings.size;
    if (left.empty()) {
      // The last atlas (it holds every receiver left, in the same order): halve it while they
      // still fit.
      for (int smaller = size / 2; smaller >= 1; smaller /= 2) {
        const RectanglePacking again = pack_one(sides, placed, smaller, settings.padding);
        if (!again.all_packed()) break;
        size = smaller;
        result = again;
      }
    }
    for (std::size_t i = 0; i < remaining.size(); ++i) {
      if (!result.packed[i]) continue;
      const std::size_t item = remaining[i];
      layout.placements[item] = {atlas, result.x[i] + settings.padding,
                                 result.y[i] + settings.padding, sides[item]};
    }
    layout.sizes.push_back(size);
    remaining = std::move(left);
  }
  return layout;
}

std::array<double, 4> atlas_scale_offset(const AtlasPlacement& p, int atlas_size, bool v_up) {
  const double a = atlas_size, s = p.side / a;
  // Column X = x + u·side; row Y = y + (1 − v)·side with v up, y + v·side with v down.
  if (v_up) return {s, s, p.x / a, 1.0 - (p.y + p.side) / a};
  return {s, s, p.x / a, p.y / a};
}

}  // namespace sb
