// manifest.json to and from its schema (manifest.h). Reading checks every key's presence and
// type, so that a reader meets either a whole manifest or a one-line error naming the key.
#include "pipeline/manifest.h"

#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <utility>

namespace sb {

namespace {

using json = nlohmann::ordered_json;

// The receiver keys the schema names; any other key is one of the method's own entries.
const std::set<std::string, std::less<>>& receiver_schema_keys() {
  static const std::set<std::string, std::less<>> keys = {
      "name",    "files",          "uv_channel", "resolution", "method",      "quantity",
      "samples", "covered_texels", "uv_layout",  "seconds",    "method_stats"};
  return keys;
}

template <typename Enum>
bool parse_enum(const std::string& text, std::initializer_list<Enum> values, Enum& out) {
  for (const Enum value : values) {
    if (text != to_string(value)) continue;
    out = value;
    return true;
  }
  return false;
}

// Reads the keys of one JSON object of the manifest, keeping the first problem as an error that
// names the file and the key's path (e.g. receivers[0].files.exr).
class FieldReader {
 public:
  FieldReader(const json& object, const std::string& where, std::string path, Status& status)
      : object_(object), where_(where), path_(std::move(path)), status_(status) {}

  void read(const char* key, std::string& out) {
    if (const json* v = find(key, &json::is_string, "a string")) out = v->get<std::string>();
  }
  void read(const char* key, bool& out) {
    if (const json* v = find(key, &json::is_boolean, "true or false")) out = v->get<bool>();
  }
  void read(const char* key, double& out) {
    if (const json* v = find(key, &json::is_number, "a number")) out = v->get<double>();
  }
  void read(const char* key, int& out) {
    const json* v = find(key, &json::is_number_integer, "an integer");
    if (!v) return;
    const std::int64_t value = v->get<std::int64_t>();
    if (value < std::numeric_limits<int>::min() || value > std::numeric_limits<int>::max() ||
        (v->is_number_unsigned() && v->get<std::uint64_t>() > std::uint64_t(value))) {
      fail(key, "an integer of at most 32 bits");
      return;
    }
    out = int(value);
  }
  void read(const char* key, std::int64_t& out) {
    const json* v = find(key, &json::is_number_integer, "an integer");
    if (!v) return;
    if (v->is_number_unsigned() &&
        v->get<std::uint64_t>() > std::uint64_t(std::numeric_limits<std::int64_t>::max())) {
      fail(key, "an integer of at most 63 bits");
      return;
    }
    out = v->get<std::int64_t>();
  }
  void read(const char* key, std::uint64_t& out) {
    if (const json* v = find(key, &json::is_number_unsigned, "an integer ≥ 0"))
      out = v->get<std::uint64_t>();
  }
  void read(const char* key, Quantity& out) {
    std::string text;
    read(key, text);
    if (status_ && !parse_enum(text, {Quantity::visibility, Quantity::irradiance}, out))
      fail(key, "\"visibility\" or \"irradiance\"");
  }
  void read(const char* key, LightShape& out) {
    std::string text;
    read(key, text);
    if (status_ &&
        !parse_enum(text, {LightShape::rectangle, LightShape::disk, LightShape::sphere}, out))
      fail(key, "\"rectangle\", \"disk\" or \"sphere\"");
  }
  template <typename T>
  void read_optional(const char* key, std::optional<T>& out) {
    if (!object_.contains(key)) return;
    out.emplace();
    read(key, *out);
  }

  // The value of `key` when it is an object (an array), else null with the error kept.
  const json* object(const char* key) { return find(key, &json::is_object, "an object"); }
  const json* array(const char* key) { return find(key, &json::is_array, "an array"); }

  // The path of the entry `key` names, for a FieldReader of a nested object.
  std::string path_of(const std::string& key) const { return path_ + key; }

 private:
  const json* find(const char* key, bool (json::*is_kind)() const noexcept, const char* kind) {
    if (!status_) return nullptr;
    const auto it = object_.find(key);
    if (it == object_.end()) {
      status_ = input_error(where_ + ": no " + path_ + key + " in the bake's manifest");
      return nullptr;
    }
    if (!((*it).*is_kind)()) {
      fail(key, kind);
      return nullptr;
    }
    return &*it;
  }
  void fail(const char* key, const std::string& kind) {
    status_ = input_error(where_ + ": " + path_ + key + " in the bake's manifest is not " + kind);
  }

  const json& object_;
  const std::string& where_;
  std::string path_;
  Status& status_;
};

json receiver_to_json(const ManifestReceiver& r) {
  json out = {
      {"name", r.name},
      {"files", {{"exr", r.files.exr}, {"png", r.files.png}, {"coverage", r.files.coverage}}},
      {"uv_channel", r.uv_channel},
      {"resolution", {r.width, r.height}},
      {"method", r.method},
      {"quantity", to_string(r.quantity)},
      {"samples", r.samples},
      {"covered_texels", r.covered_texels},
      {"uv_layout",
       {{"charts", r.uv_layout.charts},
        {"uv_area", r.uv_layout.uv_area},
        {"uv_area_outside", r.uv_layout.uv_area_outside},
        {"overlapping_texels", r.uv_layout.overlapping_texels},
        {"texels_near_other_charts", r.uv_layout.texels_near_other_charts},
        {"margin", r.uv_layout.margin}}},
      {"seconds", r.seconds},
  };
  if (!r.method_stats.empty()) {
    json& stats = out["method_stats"] = json::object();
    for (const auto& [key, value] : r.method_stats) stats[key] = value;
  }
  for (const auto& [key, value] : r.method_entries.items()) out[key] = value;
  return out;
}

void read_receiver(const json& entry, const std::string& where, const std::string& path,
                   ManifestReceiver& r, Status& status) {
  FieldReader fields(entry, where, path, status);
  fields.read("name", r.name);
  if (const json* files = fields.object("files")) {
    FieldReader file_fields(*files, where, fields.path_of("files."), status);
    file_fields.read("exr", r.files.exr);
    file_fields.read("png", r.files.png);
    file_fields.read("coverage", r.files.coverage);
  }
  fields.read("uv_channel", r.uv_channel);
  if (const json* resolution = fields.array("resolution")) {
    if (resolution->size() != 2 || !(*resolution)[0].is_number_integer() ||
        !(*resolution)[1].is_number_integer()) {
      status = input_error(where + ": " + fields.path_of("resolution") +
                           " in the bake's manifest is not [width, height]");
      return;
    }
    r.width = (*resolution)[0].get<int>();
    r.height = (*resolution)[1].get<int>();
  }
  fields.read("method", r.method);
  fields.read("quantity", r.quantity);
  fields.read("samples", r.samples);
  fields.read("covered_texels", r.covered_texels);
  if (const json* layout = fields.object("uv_layout")) {
    FieldReader layout_fields(*layout, where, fields.path_of("uv_layout."), status);
    layout_fields.read("charts", r.uv_layout.charts);
    layout_fields.read("uv_area", r.uv_layout.uv_area);
    layout_fields.read("uv_area_outside", r.uv_layout.uv_area_outside);
    layout_fields.read("overlapping_texels", r.uv_layout.overlapping_texels);
    layout_fields.read("texels_near_other_charts", r.uv_layout.texels_near_other_charts);
    layout_fields.read("margin", r.uv_layout.margin);
  }
  fields.read("seconds", r.seconds);
  if (status && entry.contains("method_stats")) {
    if (const json* stats = fields.object("method_stats")) {
      FieldReader stat_fields(*stats, where, fields.path_of("method_stats."), status);
      for (const auto& [key, value] : stats->items()) {
        double figure = 0;
        stat_fields.read(key.c_str(), figure);
        r.method_stats.emplace_back(key, figure);
      }
    }
  }
  for (const auto& [key, value] : entry.items())
    if (!receiver_schema_keys().contains(key)) r.method_entries[key] = value;
}

}  // namespace

json manifest_to_json(const Manifest& m) {
  json out;
  out["shadowbake"] = m.shadowbake;
  out["scene"] = m.scene;
  out["method"] = m.method;
  out["quantity"] = to_string(m.quantity);
  out["resolution"] = m.resolution;
  out["samples"] = m.samples;
  out["seed"] = m.seed;
  out["margin"] = m.margin;
  if (m.trace) out["trace"] = *m.trace;
  if (m.convolve) out["convolve"] = *m.convolve;
  out["lights"] = json::array();
  for (const auto& l : m.lights)
    out["lights"].push_back({{"name", l.name}, {"shape", to_string(l.shape)}});
  if (m.png_white_point) out["png_white_point"] = *m.png_white_point;
  out["receivers"] = json::array();
  for (const auto& r : m.receivers) out["receivers"].push_back(receiver_to_json(r));
  out["warnings"] = m.warnings;
  out["load_seconds"] = m.load_seconds;
  out["bake_seconds"] = m.bake_seconds;
  out["shadow_rays"] = m.shadow_rays;
  return out;
}

Expected<Manifest> manifest_from_json(const json& json_manifest, const std::string& where) {
  if (!json_manifest.is_object() || !json_manifest.contains("receivers") ||
      !json_manifest["receivers"].is_array()) {
    return input_error(where + ": not a bake manifest (no receivers array)");
  }
  Manifest m;
  Status status = Ok{};
  FieldReader fields(json_manifest, where, "", status);
  fields.read("shadowbake", m.shadowbake);
  fields.read("scene", m.scene);
  fields.read("method", m.method);
  fields.read("quantity", m.quantity);
  fields.read("resolution", m.resolution);
  fields.read("samples", m.samples);
  fields.read("seed", m.seed);
  fields.read("margin", m.margin);
  fields.read_optional("trace", m.trace);
  fields.read_optional("convolve", m.convolve);
  if (const json* lights = fields.array("lights")) {
    for (std::size_t i = 0; status && i < lights->size(); ++i) {
      const std::string path = "lights[" + std::to_string(i) + "]";
      if (!(*lights)[i].is_object()) {
        status = input_error(where + ": " + path + " in the bake's manifest is not an object");
        break;
      }
      ManifestLight& light = m.lights.emplace_back();
      FieldReader light_fields((*lights)[i], where, path + ".", status);
      light_fields.read("name", light.name);
      light_fields.read("shape", light.shape);
    }
  }
  fields.read_optional("png_white_point", m.png_white_point);
  const json& receivers = json_manifest["receivers"];
  for (std::size_t i = 0; status && i < receivers.size(); ++i) {
    const std::string path = "receivers[" + std::to_string(i) + "]";
    if (!receivers[i].is_object()) {
      status = input_error(where + ": " + path + " in the bake's manifest is not an object");
      break;
    }
    read_receiver(receivers[i], where, path + ".", m.receivers.emplace_back(), status);
  }
  if (const json* warnings = fields.array("warnings")) {
    for (const auto& w : *warnings) {
      if (!w.is_string()) {
        status = input_error(where + ": warnings in the bake's manifest are not all strings");
        break;
      }
      m.warnings.push_back(w.get<std::string>());
    }
  }
  fields.read("load_seconds", m.load_seconds);
  fields.read("bake_seconds", m.bake_seconds);
  fields.read("shadow_rays", m.shadow_rays);
  if (!status) return status.error();
  return m;
}

Expected<Manifest> parse_manifest(std::string_view text, const std::string& where) {
  const json parsed = json::parse(text, nullptr, /*allow_exceptions=*/false);
  return manifest_from_json(parsed, where);
}

Expected<Manifest> read_manifest(const std::filesystem::path& folder) {
  const std::filesystem::path path = folder / kManifestFile;
  std::ifstream in(path, std::ios::binary);
  if (!in) return input_error(path.string() + ": cannot read the bake's manifest");
  std::stringstream text;
  text << in.rdbuf();
  return parse_manifest(text.str(), path.string());
}

}  // namespace sb
