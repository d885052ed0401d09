// Dilation of a lightmap into its gutter ("edge padding"): grows the values of covered texels
// outward by `margin` rings so that bilinear filtering and mip-mapping near chart borders blend
// with plausible values instead of the uncovered background (black). Each ring of still-empty
// texels takes the per-channel mean of its already-filled 8-neighbours, the usual lightmap
// padding rule. "Empty" comes from the coverage mask, not from a texel being zero, so a covered
// texel in full shadow (value 0) still spreads.
//
// A texel filled in ring k reads only texels filled before ring k (covered, or rings < k), never
// those filled earlier in the same ring, so the result does not depend on scan order; this also
// lets each ring run its rows in parallel.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "texels/texel_space.h"

namespace sb {

void dilate(Image& image, const std::vector<std::uint8_t>& covered, int margin) {
  dilate(image, covered, margin, {}, 0);
}

void dilate(Image& image, const std::vector<std::uint8_t>& covered, int margin,
            const std::vector<std::uint8_t>& visit, int tile) {
  const int width = image.width, height = image.height, channels = image.channels;
  assert(covered.size() == std::size_t(width) * std::size_t(height));
  if (margin <= 0 || width <= 0 || height <= 0) return;
  const int tiles_x = tile > 0 ? (width + tile - 1) / tile : 0;
  const auto visited = [&](int x, int y) {
    return visit.empty() ||
           visit[std::size_t(y / tile) * std::size_t(tiles_x) + std::size_t(x / tile)];
  };
  std::vector<std::uint8_t> filled(covered.begin(), covered.end());
  std::vector<std::uint8_t> next = filled;
  for (int ring = 0; ring < margin; ++ring) {
    std::atomic<bool> any_filled = false;
    tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
      std::vector<double> sum(static_cast<std::size_t>(channels));
      bool rows_filled = false;
      for (int y = rows.begin(); y != rows.end(); ++y) {
        for (int x = 0; x < width; ++x) {
          if (!visited(x, y)) {
            x += tile - 1 - x % tile;  // past the tile
            continue;
          }
          const std::size_t index = std::size_t(y) * std::size_t(width) + std::size_t(x);
          if (filled[index]) continue;
          std::fill(sum.begin(), sum.end(), 0.0);
          int neighbours = 0;
          for (int dy = -1; dy <= 1; ++dy) {
            const int ny = y + dy;
            if (ny < 0 || ny >= height) continue;
            for (int dx = -1; dx <= 1; ++dx) {
              const int nx = x + dx;
              if ((dx == 0 && dy == 0) || nx < 0 || nx >= width) continue;
              if (!filled[std::size_t(ny) * std::size_t(width) + std::size_t(nx)]) continue;
              const float* value = image.at(nx, ny);
              for (int c = 0; c < channels; ++c) sum[std::size_t(c)] += value[c];
              ++neighbours;
            }
          }
          if (neighbours == 0) continue;
          // Writing in place is safe: this texel is not filled, so no texel of this ring reads it.
          float* value = image.at(x, y);
          for (int c = 0; c < channels; ++c) value[c] = float(sum[std::size_t(c)] / neighbours);
          next[index] = 1;
          rows_filled = true;
        }
      }
      if (rows_filled) any_filled = true;
    });
    if (!any_filled) break;
    filled = next;
  }
}

}  // namespace sb
