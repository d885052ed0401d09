// The first stage of a bake (bake_stages.h): which method, and whether the settings go together.
#include <fmt/format.h>

#include <algorithm>

#include "pipeline/bake_stages.h"

namespace sb {

namespace {

// The [bake] keys every bake reads, whatever its method.
bool read_by_every_method(const std::string& key) {
  for (const char* k :
       {"resolution", "texels_per_metre", "method", "quantity", "margin", "seams", "max_memory"})
    if (key == k) return true;
  return false;
}

// "file:line: [bake] key: method 'm' does not use it (...)" for each key the scene sets that the
// chosen method does not read, naming the methods that do.
void report_ignored_settings(const Scene& scene, const MethodEntry& method,
                             std::vector<std::string>* warnings) {
  for (const SettingGiven& given : scene.bake_keys) {
    if (read_by_every_method(given.key)) continue;
    if (method.reads(given.key)) continue;
    std::string users;
    for (const MethodEntry& other : method_registry())
      if (other.reads(given.key)) users += (users.empty() ? "" : ", ") + other.name;
    warnings->push_back(fmt::format("{}:{}: [bake] {}: method '{}' does not use it (read by {})",
                                    scene.file.string(), given.line, given.key, method.name,
                                    users));
  }
}

}  // namespace

Expected<const MethodEntry*> check_request(const Scene& scene, std::vector<std::string>* warnings) {
  const MethodEntry* entry = find_method(scene.bake.method);
  if (!entry) {
    std::string known;
    for (const auto& m : known_methods()) known += (known.empty() ? "" : ", ") + m;
    return scene_error(scene.file.string() + ": [bake]: unknown method '" + scene.bake.method +
                       "' (known: " + known + ")");
  }
  const bool ambient_occlusion = scene.bake.quantity == Quantity::ambient_occlusion;
  {
    BakeSettings settings = scene.bake;
    if (Status paired =
            pair_quantity_and_method(settings, method_baking_only(Quantity::ambient_occlusion),
                                     true, true, scene.file.string() + ": [bake]");
        !paired)
      return paired.error();
  }
  if (ambient_occlusion && (scene.output.per_light || scene.output.shadowmask))
    return scene_error(scene.file.string() +
                       ": [output]: per-light images and shadow masks are images of lights; an "
                       "ambient-occlusion bake has none (leave out per_light and shadowmask)");
  if (!ambient_occlusion && scene.lights.empty())
    return scene_error(scene.file.string() + ": no light: a " + to_string(scene.bake.quantity) +
                       " bake needs at least one (an ambient-occlusion bake needs none)");
  report_ignored_settings(scene, *entry, warnings);
  return entry;
}

}  // namespace sb
