// Reading a JSON document written by shadowbake (the manifest, a shard's data, the cache) key by
// key: each key's presence and type are checked, so that a reader meets either whole values or
// a one-line error naming the file and the key.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <initializer_list>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "core/error.h"
#include "scene/scene.h"

namespace sb {

template <typename Enum>
bool parse_enum(const std::string& text, std::initializer_list<Enum> values, Enum& out) {
  for (const Enum value : values) {
    if (text != to_string(value)) continue;
    out = value;
    return true;
  }
  return false;
}

// Reads the keys of one JSON object, keeping the first problem as an error that names the file,
// the key's path (e.g. receivers[0].files.exr) and the document (`document`: "the bake's
// manifest", "the shard's data").
class FieldReader {
  using json = nlohmann::ordered_json;

 public:
  FieldReader(const json& object, const std::string& where, std::string path, Status& status,
              const char* document = "the bake's manifest")
      : object_(object),
        where_(where),
        path_(std::move(path)),
        status_(status),
        document_(document) {}

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
    if (status_ &&
        !parse_enum(text, {Quantity::visibility, Quantity::irradiance, Quantity::ambient_occlusion},
                    out))
      fail(key, "\"visibility\", \"irradiance\" or \"ambient-occlusion\"");
  }
  void read(const char* key, Encoding& out) {
    std::string text;
    read(key, text);
    if (status_ &&
        !parse_enum(text,
                    {Encoding::linear_exr, Encoding::half_exr, Encoding::png, Encoding::rgbm_png},
                    out))
      fail(key, "\"linear-exr\", \"half-exr\", \"png\" or \"rgbm-png\"");
  }
  void read(const char* key, LightShape& out) {
    std::string text;
    read(key, text);
    if (status_ && !parse_enum(text,
                               {LightShape::rectangle, LightShape::disk, LightShape::sphere,
                                LightShape::polygon, LightShape::mesh, LightShape::sky},
                               out))
      fail(key, "\"rectangle\", \"disk\", \"sphere\", \"polygon\", \"mesh\" or \"sky\"");
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
  // A FieldReader of the nested `object` found at `key` (object(key)), in the same document.
  FieldReader nested(const json& object, const std::string& key) const {
    return FieldReader(object, where_, path_of(key + "."), status_, document_);
  }

 private:
  const json* find(const char* key, bool (json::*is_kind)() const noexcept, const char* kind) {
    if (!status_) return nullptr;
    const auto it = object_.find(key);
    if (it == object_.end()) {
      status_ = input_error(where_ + ": no " + path_ + key + " in " + document_);
      return nullptr;
    }
    if (!((*it).*is_kind)()) {
      fail(key, kind);
      return nullptr;
    }
    return &*it;
  }
  void fail(const char* key, const std::string& kind) {
    status_ = input_error(where_ + ": " + path_ + key + " in " + document_ + " is not " + kind);
  }

  const json& object_;
  const std::string& where_;
  std::string path_;
  Status& status_;
  const char* document_;
};

}  // namespace sb
