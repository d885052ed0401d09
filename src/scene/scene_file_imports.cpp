// The [[import]] tables of a scene file (docs/scene-format.md, "Levels"): a level file's objects
// and lights (level_file.h) brought into the scene, placed, and changed by name or glob in
// [[import.object]] and [[import.light]] tables. A pattern that matches nothing is an error: a
// typo must not silently leave an object as it was.
#include <fnmatch.h>

#include <string>
#include <vector>

#include "scene/level_file.h"
#include "scene/mesh_reader.h"
#include "scene/scene_file_tables.h"
#include "scene/sun_light.h"
#include "scene/toml_table_reader.h"

namespace sb {

namespace {

// The tables under `key` of an [[import]] table (its [[import.object]] or [[import.light]]).
std::vector<const toml::table*> sub_tables(TableReader& r, std::string_view key) {
  std::vector<const toml::table*> tables;
  const toml::node* node = r.find(key);
  if (!node) return tables;
  const auto* array = node->as_array();
  if (array) {
    for (const toml::node& element : *array)
      if (const auto* table = element.as_table()) tables.push_back(table);
  }
  if (!array || tables.size() != array->size())
    r.fail(key, fmt::format("'{0}' must be an array of tables, written [[import.{0}]]", key));
  return tables;
}

// Every element of `items` whose name matches the table's `name` (a glob: *, ?, [...]), or an
// error naming the pattern when none does.
template <class Item>
std::vector<Item*> matching(TableReader& r, std::vector<Item>& items, const char* kind,
                            const std::filesystem::path& level) {
  std::vector<Item*> found;
  if (!r.require("name")) return found;
  const std::optional<std::string> pattern = r.string("name");
  if (!pattern) return found;
  for (Item& item : items)
    if (::fnmatch(pattern->c_str(), item.name.c_str(), 0) == 0) found.push_back(&item);
  if (found.empty()) {
    std::string names;
    for (const Item& item : items) names += (names.empty() ? "" : ", ") + item.name;
    r.fail("name", fmt::format("'{}' matches no {} of '{}' (its {}s: {})", *pattern, kind,
                               level.string(), kind, names.empty() ? "none" : names));
  }
  return found;
}

Status override_objects(const std::filesystem::path& file, const toml::table& table,
                        const std::filesystem::path& level, std::vector<ObjectDesc>& objects) {
  TableReader r(file, table, "[[import.object]]");
  r.check_known_keys({"name", "receiver", "blocker", "uv", "lightmap_scale", "allow_uncovered"});
  const std::vector<ObjectDesc*> targets = matching(r, objects, "object", level);
  const auto receiver = r.boolean("receiver");
  const auto blocker = r.boolean("blocker");
  const auto allow_uncovered = r.boolean("allow_uncovered");
  const auto uv = r.uv_set("uv", kMaxUvChannels - 1);
  const auto scale = r.number("lightmap_scale", "a number > 0", is_positive);
  if (r.failed()) return r.error();
  for (ObjectDesc* o : targets) {
    if (receiver) o->receiver = *receiver;
    if (blocker) o->blocker = *blocker;
    if (allow_uncovered) o->allow_uncovered = *allow_uncovered;
    if (uv) set_uv(*o, *uv);
    if (scale) o->lightmap_scale = *scale;
    o->line = int(r.line());
  }
  return Ok{};
}

Status override_lights(const std::filesystem::path& file, const toml::table& table,
                       const std::filesystem::path& level, std::vector<LightDesc>& lights) {
  TableReader r(file, table, "[[import.light]]");
  r.check_known_keys(
      {"name", "enabled", "radius", "angle_deg", "power", "color", "shadowmask_range", "range"});
  const std::vector<LightDesc*> targets = matching(r, lights, "light", level);
  const auto enabled = r.boolean("enabled");
  const auto radius = r.number("radius", "a number >= 0 (metres; 0: a point light, for spheres)",
                               [](double x) { return std::isfinite(x) && x >= 0; });
  const auto power = r.number("power", "a finite number > 0 (watts)", is_positive);
  const auto color = r.vec3("color", "3 finite numbers >= 0, not all zero",
                            [](double x) { return std::isfinite(x) && x >= 0; });
  if (color && color->isZero(0)) r.fail_got("color", "3 finite numbers >= 0, not all zero");
  const auto mask_range = r.number("shadowmask_range", "a number > 0 (metres)", is_positive);
  const auto range = r.number("range", "a finite number > 0 (metres from its centre)", is_positive);
  const auto angle = r.number("angle_deg", "a number of degrees in (0, 10]",
                              [](double x) { return std::isfinite(x) && x > 0 && x <= 10; });
  for (const LightDesc* light : targets) {
    const bool sun = light->sun_angle_deg > 0;
    if (radius && sun)
      r.fail("radius", fmt::format("'{}' is a sun: give its size as 'angle_deg'", light->name));
    if (angle && !sun)
      r.fail("angle_deg",
             fmt::format("'angle_deg' applies to suns, and '{}' is not one", light->name));
    if (radius && *radius == 0 && light->shape == LightShape::disk)
      r.fail("radius", fmt::format("'{}' is a disk: its radius must be > 0", light->name));
    if (range && (sun || light->shape == LightShape::mesh || light->shape == LightShape::sky))
      r.fail("range", fmt::format("'{}' is a {}, which reaches everywhere: 'range' applies to "
                                  "point, spot, sphere, rectangle and disk lights",
                                  light->name, sun ? "sun" : to_string(light->shape)));
    if (radius && light->shape != LightShape::sphere && light->shape != LightShape::disk)
      r.fail("radius", fmt::format("'radius' applies to sphere and disk lights, and '{}' is a "
                                   "{}",
                                   light->name, to_string(light->shape)));
  }
  if (r.failed()) return r.error();
  for (LightDesc* light : targets) {
    if (radius) {
      // The same exitance-independent power: only the size changes.
      light->radius =
          light->shape == LightShape::sphere ? std::max(*radius, kPointLightRadius) : *radius;
    }
    if (angle) set_sun_angle(*light, *angle);
    if (power) light->power = *power;
    if (color) light->color = *color;
    if (range) {
      // The mask's reach follows the light's where the file gave it none of its own.
      if (light->shadowmask_range == light->range) light->shadowmask_range = *range;
      light->range = *range;
    }
    if (mask_range) light->shadowmask_range = *mask_range;
    light->line = int(r.line());
    if (enabled && !*enabled) light->name.clear();  // removed below
  }
  std::erase_if(lights, [](const LightDesc& l) { return l.name.empty(); });
  return Ok{};
}

}  // namespace

Expected<LevelContents> read_import(const std::filesystem::path& file, const toml::table& table,
                                    std::size_t index) {
  TableReader r(file, table, fmt::format("[[import]] #{}", index + 1));
  r.check_known_keys({"file", "translate", "rotate_deg", "scale", "lights", "object", "light"});
  r.require("file");
  const auto level_file = existing_file(r, file, "file", "level file");
  const Affine3 placement = read_placement(r);
  const bool with_lights = r.boolean("lights").value_or(true);
  const auto object_tables = sub_tables(r, "object");
  const auto light_tables = sub_tables(r, "light");
  if (r.failed()) return r.error();

  auto level = import_level(*level_file, placement, int(r.line()));
  if (!level) {
    return located_error(file, int(r.line()), fmt::format("[[import]] #{}", index + 1),
                         level.error().message);
  }
  if (!with_lights) level->lights.clear();
  for (const toml::table* t : object_tables)
    if (Status s = override_objects(file, *t, *level_file, level->objects); !s) return s.error();
  for (const toml::table* t : light_tables)
    if (Status s = override_lights(file, *t, *level_file, level->lights); !s) return s.error();
  return std::move(*level);
}

}  // namespace sb
