// The `backprojection` method's bake of one receiver (backprojection_bake.h), the driver of its
// stages. Per light, as a list of stages:
//   1. tile shafts (tile_shafts.cpp): each tile of 8 × 8 texels tested as one box
//      (ShaftCuller::tile_candidates): clear, or the triangles its texels must look at, or an
//      umbra (one of them hides all of the light from the whole box);
//   2. the light's pairs (light_pairs.cpp): the evaluator of the exact estimate at a texel (its
//      shaft's polygons, back-projected onto the light);
//   3. refinement (texel_refinement.cpp): the evaluator asked at the samples the refinement
//      chooses, and interpolation inside the cells it vouches for;
//   4. the lights combined by LightMix's rule.
// A textured light and a point light are the exception: their pairs the shaft test does not
// clear take the reference's estimate (light_by_rays.cpp).
#include "methods/backprojection/backprojection_bake.h"

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>

#include <algorithm>
#include <atomic>
#include <memory>
#include <optional>
#include <span>

#include "methods/backprojection/light_by_rays.h"
#include "methods/backprojection/light_pairs.h"
#include "methods/backprojection/penumbra_estimator.h"
#include "methods/backprojection/tile_shafts.h"

namespace sb {

namespace {

// Light l's field over the receiver whose texel grid (light-independent) is `grid`, over the
// tiles `in_reach` (the rest are empty).
LightField light_field(const TexelSpace& space, const TexelGrid& grid, const TileJoins& joins,
                       const BackprojectionInputs& in, std::span<const std::uint32_t> in_reach,
                       std::size_t l) {
  const Light& light = (*in.lights)[l];
  const TileShafts tiles = tile_shafts(space, grid, joins, *in.culler, *in.rays, light,
                                       kTileCandidates, /*umbrae=*/true, in_reach);
  const std::unique_ptr<PairSource> pairs = light_pairs(space, light, in, tiles);
  return refine_light(space, grid, tiles, *pairs, in.refinement);
}

}  // namespace

LightField backprojection_light(const TexelSpace& space, const BackprojectionInputs& in,
                                std::size_t l) {
  const LightLists lists(space, *in.lights);
  const TexelGrid grid(space);
  return light_field(space, grid, TileJoins(space, grid, in.rays->surface_offset()), in,
                     lists.blocks_of(l), l);
}

MixedImages bake_backprojection(const TexelSpace& space, const BackprojectionInputs& in,
                                RouteCounts* routes) {
  const std::vector<Light>& lights = *in.lights;
  std::optional<LightLists> own;
  const LightLists& lists = in.lists ? *in.lists : own.emplace(space, lights);
  LightMix mix(space, lights, in.quantity, LightMix::Order::light_by_light, in.keep_per_light,
               &lists);
  RouteCounts counts;
  // Counted: the kept rows' texels (a tile's halo is not).
  const auto kept = kept_texels(space);
  const std::size_t kept0 = kept.first, kept1 = kept.second;
  // Built once: they do not depend on the light.
  const TexelGrid grid(space);
  const TileJoins joins(space, grid, in.rays->surface_offset());
  // Light l's field into the mix: distinct texels in parallel (LightMix::set allows it), tile by
  // tile through the grid (so that no texel's record is read), each range counting its routes.
  const auto apply = [&](std::size_t l, const LightField& field) {
    const std::span<const std::uint32_t> in_reach = lists.blocks_of(l);
    tbb::combinable<RouteCounts> local;
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, in_reach.size(), 4), [&](const auto& range) {
          RouteCounts& c = local.local();
          for (std::size_t k = range.begin(); k != range.end(); ++k) {
            const int x0 = int(in_reach[k] % std::uint32_t(lists.blocks_x())) * TileShafts::kTile;
            const int y0 = int(in_reach[k] / std::uint32_t(lists.blocks_x())) * TileShafts::kTile;
            for (int j = 0; j < TileShafts::kTile * TileShafts::kTile; ++j) {
              const int x = x0 + j % TileShafts::kTile, y = y0 + j / TileShafts::kTile;
              const std::int32_t texel = grid.texel(x, y);
              if (texel < 0) continue;
              const std::size_t t = std::size_t(texel);
              const TexelRoute route = field.route_at(x, y);
              if (route == TexelRoute::none) continue;
              mix.set(l, t, x, y, Vec3::Constant(double(field.visibility_at(x, y))));
              if (t < kept0 || t >= kept1) continue;
              ++c[route];
              if (route == TexelRoute::traced) c.rays += in.light_rows * LightRows::kCells / 2;
            }
          }
        });
    local.combine_each([&](const RouteCounts& c) {
      for (std::size_t r = 0; r < c.pairs.size(); ++r) counts.pairs[r] += c.pairs[r];
      counts.rays += c.rays;
    });
  };
  // The lights in a pipeline: a few lights' fields found at once (a level's lights each reach a
  // few tiles, too little work to keep both threads busy between a light's stages), each set
  // into the mix in scene order, so that every texel's sums add its lights in that order.
  // Lights baked by rays set the mix themselves, in their turn.
  constexpr std::size_t kLightsInFlight = 4;
  struct Step {
    std::size_t light = 0;
    std::shared_ptr<LightField> field;  // null: baked by rays, in its turn
  };
  std::size_t next = 0;
  tbb::parallel_pipeline(
      kLightsInFlight,
      tbb::make_filter<void, Step>(tbb::filter_mode::serial_in_order, [&](tbb::flow_control&
                                                                              control) {
        // The tiles the light may reach (its lists' blocks): its cost follows its reach.
        while (next < lights.size() && lists.blocks_of(next).empty()) ++next;
        if (next == lights.size()) {
          control.stop();
          return Step();
        }
        return Step{next++, nullptr};
      }) & tbb::make_filter<Step, Step>(tbb::filter_mode::parallel, [&](Step step) {
        const Light& light = lights[step.light];
        if (light.textured() || light.is_point()) return step;
        step.field = std::make_shared<LightField>(
            light_field(space, grid, joins, in, lists.blocks_of(step.light), step.light));
        return step;
      }) & tbb::make_filter<Step, void>(tbb::filter_mode::serial_in_order, [&](const Step& step) {
        const std::size_t l = step.light;
        mix.begin_light(l);
        if (step.field) {
          apply(l, *step.field);
        } else {
          bake_light_by_rays(space, grid, joins, in, lists.blocks_of(l), l,
                             lights[l].is_point() ? 1 : in.samples, mix, counts);
        }
        mix.end_light(l);
      }));
  if (routes) *routes = counts;
  return mix.finish();
}

}  // namespace sb
