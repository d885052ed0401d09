// The rays' route (light_by_rays.h): a light baked by the reference's rays alone.
#include "methods/backprojection/light_by_rays.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <vector>

#include "occluders/shadow_rays.h"

namespace sb {

// A light baked by rays alone: clear tiles and texels are 1, the rest the reference's own
// estimate at `samples` rays: a textured light's (the estimator weighs a uniform light only), or a
// point's at one ray, which is exact (its shadows are hard: nothing to estimate or interpolate).
void bake_light_by_rays(const TexelSpace& space, const TexelGrid& grid, const TileJoins& joins,
                        const BackprojectionInputs& in, std::span<const std::uint32_t> in_reach,
                        std::size_t l, int samples, LightMix& mix, RouteCounts& counts) {
  const Light& light = (*in.lights)[l];
  const double offset = in.rays->surface_offset();
  const TileShafts tiles = tile_shafts(space, grid, joins, *in.culler, *in.rays, light,
                                       kTileCandidates, /*umbrae=*/false, in_reach);
  // Counted: the kept rows' texels (a tile's halo is not).
  const auto kept = kept_texels(space);
  const std::size_t kept0 = kept.first, kept1 = kept.second;
  std::atomic<std::int64_t> clear{0}, traced{0}, rays{0};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, in_reach.size(), 1), [&](const auto& r) {
    ShadowRays batch(samples);
    std::vector<Vec2> strata;
    std::int64_t local_clear = 0, local_traced = 0, local_rays = 0;
    for (std::size_t k = r.begin(); k != r.end(); ++k) {
      const std::size_t tile = in_reach[k];
      const int x0 = int(tile % std::size_t(tiles.tiles_x)) * TileShafts::kTile;
      const int y0 = int(tile / std::size_t(tiles.tiles_x)) * TileShafts::kTile;
      for (int j = 0; j < TileShafts::kTile * TileShafts::kTile; ++j) {
        const int x = x0 + j % TileShafts::kTile, y = y0 + j / TileShafts::kTile;
        const std::int32_t texel = grid.texel(x, y);
        if (texel < 0 || !tiles.reached_at(x, y)) continue;
        const std::size_t t = std::size_t(texel);
        const Texel& tx = space.texels[t];
        const Vec3 p = tx.position.cast<double>(), n = tx.normal.cast<double>();
        const TileShafts::Patch& patch = tiles.patch(x, y);
        if (patch.kind == TileShafts::Kind::clear ||
            !in.culler->maybe_blocked(
                space.ray_origin(t, offset), p, n, light,
                patch.kind == TileShafts::Kind::listed ? &patch.candidates : nullptr)) {
          mix.set(l, t, x, y, Vec3::Ones());
          local_clear += t >= kept0 && t < kept1;
          continue;
        }
        Vec3 v;
        if (!estimate_visibility(space, t, light, *in.rays, samples, in.seed, in.stream, batch,
                                 strata, &v))
          continue;
        mix.set(l, t, x, y, v);
        if (t < kept0 || t >= kept1) continue;
        ++local_traced;
        local_rays += batch.size();
      }
    }
    clear += local_clear;
    traced += local_traced;
    rays += local_rays;
  });
  counts[TexelRoute::clear] += clear;
  counts[TexelRoute::traced] += traced;
  counts.rays += rays;
}

}  // namespace sb
