// Reading the tables of a TOML scene file (https://toml.io/en/v1.0.0, via toml++): typed keys
// whose problems name the file, the line, the item and the key, and unknown keys reported rather
// than ignored, like pbrt-v4's scene parser (docs/scene-format.md, "Errors"). The readers of
// [bake], [[object]] and [[light]] (scene_file_tables.h) are built on it.
#pragma once

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/geometry.h"

namespace sb {

// A string as it would appear in a TOML file, escaped so that an error stays on one line.
std::string toml_string(std::string_view text);

// A name inside single quotes, escaped like toml_string(): 'floor'.
std::string single_quoted(std::string_view name);

// The item part of a message: `object 'floor'`.
std::string item_name(std::string_view kind, std::string_view name);

// A double as TOML writes it: shortest round trip, always with a '.' or an exponent.
std::string format_double(double x);

// The value of a node as the user wrote it (near enough), for "got ..." in messages.
std::string describe(const toml::node& node);

// The number in a TOML integer or float node; nullopt for anything else.
std::optional<double> number_of(const toml::node& node);

// "<file>:<line>: <item>: <problem>", or "<file>: ..." where there is no line to point at.
Error located_error(const std::filesystem::path& file, std::uint32_t line, std::string_view item,
                    std::string_view problem);

// The unknown key that comes first in the file (a table iterates its keys alphabetically).
const toml::key* first_unknown_key(const toml::table& table,
                                   const std::vector<std::string_view>& known);

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

  // A lightmap UV set: a channel in [0, max_channel], or "auto" (generated by the bake), returned
  // as kAutoUvSet (set_uv, scene_file_tables.h, applies either to an object).
  static constexpr int kAutoUvSet = -1;
  std::optional<int> uv_set(std::string_view key, int max_channel) {
    const toml::node* node = find(key);
    if (failed() || !node) return std::nullopt;
    const auto* channel = node->as_integer();
    if (channel && channel->get() >= 0 && channel->get() <= max_channel) return int(channel->get());
    if (const auto* s = node->as_string(); s && s->get() == "auto") return kAutoUvSet;
    fail_got(key, fmt::format("a UV channel from 0 to {} or \"auto\"", max_channel));
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

inline bool is_finite(double x) { return std::isfinite(x); }
inline bool is_positive(double x) { return std::isfinite(x) && x > 0; }

// The optional translate, rotate_deg and scale keys of an [[object]] or [[import]] table, as
// object_transform builds them (scene.h).
Affine3 read_placement(TableReader& r);

// A path key naming an existing regular file, resolved against the scene file's folder.
std::optional<std::filesystem::path> existing_file(TableReader& r,
                                                   const std::filesystem::path& file,
                                                   std::string_view key, std::string_view what);

}  // namespace sb
