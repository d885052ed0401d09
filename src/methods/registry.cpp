// The registry of bake methods: a new method adds its entry here (one line) and its own files.
#include <algorithm>
#include <stdexcept>

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

const MethodVocabulary& method_vocabulary() {
  static const MethodVocabulary vocabulary{
      known_methods(), method_baking_only(Quantity::ambient_occlusion), method_setting_specs()};
  return vocabulary;
}

Expected<Scene> load_scene(const std::filesystem::path& file, bool need_lights) {
  return load_scene(file, method_vocabulary(), need_lights);
}

namespace {

const SettingSpec& spec_of(std::string_view key) {
  const SettingSpec* spec = find_method_setting(key);
  if (!spec) throw std::logic_error("no method reads the [bake] key " + std::string(key));
  return *spec;
}

const SettingValue& value_of(const BakeSettings& bake, std::string_view key) {
  const auto given = bake.own.find(key);
  return given != bake.own.end() ? given->second : spec_of(key).fallback;
}

}  // namespace

bool setting_flag(const BakeSettings& bake, std::string_view key) {
  return std::get<bool>(value_of(bake, key));
}

std::int64_t setting_whole(const BakeSettings& bake, std::string_view key) {
  return std::get<std::int64_t>(value_of(bake, key));
}

double setting_number(const BakeSettings& bake, std::string_view key) {
  const SettingValue& v = value_of(bake, key);
  if (const auto* w = std::get_if<std::int64_t>(&v)) return double(*w);
  return std::get<double>(v);
}

std::string setting_word(const BakeSettings& bake, std::string_view key) {
  return std::get<std::string>(value_of(bake, key));
}

void set_setting(BakeSettings& bake, std::string_view key, SettingValue value) {
  set_own_setting(bake, spec_of(key), std::move(value));
}

}  // namespace sb
