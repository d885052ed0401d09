// The [[light]] tables of a scene file (docs/scene-format.md): shape, placement, size, colour,
// power and texture, each shape's keys refused on the others.
#include "scene/scene_file_tables.h"
#include "scene/toml_table_reader.h"

#include <numbers>

#include "scene/sky_models.h"
#include "scene/sun_light.h"

namespace sb {

namespace {

// Below this sine of the angle between them, an up vector counts as parallel to the normal.
constexpr double parallel_sine = 1e-6;

// The default height axis of a rectangle or disk: +Y, or +Z where +Y is along the normal, made
// perpendicular to the normal like a given `up` (Gram-Schmidt), so the light lies in its plane.
Vec3 default_up(const Vec3& normal) {
  const Vec3 y = Vec3::UnitY();
  const Vec3 axis = (y - y.dot(normal) * normal).norm() < parallel_sine ? Vec3::UnitZ() : y;
  return (axis - axis.dot(normal) * normal).normalized();
}

// A spot's cone: `direction` (its axis), `cone_deg` (the whole cone's angle, as Blender's spot
// size) and `blend` (the part of it over which the light fades, as Blender's spot blend).
void read_cone(TableReader& r, LightDesc& light) {
  if (r.require("direction")) {
    if (auto v = r.vec3("direction", "3 finite numbers, not all zero", is_finite)) {
      if (v->isZero(0)) r.fail_got("direction", "3 finite numbers, not all zero");
      light.spot_axis = v->normalized();
    }
  }
  if (r.require("cone_deg")) {
    if (auto v = r.number("cone_deg", "a number of degrees in (0, 180)",
                          [](double x) { return std::isfinite(x) && x > 0 && x < 180; }))
      light.spot_outer = 0.5 * *v * std::numbers::pi / 180;
  }
  double blend = kSpotBlend;
  if (auto v = r.number("blend", "a number in [0, 1]",
                        [](double x) { return std::isfinite(x) && x >= 0 && x <= 1; }))
    blend = *v;
  light.spot_inner = light.spot_outer * (1 - blend);
}

// A sun: `direction` (where its light goes), `angle_deg` and `irradiance` on a surface facing
// it, made a distant disk by sun_light (sun_light.h), placed for the scene by the bake.
Expected<LightDesc> read_sun(TableReader& r, LightDesc light) {
  for (const char* key : {"position", "normal", "up", "size", "radius", "power", "texture",
                          "cone_deg", "blend", "strength", "map", "rotation_deg", "parts", "model",
                          "turbidity", "sun", "sun_direction", "range"})
    r.forbid(key,
             "does not apply to a sun, which is given by 'direction', 'angle_deg' and "
             "'irradiance' (and reaches everywhere)");
  Vec3 direction = Vec3(0, 0, -1);
  if (r.require("direction")) {
    if (auto v = r.vec3("direction", "3 finite numbers, not all zero", is_finite)) {
      if (v->isZero(0)) r.fail_got("direction", "3 finite numbers, not all zero");
      direction = v->normalized();
    }
  }
  double angle = kSunAngleDeg;
  if (auto v = r.number("angle_deg", "a number of degrees in (0, 10]",
                        [](double x) { return std::isfinite(x) && x > 0 && x <= 10; }))
    angle = *v;
  double irradiance = 1;
  if (r.require("irradiance")) {
    if (auto v = r.number("irradiance", "a number > 0 (W/m² on a surface facing the sun)",
                          [](double x) { return std::isfinite(x) && x > 0 && x <= 1e9; }))
      irradiance = *v;
  }
  const std::string_view color_requirement = "3 finite numbers >= 0, not all zero";
  if (auto v =
          r.vec3("color", color_requirement, [](double x) { return std::isfinite(x) && x >= 0; })) {
    if (v->isZero(0)) r.fail_got("color", color_requirement);
    light.color = *v;
  }
  if (auto v = r.number("shadowmask_range", "a number > 0 (metres)", is_positive))
    light.shadowmask_range = *v;
  if (r.failed()) return r.error();
  Bounds3 origin;
  origin.extend(Vec3::Zero());
  LightDesc sun = sun_light(direction, angle, irradiance, origin);
  sun.name = light.name;
  sun.line = light.line;
  sun.color = light.color;
  sun.shadowmask_range = light.shadowmask_range;
  return sun;
}

// A sky's `model`: "uniform" (or its `map`), or "preetham", Preetham's clear sky
// (scene/sky_models.h) of `turbidity` around the sun light named `sun`, or around a sun whose
// light travels along `sun_direction`; with neither, the scene's one sun light
// (resolve_sky_suns, scene_file_tables.h).
void read_sky_model(TableReader& r, LightDesc& light) {
  const std::optional<std::string> model = r.string("model");
  if (model && *model != "uniform" && *model != "preetham")
    r.fail_got("model", "\"uniform\" or \"preetham\"");
  if (!model || *model != "preetham") {
    for (const char* key : {"turbidity", "sun", "sun_direction"})
      r.forbid(key, "applies only to a sky of model = \"preetham\"");
    return;
  }
  r.forbid("map", "is a sky of its own; model = \"preetham\" is another (leave one out)");
  r.forbid("rotation_deg", "turns a map; a Preetham sky turns with its sun");
  light.sky_turbidity = kDefaultTurbidity;
  if (auto v = r.number("turbidity",
                        fmt::format("a number in [{:g}, {:g}]", kMinTurbidity, kMaxTurbidity),
                        [](double x) { return x >= kMinTurbidity && x <= kMaxTurbidity; }))
    light.sky_turbidity = *v;
  if (r.find("sun") && r.find("sun_direction"))
    r.fail("sun_direction", "'sun' and 'sun_direction' both place the sky's sun; give one");
  if (auto name = r.string("sun")) {
    if (name->empty()) r.fail_got("sun", "the name of a sun light");
    light.sky_sun = *name;
  }
  if (auto v = r.vec3("sun_direction", "3 finite numbers, not all zero", is_finite)) {
    if (v->isZero(0)) r.fail_got("sun_direction", "3 finite numbers, not all zero");
    light.sky_sun_direction = v->normalized();
  }
}

// A sky: `color` and `strength` (its radiance, W/m²/sr, as Blender's Background), an optional
// equirectangular `map` and its `rotation_deg` about the zenith `up` (+Z; a glTF level's is
// +Y), and the `parts` it is baked as
// (scene/sky.h); placed around the scene by the bake.
Expected<LightDesc> read_sky(TableReader& r, const std::filesystem::path& file, LightDesc light) {
  for (const char* key : {"position", "normal", "size", "radius", "power", "texture", "direction",
                          "angle_deg", "irradiance", "cone_deg", "blend", "range"})
    r.forbid(key,
             "does not apply to a sky, which is given by 'color', 'strength', 'map' or "
             "'model', 'rotation_deg', 'up' and 'parts' (and reaches everywhere)");
  light.shape = LightShape::sky;
  light.up = Vec3::UnitZ();  // a scene file's zenith; a glTF level's is +Y
  if (auto v = r.vec3("up", "3 finite numbers, not all zero", is_finite)) {
    if (v->isZero(0)) r.fail_got("up", "3 finite numbers, not all zero");
    light.up = v->normalized();
  }
  const std::string_view color_requirement = "3 finite numbers >= 0, not all zero";
  if (auto v =
          r.vec3("color", color_requirement, [](double x) { return std::isfinite(x) && x >= 0; })) {
    if (v->isZero(0)) r.fail_got("color", color_requirement);
    light.color = *v;
  }
  if (auto v = r.number("strength", "a number > 0 (radiance, W/m²/sr)",
                        [](double x) { return std::isfinite(x) && x > 0 && x <= 1e9; }))
    light.sky_strength = *v;
  if (r.find("map")) {
    if (auto map = existing_file(r, file, "map", "environment map")) light.texture = *map;
  }
  if (auto v = r.number("rotation_deg", "a finite number of degrees", is_finite))
    light.sky_rotation_deg = *v;
  if (auto v = r.integer("parts", 20, 4096)) light.sky_parts = static_cast<int>(*v);
  read_sky_model(r, light);
  if (auto v = r.number("shadowmask_range", "a number > 0 (metres)", is_positive))
    light.shadowmask_range = *v;
  if (r.failed()) return r.error();
  return light;
}

// A light's `name`, required and not empty; the table's later errors name the light by it.
void read_light_name(TableReader& r, LightDesc& light) {
  if (r.require("name")) {
    if (auto name = r.string("name")) {
      if (name->empty()) {
        r.fail("name", "'name' must not be empty");
      } else {
        light.name = *name;
        r.set_item(item_name("light", light.name));
      }
    }
  }
}

// Refuses keys no [[light]] table has.
void check_light_keys(TableReader& r) {
  r.check_known_keys({"name",
                      "shape",
                      "position",
                      "normal",
                      "up",
                      "size",
                      "radius",
                      "color",
                      "power",
                      "texture",
                      "shadowmask_range",
                      "range",
                      "direction",
                      "angle_deg",
                      "irradiance",
                      "cone_deg",
                      "blend",
                      "strength",
                      "map",
                      "rotation_deg",
                      "parts",
                      "model",
                      "turbidity",
                      "sun",
                      "sun_direction"});
}

// Refuses a sun's and a sky's keys on a local light (`shape_name`), and reads a spot's cone or
// refuses its keys on any other.
void read_spot_or_forbid(TableReader& r, LightDesc& light, bool spot,
                         const std::string& shape_name) {
  for (const char* key : {"angle_deg", "irradiance"})
    r.forbid(key, fmt::format("applies only to sun lights, not {}", shape_name));
  for (const char* key :
       {"strength", "map", "rotation_deg", "parts", "model", "turbidity", "sun", "sun_direction"})
    r.forbid(key, fmt::format("applies only to sky lights, not {}", shape_name));
  if (spot) {
    read_cone(r, light);
  } else {
    for (const char* key : {"direction", "cone_deg", "blend"})
      r.forbid(key, fmt::format("applies only to spot lights, not {}", shape_name));
  }
}

// A rectangle's or disk's `normal`, and a rectangle's `up` made perpendicular to it (a default
// height axis where it has none); both refused where they do not apply.
void read_orientation(TableReader& r, LightDesc& light, const std::string& shape_name) {
  const bool is_rectangle = light.shape == LightShape::rectangle;
  const bool is_sphere = light.shape == LightShape::sphere;
  if (is_sphere) {
    r.forbid("normal",
             fmt::format("applies only to rectangle and disk lights, not {}", shape_name));
  } else if (r.require("normal")) {
    if (auto v = r.vec3("normal", "3 finite numbers, not all zero", is_finite)) {
      if (v->isZero(0)) r.fail_got("normal", "3 finite numbers, not all zero");
      light.normal = v->normalized();
    }
  }

  if (!is_rectangle) {
    r.forbid("up", fmt::format("applies only to rectangle lights, not {}", shape_name));
    if (!is_sphere) light.up = default_up(light.normal);
  } else if (r.find("up")) {
    if (auto v = r.vec3("up", "3 finite numbers, not all zero", is_finite)) {
      // Gram-Schmidt: keep only the part of up across the normal.
      const Vec3 across = *v - v->dot(light.normal) * light.normal;
      if (v->isZero(0)) {
        r.fail_got("up", "3 finite numbers, not all zero");
      } else if (across.norm() < parallel_sine * v->norm()) {
        r.fail("up", fmt::format("'up' must not be parallel to 'normal', got {} with normal {}",
                                 describe(*r.find("up")), describe(*r.find("normal"))));
      } else {
        light.up = across.normalized();
      }
    }
  } else {
    light.up = default_up(light.normal);
  }
}

// A rectangle's `size` or a disk's, sphere's or spot's `radius`, each refused where it does not
// apply; a sphere's radius is at least kPointLightRadius.
void read_extent(TableReader& r, LightDesc& light, bool spot, const std::string& shape_name) {
  const bool is_rectangle = light.shape == LightShape::rectangle;
  const bool is_sphere = light.shape == LightShape::sphere;
  if (!is_rectangle) {
    r.forbid("size", fmt::format("applies only to rectangle lights, not {}", shape_name));
  } else if (r.require("size")) {
    if (auto v =
            r.numbers("size", 2, "2 positive numbers (width, height in metres)", is_positive)) {
      light.width = (*v)[0];
      light.height = (*v)[1];
    }
  }

  if (is_rectangle) {
    r.forbid("radius", "applies only to disk and sphere lights, not rectangle");
  } else if (spot && !r.find("radius")) {
    light.radius = kPointLightRadius;  // a spot is a point unless given a radius
  } else if (r.require("radius")) {
    // Both `radius = 0.1` and `radius = [0.1]` are accepted; a sphere's may be 0, a point light.
    const std::string_view requirement = is_sphere
                                             ? "a number >= 0 or [r] (metres; 0: a point light)"
                                             : "a positive number or [r] (metres)";
    const auto valid = [&](double x) {
      return is_sphere ? std::isfinite(x) && x >= 0 : is_positive(x);
    };
    if (r.find("radius")->is_array()) {
      if (auto v = r.numbers("radius", 1, requirement, valid)) light.radius = (*v)[0];
    } else if (auto v = r.number("radius", requirement, valid)) {
      light.radius = *v;
    }
    if (is_sphere && light.radius < kPointLightRadius) light.radius = kPointLightRadius;
  }
}

// A local light's `color` and `power`, refused where their exitance is outside what a lightmap
// holds.
void read_emission(TableReader& r, LightDesc& light) {
  const bool is_rectangle = light.shape == LightShape::rectangle;
  const bool is_sphere = light.shape == LightShape::sphere;
  const std::string_view color_requirement = "3 finite numbers >= 0, not all zero";
  if (auto v =
          r.vec3("color", color_requirement, [](double x) { return std::isfinite(x) && x >= 0; })) {
    if (v->isZero(0)) r.fail_got("color", color_requirement);
    light.color = *v;
  }

  if (r.require("power")) {
    if (auto v = r.number("power", "a finite number > 0 (watts)", is_positive)) light.power = *v;
  }
  if (!r.failed() && light.power > 0) {
    // Radiant exitance of the brightest channel. Irradiance never exceeds it (a form factor is at
    // most 1); the bounds keep every lightmap value a normal 32-bit float.
    const double area = is_rectangle ? light.width * light.height
                        : is_sphere  ? 4 * std::numbers::pi * light.radius * light.radius
                                     : std::numbers::pi * light.radius * light.radius;
    const double exitance = light.power * light.color.maxCoeff() / area;
    constexpr double kMaxExitance = 1e15;  // the Sun's surface: 6.3e7 W/m²
    constexpr double kMinExitance = 1e-15;
    if (!(exitance <= kMaxExitance) || !(exitance >= kMinExitance)) {
      r.fail("power",
             fmt::format("'power' {} W over {} m² is an exitance of {} W/m², outside "
                         "the {} to {} W/m² a lightmap holds; check 'power' and the "
                         "light's size",
                         format_double(light.power), format_double(area), format_double(exitance),
                         format_double(kMinExitance), format_double(kMaxExitance)));
    }
  }
}

// A local light's `texture` (refused on a sphere), `range` and `shadowmask_range`.
void read_texture_and_range(TableReader& r, const std::filesystem::path& file, LightDesc& light) {
  if (light.shape == LightShape::sphere) {
    r.forbid("texture", "applies only to rectangle and disk lights, not sphere");
  } else if (r.find("texture")) {
    if (auto texture = existing_file(r, file, "texture", "texture image")) light.texture = *texture;
  }
  if (auto v = r.number("range", "a finite number > 0 (metres from its centre)", is_positive)) {
    light.range = *v;
    light.shadowmask_range = *v;
  }
  if (auto v = r.number("shadowmask_range", "a number > 0 (metres)", is_positive))
    light.shadowmask_range = *v;
}

}  // namespace

Status resolve_sky_suns(const std::filesystem::path& file, std::vector<LightDesc>& lights) {
  const auto is_sun = [](const LightDesc& l) { return l.sun_angle_deg > 0; };
  for (LightDesc& sky : lights) {
    if (sky.shape != LightShape::sky || !(sky.sky_turbidity > 0)) continue;
    const auto fail = [&](const std::string& problem) {
      return located_error(file, std::uint32_t(std::max(sky.line, 0)), item_name("light", sky.name),
                           problem);
    };
    if (!sky.sky_sun.empty()) {
      const auto named = std::find_if(lights.begin(), lights.end(),
                                      [&](const LightDesc& l) { return l.name == sky.sky_sun; });
      if (named == lights.end())
        return fail(
            fmt::format("'sun' names '{}', and the scene has no light of that name", sky.sky_sun));
      if (!is_sun(*named))
        return fail(fmt::format("'sun' names '{}', a {} light, not a sun", sky.sky_sun,
                                to_string(named->shape)));
      sky.sky_sun_direction = named->normal;
    } else if (sky.sky_sun_direction.isZero(0)) {
      const auto suns = std::count_if(lights.begin(), lights.end(), is_sun);
      if (suns != 1)
        return fail(fmt::format(
            "a Preetham sky needs its sun: 'sun' (the name of a sun light) or 'sun_direction', "
            "as the scene has {} sun lights",
            suns));
      sky.sky_sun_direction = std::find_if(lights.begin(), lights.end(), is_sun)->normal;
    }
    if (-sky.sky_sun_direction.dot(sky.up) < 0)
      return fail(
          "its sun is below the horizon (its light travels upwards along 'up'); the Preetham "
          "sky is a daylight sky");
  }
  return Ok{};
}

Expected<LightDesc> read_light(const std::filesystem::path& file, const toml::table& table,
                               std::size_t index) {
  TableReader r(file, table, fmt::format("[[light]] #{}", index + 1));
  LightDesc light;
  light.line = static_cast<int>(r.line());
  read_light_name(r, light);
  check_light_keys(r);
  bool spot = false;
  if (r.require("shape")) {
    if (auto shape = r.string("shape")) {
      if (*shape == "rectangle") {
        light.shape = LightShape::rectangle;
      } else if (*shape == "disk") {
        light.shape = LightShape::disk;
      } else if (*shape == "sphere") {
        light.shape = LightShape::sphere;
      } else if (*shape == "spot") {
        light.shape = LightShape::sphere;
        spot = true;
      } else if (*shape == "sun") {
        return read_sun(r, std::move(light));
      } else if (*shape == "sky") {
        return read_sky(r, file, std::move(light));
      } else {
        r.fail_got("shape", "\"rectangle\", \"disk\", \"sphere\", \"spot\", \"sun\" or \"sky\"");
      }
    }
  }
  if (r.failed()) return r.error();  // every later key depends on the shape
  const std::string shape_name = spot ? "spot" : to_string(light.shape);
  read_spot_or_forbid(r, light, spot, shape_name);
  if (r.require("position")) {
    if (auto v = r.vec3("position", "3 finite numbers (metres)", is_finite)) light.position = *v;
  }
  read_orientation(r, light, shape_name);
  read_extent(r, light, spot, shape_name);
  read_emission(r, light);
  read_texture_and_range(r, file, light);
  if (r.failed()) return r.error();
  return light;
}

}  // namespace sb
