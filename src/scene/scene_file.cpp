// The scene file reader: parses the TOML scene format (https://toml.io/en/v1.0.0, via toml++)
// into a Scene and validates every key against docs/scene-format.md. Like pbrt-v4's scene
// parser, every problem names the file, the line, the item and the key, and keys the reader does
// not use are reported rather than ignored (docs/scene-format.md, "Errors").
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "scene/level_file.h"
#include "scene/scene.h"
#include "scene/scene_file_tables.h"
#include "scene/toml_table_reader.h"

namespace sb {

const char* to_string(Quantity q) {
  switch (q) {
    case Quantity::visibility:
      return "visibility";
    case Quantity::irradiance:
      return "irradiance";
    case Quantity::ambient_occlusion:
      return "ambient-occlusion";
  }
  return "?";
}

const char* to_string(LightShape s) {
  switch (s) {
    case LightShape::rectangle:
      return "rectangle";
    case LightShape::disk:
      return "disk";
    case LightShape::sphere:
      return "sphere";
    case LightShape::polygon:
      return "polygon";
    case LightShape::mesh:
      return "mesh";
    case LightShape::sky:
      return "sky";
  }
  return "?";
}

Status pair_quantity_and_method(BakeSettings& bake, const std::string& ao, bool quantity_given,
                                bool method_given, const std::string& where) {
  const bool ao_quantity = bake.quantity == Quantity::ambient_occlusion;
  const bool ao_method = bake.method == ao;
  if (ao_quantity == ao_method) return Ok{};
  if (ao_quantity && !method_given) {
    bake.method = ao;
    return Ok{};
  }
  if (ao_method && !quantity_given) {
    bake.quantity = Quantity::ambient_occlusion;
    return Ok{};
  }
  return scene_error(fmt::format(
      "{}: quantity '{}' and method '{}' do not go together: ambient occlusion is baked by "
      "method '{}', which bakes nothing else",
      where, to_string(bake.quantity), bake.method, ao));
}

Affine3 object_transform(const Vec3& translate, const Vec3& rotate_deg, const Vec3& scale) {
  constexpr double radians_per_degree = std::numbers::pi / 180.0;
  const Vec3 r = rotate_deg * radians_per_degree;
  // Blender's "XYZ Euler": X is applied first, so it is the rightmost factor.
  const Mat3 rotation =
      (Eigen::AngleAxisd(r.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(r.y(), Vec3::UnitY()) *
       Eigen::AngleAxisd(r.x(), Vec3::UnitX()))
          .toRotationMatrix();
  Affine3 transform = Affine3::Identity();
  transform.linear() = rotation * scale.asDiagonal();
  transform.translation() = translate;
  return transform;
}

namespace {

// The tables of an array of tables, or an error for anything else written under its key.
Expected<std::vector<const toml::table*>> tables_of(const std::filesystem::path& file,
                                                    const toml::key& key, const toml::node& node) {
  std::vector<const toml::table*> tables;
  if (const auto* array = node.as_array()) {
    for (const toml::node& element : *array) {
      if (!element.is_table()) break;
      tables.push_back(element.as_table());
    }
    if (tables.size() == array->size()) return tables;
  }
  return located_error(file, key.source().begin.line, "top level",
                       fmt::format("'{0}' must be an array of tables, written [[{0}]]", key.str()));
}

// A scene file is a few kilobytes of TOML; one past this is not a scene file.
constexpr std::uintmax_t kMaxSceneFileBytes = 16 << 20;

Expected<std::string> read_text(const std::filesystem::path& file) {
  const auto fail = [&](const std::string& reason) {
    return scene_error(fmt::format("{}: cannot open scene file: {}", file.string(), reason));
  };
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (ec) return fail(ec.message());
  if (std::filesystem::is_directory(status)) return fail("it is a directory");
  // A FIFO would block the read for ever and a device (/dev/zero) never end it.
  if (!std::filesystem::is_regular_file(status))
    return fail("not a regular file (a device, a FIFO or a socket)");
  if (std::filesystem::file_size(file, ec) > kMaxSceneFileBytes)
    return fail(
        fmt::format("larger than {} MiB, too large for a scene file", kMaxSceneFileBytes >> 20));
  std::ifstream in(file, std::ios::binary);
  if (!in) return fail(std::generic_category().message(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return fail(std::generic_category().message(errno));
  return text.str();
}

// Replaces line breaks so that a parser's description keeps the error on one line.
std::string one_line(std::string_view text) {
  std::string out(text);
  for (char& c : out) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return out;
}

// Reads each [[kind]] table with `read` and refuses a name used twice.
template <class Desc, class Tables, class Reader>
Expected<std::vector<Desc>> read_unique(const std::filesystem::path& file, const Tables& tables,
                                        const char* kind, Reader read) {
  std::vector<Desc> out;
  std::map<std::string, int> lines;
  for (std::size_t i = 0; i < tables.size(); ++i) {
    Expected<Desc> desc = read(file, *tables[i], i);
    if (!desc) return desc.error();
    const auto [first, inserted] = lines.emplace(desc->name, desc->line);
    if (!inserted) {
      return located_error(file, desc->line, item_name(kind, desc->name),
                           fmt::format("{} names must be unique: {} is also defined at line {}",
                                       kind, single_quoted(desc->name), first->second));
    }
    out.push_back(std::move(*desc));
  }
  return out;
}

// Appends an import's objects or lights to the scene's, refusing a name the scene already has.
template <class Desc>
Status add_unique(const std::filesystem::path& file, const char* kind, std::vector<Desc>& added,
                  std::vector<Desc>& into) {
  for (Desc& desc : added) {
    for (const Desc& other : into) {
      if (other.name == desc.name) {
        return located_error(
            file, desc.line, item_name(kind, desc.name),
            fmt::format("{} names must be unique: the import's {} is also defined at line {}; "
                        "rename one (an imported name is its node's)",
                        kind, single_quoted(desc.name), other.line));
      }
    }
    into.push_back(std::move(desc));
  }
  return Ok{};
}

}  // namespace

Expected<Scene> load_scene(const std::filesystem::path& file, const MethodVocabulary& methods,
                           bool need_lights) {
  if (is_level_file(file)) return load_level_scene(file, need_lights);
  Expected<std::string> text = read_text(file);
  if (!text) return text.error();

  toml::table root;
  try {
    root = toml::parse(*text, file.string());
  } catch (const toml::parse_error& e) {
    const auto& at = e.source().begin;
    return scene_error(fmt::format("{}:{}:{}: TOML syntax error: {}", file.string(), at.line,
                                   at.column, one_line(e.description())));
  }

  Scene scene;
  scene.file = file;
  const std::vector<std::string_view> top_level_keys = {"bake", "output", "object", "light",
                                                        "import"};
  if (const toml::key* key = first_unknown_key(root, top_level_keys)) {
    return located_error(file, key->source().begin.line, "top level",
                         fmt::format("unknown key {} (known: {})", single_quoted(key->str()),
                                     fmt::join(top_level_keys, ", ")));
  }
  std::vector<const toml::table*> object_tables;
  std::vector<const toml::table*> light_tables;
  std::vector<const toml::table*> import_tables;
  for (const auto& [key, node] : root) {
    if (key == "bake") {
      const toml::table* bake = node.as_table();
      if (!bake) {
        return located_error(file, key.source().begin.line, "top level",
                             "'bake' must be a table, written [bake]");
      }
      Expected<BakeSettings> settings = read_bake(file, *bake, methods);
      if (!settings) return settings.error();
      scene.bake = *settings;
      for (const auto& [name, value] : *bake)
        scene.bake_keys.push_back({std::string(name.str()), int(name.source().begin.line)});
      // toml++ keeps a table's keys sorted by name; the scene's readers want them as written.
      std::stable_sort(
          scene.bake_keys.begin(), scene.bake_keys.end(),
          [](const SettingGiven& a, const SettingGiven& b) { return a.line < b.line; });
    } else if (key == "output") {
      const toml::table* output = node.as_table();
      if (!output) {
        return located_error(file, key.source().begin.line, "top level",
                             "'output' must be a table, written [output]");
      }
      Expected<OutputSettings> settings = read_output(file, *output);
      if (!settings) return settings.error();
      scene.output = *settings;
    } else {
      auto tables = tables_of(file, key, node);
      if (!tables) return tables.error();
      (key == "object" ? object_tables : key == "light" ? light_tables : import_tables) = *tables;
    }
  }

  auto objects = read_unique<ObjectDesc>(file, object_tables, "object", read_object);
  if (!objects) return objects.error();
  scene.objects = std::move(*objects);
  auto lights = read_unique<LightDesc>(file, light_tables, "light", read_light);
  if (!lights) return lights.error();
  scene.lights = std::move(*lights);
  for (std::size_t i = 0; i < import_tables.size(); ++i) {
    auto level = read_import(file, *import_tables[i], i);
    if (!level) return level.error();
    if (Status s = add_unique(file, "object", level->objects, scene.objects); !s) return s.error();
    if (Status s = add_unique(file, "light", level->lights, scene.lights); !s) return s.error();
    scene.warnings.insert(scene.warnings.end(), level->warnings.begin(), level->warnings.end());
  }

  if (Status s = resolve_sky_suns(file, scene.lights); !s) return s.error();
  if (scene.objects.empty()) {
    return located_error(file, 0, "scene", "no [[object]] table; a scene needs at least one");
  }
  if (scene.lights.empty() && need_lights && scene.bake.quantity != Quantity::ambient_occlusion) {
    return located_error(
        file, 0, "scene",
        "no light: no [[light]] table, and no light imported; a scene needs at least one");
  }
  const bool any_receiver = std::any_of(scene.objects.begin(), scene.objects.end(),
                                        [](const ObjectDesc& o) { return o.receiver; });
  if (!any_receiver) {
    return located_error(file, 0, "scene",
                         "no object has 'receiver' = true, so there is nothing to bake");
  }
  return scene;
}

}  // namespace sb
