// Stage 1 of the `backprojection` bake: the tiles' shaft tests (tile_shafts.h).
#include "methods/backprojection/tile_shafts.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "methods/backprojection/penumbra_estimator.h"

namespace sb {

bool hides_from_all(const Light& light, const Vec3* corners, std::span<const Vec3> points,
                    double offset) {
  for (const Vec3& p : points)
    if (!triangle_hides_light(light, corners, p, offset)) return false;
  return true;
}

TileShafts tile_shafts(const TexelSpace& space, const TexelGrid& grid, const ShaftCuller& culler,
                       const Light& light, double offset, std::size_t max, bool umbrae) {
  static_assert(TileShafts::kTile == TexelBlock::kSide, "a tile is a block of the texel space");
  TileShafts tiles;
  constexpr int k = TileShafts::kTile;
  tiles.tiles_x = (space.width + k - 1) / k;
  tiles.tiles_y = (space.height + k - 1) / k;
  const std::size_t count = std::size_t(tiles.tiles_x) * std::size_t(tiles.tiles_y);
  tiles.kind.assign(count, TileShafts::Kind::empty);
  tiles.candidates.resize(count);
  std::vector<Bounds3>& boxes = tiles.origins;
  boxes.assign(count, Bounds3());
  tiles.reached.resize(space.texels.size());  // every texel's written below
  const bool blocks = space.blocks.size() == count;
  // Bands of kGroup tile rows in parallel, each in one pass over its texels through the grid.
  // A tile whose block shares one normal and that the light reaches all of (the sun over flat
  // ground) takes its box from the block, shifted as each ray origin is (the same box: rounding
  // is monotonic), and its texels' records are not read.
  constexpr int g = TileShafts::kGroup;
  const auto test = [&](std::size_t i, const std::vector<std::uint32_t>* among) {
    std::vector<std::uint32_t>& list = tiles.candidates[i];
    if (!culler.tile_candidates(boxes[i], light, max, list, among)) {
      tiles.kind[i] = TileShafts::Kind::clear;
    } else if (list.empty()) {
      tiles.kind[i] = TileShafts::Kind::all;
    } else {
      tiles.kind[i] = TileShafts::Kind::listed;
      std::sort(list.begin(), list.end());
      if (!umbrae) return;
      std::array<Vec3, 8> corners;
      for (int k = 0; k < 8; ++k) corners[std::size_t(k)] = boxes[i].corner(k);
      for (std::uint32_t c : list)
        if (hides_from_all(light, culler.triangle_corners(c), corners, offset)) {
          tiles.kind[i] = TileShafts::Kind::umbra;
          return;
        }
    }
  };
  tbb::parallel_for(tbb::blocked_range<int>(0, (tiles.tiles_y + g - 1) / g), [&](const auto& r) {
    const int ty0 = r.begin() * g, ty1 = std::min(r.end() * g, tiles.tiles_y);
    const std::size_t first_tile = std::size_t(ty0) * std::size_t(tiles.tiles_x);
    thread_local std::vector<std::uint8_t> whole;  // per tile of the band
    whole.assign(std::size_t(ty1 - ty0) * std::size_t(tiles.tiles_x), 0);
    for (std::size_t i = first_tile; blocks && i < first_tile + whole.size(); ++i) {
      const TexelBlock& b = space.blocks[i];
      if (!b.uniform || b.empty()) continue;
      Bounds3 positions;
      positions.extend(b.lo.cast<double>());
      positions.extend(b.hi.cast<double>());
      if (!light.reaches_all(positions, b.normal.cast<double>())) continue;
      whole[i - first_tile] = 1;
      const Vec3 shift = offset * b.geometric.cast<double>();
      boxes[i].extend(Vec3(b.lo.cast<double>() + shift));
      boxes[i].extend(Vec3(b.hi.cast<double>() + shift));
    }
    grid.for_each(ty0 * k, std::min(space.height, ty1 * k), [&](std::size_t t, int x, int y) {
      const std::size_t tile = tiles.tile_of(x, y);
      if (whole[tile - first_tile]) {
        tiles.reached[t] = 1;
        return;
      }
      const Texel& tx = space.texels[t];
      tiles.reached[t] = light.reaches(tx.position.cast<double>(), tx.normal.cast<double>());
      if (tiles.reached[t]) boxes[tile].extend(space.ray_origin(t, offset));
    });
    // A group of g × g tiles whose joint box's shaft is clear is clear throughout (each tile's
    // shaft lies inside it); otherwise its tiles are tested one by one, among the group's
    // candidates where it listed them (a tile's shaft lies inside the group's, so every triangle
    // in it is among them) rather than down the whole hierarchy again.
    thread_local std::vector<std::uint32_t> group_list;
    for (int gy = ty0; gy < ty1; gy += g)
      for (int gx = 0; gx < tiles.tiles_x; gx += g) {
        const int x1 = std::min(gx + g, tiles.tiles_x), y1 = std::min(gy + g, ty1);
        Bounds3 joint;
        int filled = 0;
        for (int ty = gy; ty < y1; ++ty)
          for (int tx = gx; tx < x1; ++tx) {
            const Bounds3& b = boxes[std::size_t(ty) * std::size_t(tiles.tiles_x) + tx];
            if (b.empty()) continue;
            joint.extend(b);
            ++filled;
          }
        if (filled == 0) continue;
        const bool clear = filled > 1 && !culler.tile_candidates(joint, light, max, group_list);
        for (int ty = gy; ty < y1; ++ty)
          for (int tx = gx; tx < x1; ++tx) {
            const std::size_t i = std::size_t(ty) * std::size_t(tiles.tiles_x) + tx;
            if (boxes[i].empty()) continue;
            if (clear)
              tiles.kind[i] = TileShafts::Kind::clear;
            else
              test(i, filled > 1 && !group_list.empty() ? &group_list : nullptr);
          }
      }
  });
  return tiles;
}

}  // namespace sb
