// The [bake] table of a scene file (docs/scene-format.md): resolution, method, sampling, memory
// and each method's settings, every value checked.
#include "scene/scene_file_tables.h"
#include "scene/toml_table_reader.h"

#include "core/memory_size.h"

namespace sb {

void set_own_setting(BakeSettings& bake, const SettingSpec& spec, SettingValue value) {
  if (std::holds_alternative<double>(spec.fallback))
    if (const auto* w = std::get_if<std::int64_t>(&value)) value = double(*w);
  bake.own.insert_or_assign(spec.key, std::move(value));
}

Expected<BakeSettings> read_bake(const std::filesystem::path& file, const toml::table& table,
                                 const MethodVocabulary& methods) {
  TableReader r(file, table, "[bake]");
  // Every bake's keys, then each method's own (SettingSpec, from the methods' vocabulary).
  std::vector<std::string_view> known = {
      "resolution", "texels_per_metre", "method",          "quantity",
      "samples",    "ao_distance",      "margin",          "seams",
      "seed",       "max_memory",       "irradiance_floor"};
  for (const SettingSpec& spec : methods.settings) known.push_back(spec.key);
  r.check_known_keys(known);
  BakeSettings bake;
  const int int_max = std::numeric_limits<int>::max();
  if (auto v = r.integer("resolution", 1, 16384)) bake.resolution = static_cast<int>(*v);
  if (auto v = r.number("texels_per_metre", "a number > 0 (texels per metre of surface)",
                        [](double x) { return std::isfinite(x) && x > 0 && x <= 1e6; })) {
    if (r.find("resolution")) {
      r.fail("texels_per_metre",
             "give 'resolution' (texels per side of every lightmap) or 'texels_per_metre' (each "
             "lightmap sized by its surface area), not both");
    }
    bake.texels_per_metre = *v;
  }
  if (auto v = r.string("method")) {
    const auto& known = methods.names;
    if (std::find(known.begin(), known.end(), *v) == known.end()) {
      r.fail("method", fmt::format("unknown method {} (known: {})", single_quoted(*v),
                                   fmt::join(known, ", ")));
    }
    bake.method = *v;
  }
  if (auto v = r.string("quantity")) {
    if (*v == "visibility") {
      bake.quantity = Quantity::visibility;
    } else if (*v == "irradiance") {
      bake.quantity = Quantity::irradiance;
    } else if (*v == "ambient-occlusion") {
      bake.quantity = Quantity::ambient_occlusion;
    } else {
      r.fail_got("quantity", "\"visibility\", \"irradiance\" or \"ambient-occlusion\"");
    }
  }
  if (auto v = r.number("ao_distance", "a number > 0 (metres)",
                        [](double x) { return std::isfinite(x) && x > 0 && x <= 1e6; })) {
    bake.ao_distance = *v;
  }
  if (auto v = r.number("irradiance_floor", "a number >= 0 (W/m²; 0: lights reach everywhere)",
                        [](double x) { return std::isfinite(x) && x >= 0 && x <= 1e9; }))
    bake.irradiance_floor = *v;
  if (auto v = r.integer("samples", 1, int_max)) bake.samples = static_cast<int>(*v);
  if (auto v = r.integer("margin", 0, int_max)) bake.margin = static_cast<int>(*v);
  if (auto v = r.boolean("seams")) bake.seams = *v;
  if (auto v = r.integer("seed", 0, std::numeric_limits<std::int64_t>::max())) {
    bake.seed = static_cast<std::uint64_t>(*v);
  }
  if (const toml::node* node = r.find("max_memory"); node && !r.failed()) {
    // A size with its unit ("8 GiB", "512 MiB") or a whole number of bytes.
    const std::string_view requirement = "a size such as \"8 GiB\" or \"512 MiB\", or bytes";
    std::uint64_t bytes = 0;
    if (const auto* text = node->as_string(); text && parse_memory_size(text->get(), bytes)) {
      bake.max_memory = bytes;
    } else if (const auto* whole = node->as_integer(); whole && whole->get() > 0) {
      bake.max_memory = std::uint64_t(whole->get());
    } else {
      r.fail_got("max_memory", requirement);
    }
  }
  // Each method's own keys, by their type, range and check.
  for (const SettingSpec& spec : methods.settings) {
    if (!r.find(spec.key)) continue;
    const auto valid = [&](const SettingValue& v) { return !spec.valid || spec.valid(v); };
    if (std::holds_alternative<bool>(spec.fallback)) {
      if (auto v = r.boolean(spec.key)) set_own_setting(bake, spec, *v);
    } else if (std::holds_alternative<std::int64_t>(spec.fallback)) {
      if (auto v = r.integer(spec.key, spec.lo, spec.hi)) {
        if (valid(*v))
          set_own_setting(bake, spec, *v);
        else
          r.fail_got(spec.key, spec.requirement);
      }
    } else if (std::holds_alternative<double>(spec.fallback)) {
      if (auto v = r.number(spec.key, spec.requirement,
                            [&](double x) { return std::isfinite(x) && valid(x); }))
        set_own_setting(bake, spec, *v);
    } else if (auto v = r.string(spec.key)) {
      if (valid(*v))
        set_own_setting(bake, spec, *v);
      else
        r.fail_got(spec.key, spec.requirement);
    }
  }
  if (r.failed()) return r.error();
  // Where a mismatch of quantity and method is reported: the quantity's line, else the method's.
  if (const toml::node* given = r.find("quantity") ? r.find("quantity") : r.find("method")) {
    const std::string where =
        fmt::format("{}:{}: [bake]", file.string(), given->source().begin.line);
    if (Status paired =
            pair_quantity_and_method(bake, methods.ambient_occlusion, r.find("quantity") != nullptr,
                                     r.find("method") != nullptr, where);
        !paired)
      return paired.error();
  }
  return bake;
}

}  // namespace sb
