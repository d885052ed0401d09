// The scene file reader: parses the TOML scene format (https://toml.io/en/v1.0.0, via toml++)
// into a Scene and validates every key against docs/scene-format.md. Like pbrt-v4's scene
// parser, every problem names the file, the line, the item and the key, and keys the reader does
// not use are reported rather than ignored (../shared/docs/style.md, rule 5).
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "core/memory_size.h"
#include "scene/scene.h"

namespace sb {

const char* to_string(Quantity q) {
  switch (q) {
    case Quantity::visibility:
      return "visibility";
    case Quantity::irradiance:
      return "irradiance";
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
  }
  return "?";
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

// Below this sine of the angle between them, an up vector counts as parallel to the normal.
constexpr double parallel_sine = 1e-6;

// A string as it would appear in a TOML file, escaped so that an error stays on one line.
std::string toml_string(std::string_view text) {
  std::string out = "\"";
  for (char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (byte < 0x20 || byte == 0x7f) {
      constexpr char hex[] = "0123456789abcdef";
      out += "\\u00";
      out += hex[byte >> 4];
      out += hex[byte & 15];
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// A name inside single quotes, escaped like toml_string(): 'floor'.
std::string single_quoted(std::string_view name) {
  const std::string q = toml_string(name);
  return fmt::format("'{}'", std::string_view(q).substr(1, q.size() - 2));
}

// The item part of a message: `object 'floor'`.
std::string item_name(std::string_view kind, std::string_view name) {
  return fmt::format("{} {}", kind, single_quoted(name));
}

std::string format_double(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), x);
  std::string text(buffer.data(), result.ptr);
  if (text.find_first_of(".e") == std::string::npos) text += ".0";  // keep it a TOML float
  return text;
}

// The value of a node as the user wrote it (near enough), for "got ..." in messages.
std::string describe(const toml::node& node) {
  if (const auto* v = node.as_integer()) return std::to_string(v->get());
  if (const auto* v = node.as_floating_point()) return format_double(v->get());
  if (const auto* v = node.as_boolean()) return v->get() ? "true" : "false";
  if (const auto* v = node.as_string()) return toml_string(v->get());
  if (const auto* a = node.as_array()) {
    std::string out = "[";
    for (std::size_t i = 0; i < a->size(); ++i) {
      if (i > 0) out += ", ";
      out += describe(*a->get(i));
    }
    return out + "]";
  }
  if (node.is_table()) return "a table";
  return "a date or time";
}

// The number in a TOML integer or float node; nullopt for anything else.
std::optional<double> number_of(const toml::node& node) {
  if (const auto* v = node.as_integer()) return static_cast<double>(v->get());
  if (const auto* v = node.as_floating_point()) return v->get();
  return std::nullopt;
}

// "<file>:<line>: <item>: <problem>", or "<file>: ..." where there is no line to point at.
Error located_error(const std::filesystem::path& file, std::uint32_t line, std::string_view item,
                    std::string_view problem) {
  if (line == 0) return scene_error(fmt::format("{}: {}: {}", file.string(), item, problem));
  return scene_error(fmt::format("{}:{}: {}: {}", file.string(), line, item, problem));
}

// The unknown key that comes first in the file (a table iterates its keys alphabetically).
const toml::key* first_unknown_key(const toml::table& table,
                                   const std::vector<std::string_view>& known) {
  const toml::key* first = nullptr;
  for (const auto& [key, node] : table) {
    if (std::find(known.begin(), known.end(), key.str()) != known.end()) continue;
    if (!first || key.source().begin < first->source().begin) first = &key;
  }
  return first;
}

// Reads the keys of one table. It keeps the first problem found and makes every later read a
// no-op, so a caller reads all keys and then checks failed() once.
class TableReader {
 public:
  TableReader(const std::filesystem::path& file, const toml::table& table, std::string item)
      : file_(file), table_(table), item_(std::move(item)) {}

  void set_item(std::string item) { item_ = std::move(item); }
  bool failed() const { return error_.has_value(); }
  const Error& error() const { return *error_; }
  std::uint32_t line() const { return table_.source().begin.line; }
  const toml::node* find(std::string_view key) const { return table_.get(key); }

  // Reports at the line of `key` when present, else at the line of the table.
  void fail(std::string_view key, std::string problem) {
    if (failed()) return;
    const toml::node* node = key.empty() ? nullptr : find(key);
    const std::uint32_t at =
        node && node->source().begin.line > 0 ? node->source().begin.line : line();
    error_ = located_error(file_, at, item_, problem);
  }

  void check_known_keys(const std::vector<std::string_view>& known) {
    if (failed()) return;
    if (const toml::key* key = first_unknown_key(table_, known)) {
      const std::uint32_t at = key->source().begin.line > 0 ? key->source().begin.line : line();
      error_ = located_error(file_, at, item_,
                             fmt::format("unknown key {} (known: {})", single_quoted(key->str()),
                                         fmt::join(known, ", ")));
    }
  }

  // A key that this kind of item does not take (a shape-specific key on another shape).
  void forbid(std::string_view key, std::string_view why) {
    if (find(key)) fail(key, fmt::format("'{}' {}", key, why));
  }

  bool require(std::string_view key) {
    if (failed()) return false;
    if (find(key)) return true;
    fail("", fmt::format("missing required key '{}'", key));
    return false;
  }

  void fail_got(std::string_view key, std::string_view requirement) {
    fail(key, fmt::format("'{}' must be {}, got {}", key, requirement, describe(*find(key))));
  }

  std::optional<std::string> string(std::string_view key) {
    const toml::node* node = find(key);
    if (failed() || !node) return std::nullopt;
    if (const auto* s = node->as_string()) return s->get();
    fail_got(key, "a string");
    return std::nullopt;
  }

  std::optional<bool> boolean(std::string_view key) {
    const toml::node* node = find(key);
    if (failed() || !node) return std::nullopt;
    if (const auto* b = node->as_boolean()) return b->get();
    fail_got(key, "true or false");
    return std::nullopt;
  }

  // An integer in [lo, hi]; a float (even 512.0) is refused, as the key counts things.
  std::optional<std::int64_t> integer(std::string_view key, std::int64_t lo, std::int64_t hi) {
    const toml::node* node = find(key);
    if (failed() || !node) return std::nullopt;
    const auto* v = node->as_integer();
    if (v && v->get() >= lo && v->get() <= hi) return v->get();
    if (hi >= std::numeric_limits<int>::max()) {  // no upper bound worth stating
      fail_got(key, fmt::format("an integer >= {}", lo));
    } else {
      fail_got(key, fmt::format("an integer from {} to {}", lo, hi));
    }
    return std::nullopt;
  }

  // One number (TOML integer or float) for which `valid` holds.
  std::optional<double> number(std::string_view key, std::string_view requirement,
                               const std::function<bool(double)>& valid) {
    const toml::node* node = find(key);
    if (failed() || !node) return std::nullopt;
    const std::optional<double> x = number_of(*node);
    if (x && valid(*x)) return x;
    fail_got(key, requirement);
    return std::nullopt;
  }

  // An array of exactly `count` numbers, each satisfying `valid`.
  std::optional<std::vector<double>> numbers(std::string_view key, std::size_t count,
                                             std::string_view requirement,
                                             const std::function<bool(double)>& valid) {
    const toml::node* node = find(key);
    if (failed() || !node) return std::nullopt;
    if (const auto* array = node->as_array(); array && array->size() == count) {
      std::vector<double> values;
      for (const toml::node& element : *array) {
        const std::optional<double> x = number_of(element);
        if (!x || !valid(*x)) break;
        values.push_back(*x);
      }
      if (values.size() == count) return values;
    }
    fail_got(key, requirement);
    return std::nullopt;
  }

  std::optional<Vec3> vec3(std::string_view key, std::string_view requirement,
                           const std::function<bool(double)>& valid) {
    const auto v = numbers(key, 3, requirement, valid);
    if (!v) return std::nullopt;
    return Vec3((*v)[0], (*v)[1], (*v)[2]);
  }

 private:
  const std::filesystem::path& file_;
  const toml::table& table_;
  std::string item_;
  std::optional<Error> error_;
};

bool is_finite(double x) { return std::isfinite(x); }
bool is_positive(double x) { return std::isfinite(x) && x > 0; }

// Usable as a file stem on every platform the outputs travel to: no separators, no hidden files.
bool is_valid_object_name(std::string_view name) {
  if (name.empty() || name.front() == '.') return false;
  for (char c : name) {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '.' || c == '-';
    if (!ok) return false;
  }
  return true;
}

Expected<BakeSettings> read_bake(const std::filesystem::path& file, const toml::table& table) {
  TableReader r(file, table, "[bake]");
  r.check_known_keys({"resolution", "method", "quantity", "samples", "margin", "seed", "max_memory",
                      "error_texels", "max_image", "max_triples", "light_parts", "trace",
                      "convolve", "trace_error_texels", "blocker_combine", "weighting",
                      "shadow_map", "pcf_radius", "erosion_factor"});
  BakeSettings bake;
  const int int_max = std::numeric_limits<int>::max();
  if (auto v = r.integer("resolution", 1, 16384)) bake.resolution = static_cast<int>(*v);
  if (auto v = r.string("method")) {
    const auto& known = known_methods();
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
    } else {
      r.fail_got("quantity", "\"visibility\" or \"irradiance\"");
    }
  }
  if (auto v = r.integer("samples", 1, int_max)) bake.samples = static_cast<int>(*v);
  if (auto v = r.integer("margin", 0, int_max)) bake.margin = static_cast<int>(*v);
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
  if (auto v = r.number("error_texels", "a number > 0", is_positive)) bake.error_texels = *v;
  if (auto v = r.boolean("trace")) bake.trace = *v;
  if (auto v = r.boolean("convolve")) bake.convolve = *v;
  if (auto v = r.number("trace_error_texels", "a number >= 0",
                        [](double x) { return std::isfinite(x) && x >= 0; })) {
    bake.trace_error_texels = *v;
  }
  if (auto v = r.integer("max_image", 64, 16384)) bake.max_image = static_cast<int>(*v);
  if (auto v = r.string("blocker_combine")) {
    if (*v == "product" || *v == "sum") {
      bake.blocker_combine = *v == "sum" ? BlockerCombine::sum : BlockerCombine::product;
    } else {
      r.fail_got("blocker_combine", "\"product\" or \"sum\"");
    }
  }
  if (auto v = r.string("weighting")) {
    if (*v == "irradiance" || *v == "emission") {
      bake.weighting =
          *v == "irradiance" ? ConvolutionWeighting::irradiance : ConvolutionWeighting::emission;
    } else {
      r.fail_got("weighting", "\"irradiance\" or \"emission\"");
    }
  }
  if (auto v = r.integer("max_triples", 1, 1 << 20)) bake.max_triples = static_cast<int>(*v);
  if (auto v = r.integer("light_parts", 1, 4)) {
    if (*v == 3) {
      r.fail_got("light_parts", "1, 2 or 4");
    } else {
      bake.light_parts = static_cast<int>(*v);
    }
  }
  if (auto v = r.integer("shadow_map", 64, 16384)) bake.shadow_map = static_cast<int>(*v);
  if (auto v = r.number("pcf_radius", "a number >= 0",
                        [](double x) { return std::isfinite(x) && x >= 0; })) {
    bake.pcf_radius = *v;
  }
  if (auto v = r.string("erosion_factor")) {
    if (*v == "pcf" || *v == "distance") {
      bake.erosion_factor = *v == "pcf" ? ErosionFactor::pcf : ErosionFactor::distance;
    } else {
      r.fail_got("erosion_factor", "\"pcf\" or \"distance\"");
    }
  }
  if (r.failed()) return r.error();
  return bake;
}

// A path key naming an existing regular file, resolved against the scene file's folder.
std::optional<std::filesystem::path> existing_file(TableReader& r,
                                                   const std::filesystem::path& file,
                                                   std::string_view key, std::string_view what) {
  auto name = r.string(key);
  if (!name) return std::nullopt;
  const std::filesystem::path resolved = file.parent_path() / *name;
  std::error_code ec;
  std::filesystem::path looked_for = std::filesystem::absolute(resolved, ec).lexically_normal();
  if (ec) looked_for = resolved;
  const std::string shown = single_quoted(*name);
  const auto status = std::filesystem::status(looked_for, ec);
  if (name->empty()) {
    r.fail(key, fmt::format("'{}' must not be empty", key));
  } else if (ec && ec != std::errc::no_such_file_or_directory) {
    // A loop of symbolic links, a folder we may not enter, ...: say which.
    r.fail(key, fmt::format("{} {} cannot be opened: {} (looked for {})", what, shown, ec.message(),
                            looked_for.string()));
  } else if (!std::filesystem::exists(status)) {
    r.fail(key, fmt::format("{} {} not found (looked for {})", what, shown, looked_for.string()));
  } else if (!std::filesystem::is_regular_file(status)) {
    r.fail(key, fmt::format("{} {} is not a regular file (looked for {})", what, shown,
                            looked_for.string()));
  }
  return looked_for;
}

Expected<ObjectDesc> read_object(const std::filesystem::path& file, const toml::table& table,
                                 std::size_t index) {
  TableReader r(file, table, fmt::format("[[object]] #{}", index + 1));
  ObjectDesc obj;
  obj.line = static_cast<int>(r.line());
  if (r.require("name")) {
    if (auto name = r.string("name")) {
      if (is_valid_object_name(*name)) {
        obj.name = *name;
        r.set_item(item_name("object", obj.name));
      } else {
        r.fail_got("name",
                   "usable as a file stem: letters, digits, '_', '.', '-', not starting with '.'");
      }
    }
  }
  r.check_known_keys({"name", "mesh", "receiver", "blocker", "uv", "allow_uncovered", "translate",
                      "rotate_deg", "scale"});
  r.require("mesh");
  if (auto mesh = existing_file(r, file, "mesh", "mesh file")) obj.mesh = *mesh;
  if (auto v = r.boolean("receiver")) obj.receiver = *v;
  if (auto v = r.boolean("blocker")) obj.blocker = *v;
  if (auto v = r.boolean("allow_uncovered")) obj.allow_uncovered = *v;
  if (auto v = r.integer("uv", 0, std::numeric_limits<int>::max())) {
    obj.uv_channel = static_cast<int>(*v);
  }
  const Vec3 translate = r.vec3("translate", "3 finite numbers", is_finite).value_or(Vec3::Zero());
  const Vec3 rotate_deg =
      r.vec3("rotate_deg", "3 finite numbers (degrees)", is_finite).value_or(Vec3::Zero());
  const Vec3 scale = r.vec3("scale", "3 finite non-zero numbers", [](double x) {
                        return std::isfinite(x) && x != 0;
                      }).value_or(Vec3::Ones());
  obj.transform = object_transform(translate, rotate_deg, scale);
  if (r.failed()) return r.error();
  return obj;
}

// The default height axis of a rectangle or disk: +Y, or +Z where +Y is along the normal, made
// perpendicular to the normal like a given `up` (Gram-Schmidt), so the light lies in its plane.
Vec3 default_up(const Vec3& normal) {
  const Vec3 y = Vec3::UnitY();
  const Vec3 axis = (y - y.dot(normal) * normal).norm() < parallel_sine ? Vec3::UnitZ() : y;
  return (axis - axis.dot(normal) * normal).normalized();
}

Expected<LightDesc> read_light(const std::filesystem::path& file, const toml::table& table,
                               std::size_t index) {
  TableReader r(file, table, fmt::format("[[light]] #{}", index + 1));
  LightDesc light;
  light.line = static_cast<int>(r.line());
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
  r.check_known_keys(
      {"name", "shape", "position", "normal", "up", "size", "radius", "color", "power", "texture"});
  if (r.require("shape")) {
    if (auto shape = r.string("shape")) {
      if (*shape == "rectangle") {
        light.shape = LightShape::rectangle;
      } else if (*shape == "disk") {
        light.shape = LightShape::disk;
      } else if (*shape == "sphere") {
        light.shape = LightShape::sphere;
      } else {
        r.fail_got("shape", "\"rectangle\", \"disk\" or \"sphere\"");
      }
    }
  }
  if (r.failed()) return r.error();  // every later key depends on the shape
  const std::string shape_name = to_string(light.shape);
  const bool is_rectangle = light.shape == LightShape::rectangle;
  const bool is_sphere = light.shape == LightShape::sphere;

  if (r.require("position")) {
    if (auto v = r.vec3("position", "3 finite numbers (metres)", is_finite)) light.position = *v;
  }

  if (is_sphere) {
    r.forbid("normal", "applies only to rectangle and disk lights, not sphere");
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
  } else if (r.require("radius")) {
    // Both `radius = 0.1` and `radius = [0.1]` are accepted.
    const std::string_view requirement = "a positive number or [r] (metres)";
    if (r.find("radius")->is_array()) {
      if (auto v = r.numbers("radius", 1, requirement, is_positive)) light.radius = (*v)[0];
    } else if (auto v = r.number("radius", requirement, is_positive)) {
      light.radius = *v;
    }
  }

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
  if (is_sphere) {
    r.forbid("texture", "applies only to rectangle and disk lights, not sphere");
  } else if (r.find("texture")) {
    if (auto texture = existing_file(r, file, "texture", "texture image")) light.texture = *texture;
  }
  if (r.failed()) return r.error();
  return light;
}

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

}  // namespace

Expected<Scene> load_scene(const std::filesystem::path& file) {
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
  const std::vector<std::string_view> top_level_keys = {"bake", "object", "light"};
  if (const toml::key* key = first_unknown_key(root, top_level_keys)) {
    return located_error(file, key->source().begin.line, "top level",
                         fmt::format("unknown key {} (known: {})", single_quoted(key->str()),
                                     fmt::join(top_level_keys, ", ")));
  }
  std::vector<const toml::table*> object_tables;
  std::vector<const toml::table*> light_tables;
  for (const auto& [key, node] : root) {
    if (key == "bake") {
      const toml::table* bake = node.as_table();
      if (!bake) {
        return located_error(file, key.source().begin.line, "top level",
                             "'bake' must be a table, written [bake]");
      }
      Expected<BakeSettings> settings = read_bake(file, *bake);
      if (!settings) return settings.error();
      scene.bake = *settings;
      for (const auto& [name, value] : *bake)
        scene.bake_keys.push_back({std::string(name.str()), int(name.source().begin.line)});
      // toml++ keeps a table's keys sorted by name; the scene's readers want them as written.
      std::stable_sort(scene.bake_keys.begin(), scene.bake_keys.end(),
                       [](const SettingGiven& a, const SettingGiven& b) { return a.line < b.line; });
    } else {
      auto tables = tables_of(file, key, node);
      if (!tables) return tables.error();
      (key == "object" ? object_tables : light_tables) = *tables;
    }
  }

  auto objects = read_unique<ObjectDesc>(file, object_tables, "object", read_object);
  if (!objects) return objects.error();
  scene.objects = std::move(*objects);
  auto lights = read_unique<LightDesc>(file, light_tables, "light", read_light);
  if (!lights) return lights.error();
  scene.lights = std::move(*lights);

  if (scene.objects.empty()) {
    return located_error(file, 0, "scene", "no [[object]] table; a scene needs at least one");
  }
  if (scene.lights.empty()) {
    return located_error(file, 0, "scene", "no [[light]] table; a scene needs at least one");
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
