// The registry's entries of the baselines (baselines.h): accumulation, erosion and the
// shadow-map filters, each one receiver at a time through its bake function.
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "methods/baselines.h"

namespace sb {

namespace {

// accumulation, erosion and the shadow-map filters: one receiver through their bake function.
class BaselineMethod final : public Method {
 public:
  using Bake = std::function<MixedImages(const TexelSpace&, const BaselineInputs&, MethodStats*,
                                         std::int64_t*)>;
  BaselineMethod(const BakeContext& context, Bake bake) : context_(context), bake_(bake) {}

  Expected<MethodResult> bake(const ReceiverInput& receiver) override {
    BaselineInputs in;
    in.lights = context_.lights;
    in.rays = context_.rays;
    in.blockers = context_.blockers;
    in.receiver = receiver.mesh;
    in.settings = &context_.scene->bake;
    in.stream = receiver.stream;
    in.keep_per_light = context_.keep_per_light;
    MethodResult result;
    result.images = bake_(*receiver.space, in, &result.report.stats, &result.rays);
    return result;
  }

 private:
  BakeContext context_;
  Bake bake_;
};

// Shadow-map baselines hold a depth map (float) per light and cube face at shadow_map², and,
// running light by light, every light's V per texel until the lights are mixed (LightMix).
std::vector<MemoryItem> shadow_map_memory(const Scene& scene, double texels) {
  const BakeSettings& b = scene.bake;
  const double lights = double(scene.lights.size());
  const double map = double(b.shadow_map) * double(b.shadow_map) * 4;
  return {{"shadow maps", map * lights * 6},
          {"per-light visibility", texels * lights * (sizeof(Vec3f) + 1)}};
}

MethodEntry baseline_entry(std::string name, std::vector<std::string> settings, bool rays,
                           BaselineMethod::Bake bake,
                           std::function<std::vector<MemoryItem>(const Scene&, double)> memory) {
  return {std::move(name),
          std::move(settings),
          [rays](const BakeSettings&) { return MethodNeeds{.rays = rays}; },
          std::move(memory),
          [bake](const BakeContext& context) -> Expected<std::unique_ptr<Method>> {
            return std::unique_ptr<Method>(std::make_unique<BaselineMethod>(context, bake));
          },
          /*tile_halo=*/-1,  // shadow maps and clusters fitted to the whole receiver
          nullptr};
}

}  // namespace

MethodEntry accumulation_method() {
  return baseline_entry("accumulation", {"samples", "seed"}, true, bake_accumulation, nullptr);
}

MethodEntry erosion_method() {
  return baseline_entry(
      "erosion", {"erosion_factor"}, true,
      [](const TexelSpace& space, const BaselineInputs& in, MethodStats* stats,
         std::int64_t* rays) { return bake_erosion(space, in, stats, rays); },
      shadow_map_memory);
}

MethodEntry shadow_map_method(const std::string& name) {
  std::vector<std::string> settings = {"shadow_map"};
  if (name == "pcf") settings.push_back("pcf_radius");
  if (name == "adaptive-pcf") settings.insert(settings.end(), {"samples", "seed"});
  return baseline_entry(
      name, settings, false,
      [](const TexelSpace& space, const BaselineInputs& in, MethodStats* stats, std::int64_t*) {
        return bake_shadow_map_filter(space, in, stats);
      },
      shadow_map_memory);
}

}  // namespace sb
