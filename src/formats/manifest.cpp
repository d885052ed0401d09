// manifest.json to and from its schema (manifest.h). Reading checks every key's presence and
// type, so that a reader meets either a whole manifest or a one-line error naming the key.
#include "formats/manifest.h"

#include "formats/json_fields.h"
#include "formats/receiver_record.h"
#include "lightmaps/shadowmask.h"

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
      "name",      "files",    "atlas",   "uv_channel",     "resolution",
      "method",    "quantity", "samples", "covered_texels", "most_lights_per_texel",
      "uv_layout", "seams",    "seconds", "method_stats",   "bake"};
  return keys;
}

json file_to_json(const ManifestFile& f) {
  return {{"file", f.file},
          {"encoding", to_string(f.encoding)},
          {"transfer", f.transfer},
          {"scale", f.scale}};
}

json files_to_json(const ManifestFiles& files) {
  json out = {{"lightmap", file_to_json(files.lightmap)}};
  if (files.preview) out["preview"] = file_to_json(*files.preview);
  out["coverage"] = file_to_json(files.coverage);
  if (!files.per_light.empty()) {
    json& lights = out["per_light"] = json::object();
    for (const auto& [light, file] : files.per_light) lights[light] = file_to_json(file);
  }
  if (files.shadowmask) out["shadowmask"] = file_to_json(*files.shadowmask);
  return out;
}

void read_file_entry(const json& entry, const std::string& where, const std::string& path,
                     ManifestFile& f, Status& status) {
  FieldReader fields(entry, where, path, status);
  fields.read("file", f.file);
  fields.read("encoding", f.encoding);
  fields.read("transfer", f.transfer);
  fields.read("scale", f.scale);
}

void read_files(FieldReader& parent, const char* key, const std::string& where,
                ManifestFiles& files, Status& status) {
  const json* entry = parent.object(key);
  if (!entry) return;
  const std::string path = parent.path_of(std::string(key) + ".");
  FieldReader fields(*entry, where, path, status);
  if (const json* f = fields.object("lightmap"))
    read_file_entry(*f, where, path + "lightmap.", files.lightmap, status);
  if (status && entry->contains("preview")) {
    if (const json* f = fields.object("preview"))
      read_file_entry(*f, where, path + "preview.", files.preview.emplace(), status);
  }
  if (const json* f = fields.object("coverage"))
    read_file_entry(*f, where, path + "coverage.", files.coverage, status);
  if (status && entry->contains("per_light")) {
    if (const json* lights = fields.object("per_light")) {
      for (const auto& [light, value] : lights->items()) {
        if (!status) break;
        auto& [name, file] = files.per_light.emplace_back(light, ManifestFile{});
        FieldReader light_fields(*lights, where, path + "per_light.", status);
        if (const json* f = light_fields.object(name.c_str()))
          read_file_entry(*f, where, path + "per_light." + name + ".", file, status);
      }
    }
  }
  if (status && entry->contains("shadowmask")) {
    if (const json* f = fields.object("shadowmask"))
      read_file_entry(*f, where, path + "shadowmask.", files.shadowmask.emplace(), status);
  }
}

// The [output] settings as the manifest records them.
json output_to_json(const OutputSettings& o) {
  json out = {{"encoding", to_string(o.encoding)},
              {"per_light", o.per_light},
              {"shadowmask", o.shadowmask},
              {"shadowmask_encoding", to_string(o.shadowmask_encoding)}};
  if (o.atlas) out["atlas"] = {{"size", o.atlas->size}, {"padding", o.atlas->padding}};
  out["gltf"] = o.gltf;
  return out;
}

void read_output(FieldReader& parent, const std::string& where, OutputSettings& o, Status& status) {
  const json* entry = parent.object("output");
  if (!entry) return;
  FieldReader fields(*entry, where, "output.", status);
  fields.read("encoding", o.encoding);
  fields.read("per_light", o.per_light);
  fields.read("shadowmask", o.shadowmask);
  fields.read("shadowmask_encoding", o.shadowmask_encoding);
  if (status && entry->contains("atlas")) {
    if (const json* atlas = fields.object("atlas")) {
      FieldReader atlas_fields(*atlas, where, "output.atlas.", status);
      AtlasSettings& a = o.atlas.emplace();
      atlas_fields.read("size", a.size);
      atlas_fields.read("padding", a.padding);
    }
  }
  fields.read("gltf", o.gltf);
}

json receiver_to_json(const ManifestReceiver& r) {
  json out = {{"name", r.name}};
  if (r.files) out["files"] = files_to_json(*r.files);
  if (r.atlas) {
    const ManifestAtlasPlacement& a = *r.atlas;
    out["atlas"] = {
        {"index", a.index}, {"rect", {a.x, a.y, a.side, a.side}}, {"scale_offset", a.scale_offset}};
  }
  out.update(json{
      {"uv_channel", r.uv_channel},
      {"resolution", {r.width, r.height}},
      {"method", r.method},
      {"quantity", to_string(r.quantity)},
      {"samples", r.samples},
  });
  write_record(r, out);
  out["seconds"] = r.seconds;
  if (r.bake) out["bake"] = {{"reused", r.bake->reused}, {"why", r.bake->why}};
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
  if (status && !entry.contains("atlas"))
    read_files(fields, "files", where, r.files.emplace(), status);
  if (status && entry.contains("atlas")) {
    if (const json* atlas = fields.object("atlas")) {
      ManifestAtlasPlacement& a = r.atlas.emplace();
      FieldReader atlas_fields(*atlas, where, fields.path_of("atlas."), status);
      atlas_fields.read("index", a.index);
      const json* rect = atlas_fields.array("rect");
      const json* scale_offset = atlas_fields.array("scale_offset");
      const auto all = [](const json& array, std::size_t size,
                          bool (json::*is_kind)() const noexcept) {
        if (array.size() != size) return false;
        for (const auto& v : array)
          if (!(v.*is_kind)()) return false;
        return true;
      };
      if (rect && scale_offset) {
        if (!all(*rect, 4, &json::is_number_integer) || !all(*scale_offset, 4, &json::is_number)) {
          status = input_error(where + ": " + fields.path_of("atlas") +
                               " in the bake's manifest needs rect [x, y, w, h] and "
                               "scale_offset [sx, sy, ox, oy]");
          return;
        }
        a.x = (*rect)[0].get<int>();
        a.y = (*rect)[1].get<int>();
        a.side = (*rect)[2].get<int>();
        for (int i = 0; i < 4; ++i)
          a.scale_offset[std::size_t(i)] = (*scale_offset)[i].get<double>();
      }
    }
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
  read_record(fields, entry, r);
  if (const json* reuse = entry.contains("bake") ? fields.object("bake") : nullptr) {
    FieldReader reuse_fields(*reuse, where, fields.path_of("bake."), status);
    // Assigned, not emplace()d: clang 14 (the fuzzing build's) does not count a nested struct
    // with member initialisers as default-constructible inside its enclosing class.
    r.bake = ManifestReceiver::Reuse{false, {}};
    ManifestReceiver::Reuse& b = *r.bake;
    reuse_fields.read("reused", b.reused);
    reuse_fields.read("why", b.why);
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

// Calls read(element, "name[i].") for each element of `array`, in order; an element that is not
// an object is an error naming it, and ends the reading (as any error does).
template <typename Read>
void read_objects(const json& array, const std::string& name, const std::string& where,
                  Status& status, Read read) {
  for (std::size_t i = 0; status && i < array.size(); ++i) {
    const std::string path = name + "[" + std::to_string(i) + "]";
    if (!array[i].is_object()) {
      status = input_error(where + ": " + path + " in the bake's manifest is not an object");
      return;
    }
    read(array[i], path + ".");
  }
}

}  // namespace

json manifest_to_json(const Manifest& m) {
  json out;
  out["shadowbake"] = m.shadowbake;
  out["scene"] = m.scene;
  out["method"] = m.method;
  out["quantity"] = to_string(m.quantity);
  out["resolution"] = m.resolution;
  if (m.texels_per_metre) out["texels_per_metre"] = *m.texels_per_metre;
  out["samples"] = m.samples;
  out["seed"] = m.seed;
  out["margin"] = m.margin;
  for (const auto& [key, value] : m.method_settings)
    std::visit([&, &key = key](const auto& v) { out[key] = v; }, value);
  out["output"] = output_to_json(m.output);
  out["lights"] = json::array();
  for (const auto& l : m.lights) {
    json light = {{"name", l.name}, {"shape", to_string(l.shape)}};
    if (l.range) light["range"] = *l.range;
    if (l.shadowmask_channel) {
      light["shadowmask_channel"] = *l.shadowmask_channel >= 0
                                        ? json(shadowmask_channel_name(*l.shadowmask_channel))
                                        : json(nullptr);
    }
    out["lights"].push_back(std::move(light));
  }
  if (m.png_white_point) out["png_white_point"] = *m.png_white_point;
  if (!m.atlases.empty()) {
    json& atlases = out["atlases"] = json::array();
    for (const ManifestAtlas& a : m.atlases)
      atlases.push_back({{"index", a.index}, {"size", a.size}, {"files", files_to_json(a.files)}});
  }
  if (m.gltf) out["gltf"] = *m.gltf;
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
  fields.read_optional("texels_per_metre", m.texels_per_metre);
  fields.read("samples", m.samples);
  fields.read("seed", m.seed);
  fields.read("margin", m.margin);
  // The method's settings it records: any method's own keys present (MethodEntry).
  for (const SettingSpec& spec : method_setting_specs()) {
    if (!json_manifest.is_object() || !json_manifest.contains(spec.key)) continue;
    SettingValue value = spec.fallback;
    std::visit([&](auto& v) { fields.read(spec.key.c_str(), v); }, value);
    m.method_settings.emplace_back(spec.key, std::move(value));
  }
  read_output(fields, where, m.output, status);
  if (const json* lights = fields.array("lights")) {
    read_objects(*lights, "lights", where, status, [&](const json& entry, const std::string& path) {
      ManifestLight& light = m.lights.emplace_back();
      FieldReader light_fields(entry, where, path, status);
      light_fields.read("name", light.name);
      light_fields.read("shape", light.shape);
      light_fields.read_optional("range", light.range);
      if (!status || !entry.contains("shadowmask_channel")) return;
      const json& channel = entry["shadowmask_channel"];
      int c = -1;
      for (int k = 0; k < kShadowmaskChannels && !channel.is_null(); ++k)
        if (channel == shadowmask_channel_name(k)) c = k;
      if (!channel.is_null() && c < 0) {
        status = input_error(where + ": " + path +
                             "shadowmask_channel in the bake's manifest is not \"R\", \"G\", "
                             "\"B\", \"A\" or null");
        return;
      }
      light.shadowmask_channel = c;
    });
  }
  fields.read_optional("png_white_point", m.png_white_point);
  if (status && json_manifest.contains("atlases")) {
    if (const json* atlases = fields.array("atlases")) {
      read_objects(*atlases, "atlases", where, status,
                   [&](const json& entry, const std::string& path) {
                     ManifestAtlas& atlas = m.atlases.emplace_back();
                     FieldReader atlas_fields(entry, where, path, status);
                     atlas_fields.read("index", atlas.index);
                     atlas_fields.read("size", atlas.size);
                     read_files(atlas_fields, "files", where, atlas.files, status);
                   });
    }
  }
  fields.read_optional("gltf", m.gltf);
  const json& receivers = json_manifest["receivers"];
  read_objects(receivers, "receivers", where, status,
               [&](const json& entry, const std::string& path) {
                 read_receiver(entry, where, path, m.receivers.emplace_back(), status);
               });
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
