// Settings to and from JSON (settings_json.h). Doubles round-trip exactly: nlohmann-json writes
// the shortest representation that reads back to the same bits.
#include "formats/settings_json.h"

#include "methods/method.h"

#include <initializer_list>
#include <optional>

namespace sb {

namespace {

using json = nlohmann::ordered_json;

// Reads keys of one object, keeping the first problem.
class Reader {
 public:
  Reader(const json& object, const std::string& where, Status& status)
      : object_(object), where_(where), status_(status) {}

  const json* find(const char* key) {
    if (!status_) return nullptr;
    if (!object_.is_object() || !object_.contains(key)) {
      status_ = input_error(where_ + ": no settings." + key);
      return nullptr;
    }
    return &object_[key];
  }
  template <typename T>
  void read(const char* key, T& out) {
    const json* v = find(key);
    if (!v) return;
    try {
      out = v->get<T>();
    } catch (const json::exception&) {
      status_ = input_error(where_ + ": settings." + key + " has the wrong type");
    }
  }
  template <typename Enum>
  void read_enum(const char* key, Enum& out, std::initializer_list<Enum> values) {
    std::string text;
    read(key, text);
    if (!status_) return;
    for (Enum e : values)
      if (text == to_string(e)) {
        out = e;
        return;
      }
    status_ = input_error(where_ + ": settings." + key + " is not a known value: " + text);
  }

 private:
  const json& object_;
  const std::string& where_;
  Status& status_;
};

}  // namespace

json settings_to_json(const BakeSettings& b, const OutputSettings& o) {
  json bake = {{"resolution", b.resolution},
               {"texels_per_metre", b.texels_per_metre},
               {"method", b.method},
               {"quantity", to_string(b.quantity)},
               {"samples", b.samples},
               {"ao_distance", b.ao_distance},
               {"irradiance_floor", b.irradiance_floor},
               {"margin", b.margin},
               {"seams", b.seams},
               {"seed", b.seed}};
  // Each method's own settings, as set or by default (SettingSpec).
  for (const SettingSpec& spec : method_setting_specs()) {
    const auto given = b.own.find(spec.key);
    const SettingValue& v = given != b.own.end() ? given->second : spec.fallback;
    std::visit([&](const auto& value) { bake[spec.key] = value; }, v);
  }
  json output = {{"encoding", to_string(o.encoding)},
                 {"per_light", o.per_light},
                 {"shadowmask", o.shadowmask},
                 {"shadowmask_encoding", to_string(o.shadowmask_encoding)},
                 {"atlas", o.atlas ? json{{"size", o.atlas->size}, {"padding", o.atlas->padding}}
                                   : json(nullptr)},
                 {"gltf", o.gltf}};
  return {{"bake", bake}, {"output", output}};
}

Status settings_from_json(const json& j, const std::string& where, BakeSettings& b,
                          OutputSettings& o) {
  Status status = Ok{};
  if (!j.is_object() || !j.contains("bake") || !j.contains("output"))
    return input_error(where + ": no settings.bake or settings.output");
  Reader r(j["bake"], where, status);
  r.read("resolution", b.resolution);
  r.read("texels_per_metre", b.texels_per_metre);
  r.read("method", b.method);
  r.read_enum("quantity", b.quantity,
              {Quantity::visibility, Quantity::irradiance, Quantity::ambient_occlusion});
  r.read("ao_distance", b.ao_distance);
  r.read("irradiance_floor", b.irradiance_floor);
  r.read("samples", b.samples);
  r.read("margin", b.margin);
  r.read("seams", b.seams);
  r.read("seed", b.seed);
  for (const SettingSpec& spec : method_setting_specs()) {
    SettingValue v = spec.fallback;
    std::visit([&](auto& value) { r.read(spec.key.c_str(), value); }, v);
    if (status) set_setting(b, spec.key, std::move(v));
  }
  Reader out(j["output"], where, status);
  const std::initializer_list<Encoding> encodings = {Encoding::linear_exr, Encoding::half_exr,
                                                     Encoding::png, Encoding::rgbm_png};
  out.read_enum("encoding", o.encoding, encodings);
  out.read("per_light", o.per_light);
  out.read("shadowmask", o.shadowmask);
  out.read_enum("shadowmask_encoding", o.shadowmask_encoding, encodings);
  if (const json* atlas = out.find("atlas"); atlas && !atlas->is_null()) {
    Reader a(*atlas, where, status);
    AtlasSettings settings;
    a.read("size", settings.size);
    a.read("padding", settings.padding);
    o.atlas = settings;
  } else {
    o.atlas.reset();
  }
  out.read("gltf", o.gltf);
  return status;
}

}  // namespace sb
