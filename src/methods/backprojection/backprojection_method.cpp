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
    MethodReport& report = result.report;
    const double all = std::max<double>(1.0, double(routes.reached()));
    std::string explain =
        fmt::format("{} (light, texel) pairs the lights reach:", routes.reached());
    for (TexelRoute r : kTexelRoutes) {
      report.stats.emplace_back(std::string(to_string(r)) + "_fraction", double(routes[r]) / all);
      explain += fmt::format(" {} {:.1f} %", to_string(r), 100.0 * double(routes[r]) / all);
    }
    report.stats.emplace_back(
        "rays_per_texel",
        double(routes.rays) / std::max<double>(1.0, double(receiver.space->texels.size())));
    report.explain = explain + "\n";
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
          }};
}

}  // namespace sb
