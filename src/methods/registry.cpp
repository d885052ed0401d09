// The registry of bake methods: a new method adds its entry here (one line) and its own files.
#include <algorithm>

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

bool MethodEntry::reads(std::string_view key) const {
  for (const std::string& k : settings)
    if (k == key) return true;
  for (const SettingSpec& spec : own_settings)
    if (spec.key == key) return true;
  return false;
}

SettingSpec flag_setting(std::string key, bool fallback) {
  SettingSpec spec;
  spec.key = std::move(key);
  spec.fallback = fallback;
  return spec;
}

SettingSpec whole_setting(std::string key, std::int64_t fallback, std::int64_t lo, std::int64_t hi,
                          std::string requirement, std::function<bool(std::int64_t)> valid) {
  SettingSpec spec;
  spec.key = std::move(key);
  spec.fallback = fallback;
  spec.lo = lo, spec.hi = hi;
  spec.requirement = std::move(requirement);
  if (valid)
    spec.valid = [valid = std::move(valid)](const SettingValue& v) {
      return valid(std::get<std::int64_t>(v));
    };
  return spec;
}

SettingSpec number_setting(std::string key, double fallback, std::string requirement,
                           std::function<bool(double)> valid) {
  SettingSpec spec;
  spec.key = std::move(key);
  spec.fallback = fallback;
  spec.requirement = std::move(requirement);
  spec.valid = [valid = std::move(valid)](const SettingValue& v) {
    return valid(std::get<double>(v));
  };
  return spec;
}

SettingSpec word_setting(std::string key, std::string fallback, std::vector<std::string> words) {
  SettingSpec spec;
  spec.key = std::move(key);
  spec.fallback = std::move(fallback);
  for (std::size_t i = 0; i < words.size(); ++i)
    spec.requirement += (i == 0                  ? ""
                         : i + 1 == words.size() ? " or "
                                                 : ", ") +
                        ("\"" + words[i] + "\"");
  spec.valid = [words = std::move(words)](const SettingValue& v) {
    return std::find(words.begin(), words.end(), std::get<std::string>(v)) != words.end();
  };
  return spec;
}

// The rest are declared in scene/scene.h, for the scene reader.
std::string default_method() { return method_registry().front().name; }

std::string method_baking_only(Quantity q) {
  for (const MethodEntry& entry : method_registry())
    if (entry.only_quantity == q) return entry.name;
  return {};
}

const std::vector<SettingSpec>& method_setting_specs() {
  static const std::vector<SettingSpec> specs = [] {
    std::vector<SettingSpec> out;
    for (const MethodEntry& entry : method_registry())
      for (const SettingSpec& spec : entry.own_settings)
        if (std::none_of(out.begin(), out.end(),
                         [&](const SettingSpec& s) { return s.key == spec.key; }))
          out.push_back(spec);
    return out;
  }();
  return specs;
}

const SettingSpec* find_method_setting(std::string_view key) {
  for (const SettingSpec& spec : method_setting_specs())
    if (spec.key == key) return &spec;
  return nullptr;
}

}  // namespace sb
