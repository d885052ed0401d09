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
  BaselineMethod(const BakeContext& context, Bake bake)
      : context_(context), settings_(baseline_settings(context.scene->bake)), bake_(bake) {}

  Expected<MethodResult> bake(const ReceiverInput& receiver) override {
    BaselineInputs in;
    in.lights = context_.lights;
    in.rays = context_.rays;
    in.blockers = context_.blockers;
    in.receiver = receiver.mesh;
    in.settings = settings_;
    in.stream = receiver.stream;
    in.keep_per_light = context_.keep_per_light;
    MethodResult result;
    result.images = bake_(*receiver.space, in, &result.report.stats, &result.rays);
    return result;
  }

 private:
  BakeContext context_;
  BaselineSettings settings_;
  Bake bake_;
};

}  // namespace

BaselineSettings baseline_settings(const BakeSettings& bake) {
  BaselineSettings s;
  s.method = bake.method;
  s.quantity = bake.quantity;
  s.samples = bake.samples;
  s.seed = bake.seed;
  s.shadow_map = int(setting_whole(bake, "shadow_map"));
  s.pcf_radius = setting_number(bake, "pcf_radius");
  s.erosion_by_distance = setting_word(bake, "erosion_factor") == "distance";
  return s;
}

namespace {

// Shadow-map baselines hold a depth map (float) per light and cube face at shadow_map², and,
// running light by light, every light's V per texel until the lights are mixed (LightMix).
std::vector<MemoryItem> shadow_map_memory(const Scene& scene, double texels) {
  const BakeSettings& b = scene.bake;
  const double lights = double(scene.lights.size());
  const double side = double(setting_whole(b, "shadow_map")), map = side * side * 4;
  return {{"shadow maps", map * lights * 6},
          {"per-light visibility", texels * lights * (sizeof(Vec3f) + 1)}};
}

MethodEntry baseline_entry(std::string name, std::vector<std::string> settings,
                           std::vector<SettingSpec> own, bool rays, BaselineMethod::Bake bake,
                           std::function<std::vector<MemoryItem>(const Scene&, double)> memory) {
  MethodEntry e;
  e.name = std::move(name);
  e.settings = std::move(settings);
  e.own_settings = std::move(own);
  e.needs = [rays](const BakeSettings&) { return MethodNeeds{.rays = rays}; };
  e.memory = std::move(memory);
  e.make = [bake](const BakeContext& context) -> Expected<std::unique_ptr<Method>> {
    return std::unique_ptr<Method>(std::make_unique<BaselineMethod>(context, bake));
  };
  e.tile_halo = -1;  // shadow maps and clusters fitted to the whole receiver
  e.local = false;   // and to the whole scene
  return e;
}

}  // namespace

MethodEntry accumulation_method() {
  return baseline_entry("accumulation", {"samples", "seed"}, {}, true, bake_accumulation, nullptr);
}

MethodEntry erosion_method() {
  return baseline_entry(
      "erosion", {}, {word_setting("erosion_factor", "pcf", {"pcf", "distance"})}, true,
      [](const TexelSpace& space, const BaselineInputs& in, MethodStats* stats,
         std::int64_t* rays) { return bake_erosion(space, in, stats, rays); },
      shadow_map_memory);
}

MethodEntry shadow_map_method(const std::string& name) {
  std::vector<std::string> settings;
  std::vector<SettingSpec> own = {whole_setting("shadow_map", 2048, 64, 16384)};
  if (name == "pcf")
    own.push_back(
        number_setting("pcf_radius", 2.0, "a number >= 0", [](double x) { return x >= 0; }));
  if (name == "adaptive-pcf") settings = {"samples", "seed"};
  return baseline_entry(
      name, settings, own, false,
      [](const TexelSpace& space, const BaselineInputs& in, MethodStats* stats, std::int64_t*) {
        return bake_shadow_map_filter(space, in, stats);
      },
      shadow_map_memory);
}

}  // namespace sb
