// Stage 3 of the `backprojection` bake (backprojection_bake.cpp), per light: adaptive texel
// sampling over one receiver (texel_refinement.cpp): stage 2's exact estimate (light_pairs.h) at
// the corners and centres of cells of 8, 4 and 2 texels, interpolated inside a cell only where
// its checks pass, and evaluated texel by texel where they fail. Possible only because the
// estimates have no noise: a sample that disagrees with its neighbours' prediction is a real
// change in the field, not chance.
#pragma once

#include <cstdint>
#include <vector>

#include "core/fresh_memory.h"
#include "methods/backprojection/backprojection_settings.h"
#include "methods/backprojection/light_pairs.h"
#include "methods/backprojection/texel_grid.h"
#include "methods/backprojection/texel_routes.h"
#include "methods/backprojection/tile_shafts.h"
#include "texels/texel_space.h"

namespace sb {

// One light's visibility at every covered texel of a receiver, and the route each came by, by
// tile: a clear or umbra tile all of whose covered texels the light reaches holds one value for
// them all (1 or 0), an empty one none; the rest — the cells' tiles, the umbrae whose texels are
// their corners, the tiles the light reaches in part — hold their texels' own, kTile² each. Under
// a sun at 4096² that is a fifth of the texels: the refinement's per-texel arrays (these, and its
// own state and samples) are written for those alone.
struct LightField {
  int tiles_x = 0;
  std::vector<std::int32_t> slot;      // per tile: its place in `visibility` and `route`, or -1
  std::vector<TexelRoute> tile_route;  // per tile without a place: its texels' route
  // Per texel of the tiles with a place, row-major within the tile; 1 where the route is none.
  FreshVector<float> visibility;
  FreshVector<TexelRoute> route;

  // The texel at pixel (x, y): its index in the arrays above, or -1 where its tile has none.
  std::int64_t index(int x, int y) const {
    constexpr int k = TileShafts::kTile;
    const std::int32_t s = slot[std::size_t(y / k) * std::size_t(tiles_x) + std::size_t(x / k)];
    return s < 0 ? -1 : std::int64_t(s) * k * k + (y % k) * k + x % k;
  }
  TexelRoute route_at(int x, int y) const {
    constexpr int k = TileShafts::kTile;
    const std::int64_t i = index(x, y);
    return i >= 0 ? route[std::size_t(i)]
                  : tile_route[std::size_t(y / k) * std::size_t(tiles_x) + std::size_t(x / k)];
  }
  float visibility_at(int x, int y) const {
    const std::int64_t i = index(x, y);
    return i >= 0 ? visibility[std::size_t(i)] : route_at(x, y) == TexelRoute::umbra ? 0.0f : 1.0f;
  }
};

// The light's field over the receiver: stage 1's tile shafts say where to start, and `source`,
// stage 2's evaluator of the light's pairs, gives the samples the refinement asks for.
LightField refine_light(const TexelSpace& space, const TexelGrid& grid, const TileShafts& tiles,
                        const PairSource& source, const RefinementSettings& settings);

}  // namespace sb
