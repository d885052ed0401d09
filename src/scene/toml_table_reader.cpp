// The TOML table reader's helpers (toml_table_reader.h): values and names as messages show them,
// located errors, unknown keys and file keys.
#include "scene/toml_table_reader.h"

#include <array>
#include <charconv>
#include <system_error>

namespace sb {

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

}  // namespace sb
