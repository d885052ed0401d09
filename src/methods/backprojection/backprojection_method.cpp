// The `backprojection` method's entry in the registry: its settings, what it needs built (the
// ray scene for the surface offset and the traced route, the shaft culler), and what it reports
// per receiver: the share of (light, texel) pairs each route took (method_stats), and the rays
// traced.
#include "methods/backprojection/backprojection_method.h"

#include <fmt/format.h>

#include <cstdint>
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

// The method's settings from the [bake] table, read once per bake.
BackprojectionSettings backprojection_settings(const BakeSettings& bake) {
  BackprojectionSettings s;
  s.quantity = bake.quantity;
  s.light_rows = int(setting_whole(bake, "light_rows"));
  s.max_polygons = int(setting_whole(bake, "max_polygons"));
  s.refinement.max_cell = int(setting_whole(bake, "max_cell"));
  s.refinement.tolerance = setting_number(bake, "interpolation_tolerance");
  s.refinement.midpoint_cells = setting_number(bake, "midpoint_cells");
  s.samples = bake.samples;
  s.seed = bake.seed;
  return s;
}

class BackprojectionMethod final : public Method {
 public:
  explicit BackprojectionMethod(const BakeContext& context)
      : context_(context), settings_(backprojection_settings(context.scene->bake)) {}

  Expected<MethodResult> bake(const ReceiverInput& receiver) override {
    BackprojectionInputs in;
    static_cast<BackprojectionSettings&>(in) = settings_;
    in.lights = context_.lights;
    in.culler = context_.shafts;
    in.rays = context_.rays;
    in.stream = receiver.stream;
    in.keep_per_light = context_.keep_per_light;
    in.lists = receiver.lists;
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
  BackprojectionSettings settings_;
};

}  // namespace

MethodEntry backprojection_method() {
  const BackprojectionSettings defaults;  // the defaults of its own keys
  MethodEntry e;
  e.name = "backprojection";
  e.settings = {"samples", "seed"};
  e.own_settings = {
      whole_setting("light_rows", defaults.light_rows, 4, 64),
      whole_setting("max_polygons", defaults.max_polygons, 0, 1 << 20),
      whole_setting(
          "max_cell", defaults.refinement.max_cell, 1, 8, "1, 2, 4 or 8",
          [](std::int64_t cell) { return cell == 1 || cell == 2 || cell == 4 || cell == 8; }),
      number_setting("interpolation_tolerance", defaults.refinement.tolerance,
                     "a number >= 0 and < 1", [](double x) { return x >= 0 && x < 1; }),
      number_setting("midpoint_cells", defaults.refinement.midpoint_cells, "a number >= 0",
                     [](double x) { return x >= 0; })};
  e.needs = [](const BakeSettings&) { return MethodNeeds{.rays = true, .shafts = true}; };
  e.make = [](const BakeContext& context) -> Expected<std::unique_ptr<Method>> {
    return std::unique_ptr<Method>(std::make_unique<BackprojectionMethod>(context));
  };
  e.tile_halo = kBackprojectionHalo;
  e.summarise = summarise_routes;
  e.local = true;
  return e;
}

}  // namespace sb
