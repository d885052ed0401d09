// The `backprojection` method's entry in the registry: its settings, what it needs built (the
// ray scene for the surface offset and the traced route, the shaft culler), and what it reports
// per receiver: the share of (light, texel) pairs each route took (method_stats), and the rays
// traced.
#include "methods/backprojection/backprojection_method.h"

#include <fmt/format.h>

#include <string>

#include "methods/backprojection/backprojection_bake.h"

namespace sb {

namespace {

// A texel's value depends on its tile of 8 × 8 texels and the tiles around it (their cells'
// corners, texel_refinement.cpp), and a tile's shaft test on its group of kGroup × kGroup tiles:
// a tile of rows, its borders on groups, holds a group of tile rows on each side.
constexpr int kBackprojectionHalo = TileShafts::kTile * TileShafts::kGroup;
static_assert(kTileRows % kBackprojectionHalo == 0, "tiles' borders must lie on tile groups");

// Its stats and explain from its tallies: the share of (light, texel) pairs each route took, and
// the rays per texel.
void summarise_routes(MethodReport& report) {
  const auto tally = [&](std::string_view name) {
    for (const auto& [key, count] : report.tallies)
      if (key == name) return count;
    return std::int64_t(0);
  };
  std::int64_t reached = 0;
  for (TexelRoute r : kTexelRoutes) reached += tally(to_string(r));
  const double all = std::max<double>(1.0, double(reached));
  report.stats.clear();
  std::string explain = fmt::format("{} (light, texel) pairs the lights reach:", reached);
  for (TexelRoute r : kTexelRoutes) {
    const double share = double(tally(to_string(r))) / all;
    report.stats.emplace_back(std::string(to_string(r)) + "_fraction", share);
    explain += fmt::format(" {} {:.1f} %", to_string(r), 100.0 * share);
  }
  report.stats.emplace_back("rays_per_texel",
                            double(tally("rays")) / std::max<double>(1.0, double(tally("texels"))));
  report.explain = explain + "\n";
}

class BackprojectionMethod final : public Method {
 public:
  explicit BackprojectionMethod(const BakeContext& context) : context_(context) {}

  Expected<MethodResult> bake(const ReceiverInput& receiver) override {
    const BakeSettings& settings = context_.scene->bake;
    BackprojectionInputs in;
    in.lights = context_.lights;
    in.culler = context_.shafts;
    in.rays = context_.rays;
    in.quantity = settings.quantity;
    in.light_rows = settings.light_rows;
    in.max_polygons = settings.max_polygons;
    in.refinement.max_cell = settings.max_cell;
    in.refinement.tolerance = settings.interpolation_tolerance;
    in.samples = settings.samples;
    in.seed = settings.seed;
    in.stream = receiver.stream;
    in.keep_per_light = context_.keep_per_light;
    RouteCounts routes;
    MethodResult result;
    result.images = bake_backprojection(*receiver.space, in, &routes);
    result.rays = routes.rays;
    for (TexelRoute r : kTexelRoutes)
      result.report.tallies.emplace_back(std::string(to_string(r)), routes[r]);
    result.report.tallies.emplace_back("rays", routes.rays);
    const auto [first, last] = kept_texels(*receiver.space);
    result.report.tallies.emplace_back("texels", std::int64_t(last - first));
    summarise_routes(result.report);
    return result;
  }

 private:
  BakeContext context_;
};

}  // namespace

MethodEntry backprojection_method() {
  return {"backprojection",
          {"light_rows", "max_polygons", "max_cell", "interpolation_tolerance", "samples", "seed"},
          [](const BakeSettings&) { return MethodNeeds{.rays = true, .shafts = true}; },
          nullptr,
          [](const BakeContext& context) -> Expected<std::unique_ptr<Method>> {
            return std::unique_ptr<Method>(std::make_unique<BackprojectionMethod>(context));
          },
          kBackprojectionHalo,
          summarise_routes};
}

}  // namespace sb
