// The registry of bake methods: a new method adds its entry here (one line) and its own files.
#include "methods/ambient_occlusion.h"
#include "methods/backprojection/backprojection_method.h"
#include "methods/baselines.h"
#include "methods/convolution/traced_convolution.h"
#include "methods/method.h"
#include "methods/reference_bake.h"

namespace sb {

const std::vector<MethodEntry>& method_registry() {
  static const std::vector<MethodEntry> entries = {
      backprojection_method(),    convolution_method(),         accumulation_method(),
      shadow_map_method("pcf"),   shadow_map_method("pcss"),    shadow_map_method("adaptive-pcf"),
      erosion_method(),           shadow_map_method("chun-oh"), reference_method(),
      ambient_occlusion_method(),
  };
  return entries;
}

const MethodEntry* find_method(std::string_view name) {
  for (const MethodEntry& entry : method_registry())
    if (entry.name == name) return &entry;
  return nullptr;
}

// Declared in scene/scene.h, so that the scene reader and the CLI can name the known methods
// without depending on them.
const std::vector<std::string>& known_methods() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const MethodEntry& entry : method_registry()) out.push_back(entry.name);
    return out;
  }();
  return names;
}

}  // namespace sb
