// Pre-import checks of OBJ and PLY files (mesh_file_checks.h). OBJ: Wavefront's "Object Files"
// appendix of the Advanced Visualizer manual (v, vt, vn, f; 1-based indices, negative ones count
// back from the latest element). PLY: Turk's PLY format description (Stanford, 1994): an ASCII
// header of `element NAME COUNT` and `property TYPE NAME` / `property list COUNT_TYPE TYPE NAME`
// lines, then the elements in ASCII or binary.
//
// Written by hand: the readers of these formats in Debian's libraries (Assimp, OpenMesh) are the
// ones whose trust in the header is the problem; a check needs only counts and sizes, not a mesh.
#include "scene/mesh_file_checks.h"

#include "core/memory_size.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <system_error>
#include <vector>

namespace sb {

namespace fs = std::filesystem;

namespace {

std::string lower(std::string text) {
  for (char& c : text) c = char(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

// Splits a line at spaces and tabs.
std::vector<std::string_view> tokens_of(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

// A token shown in a message: at most 24 characters, printable ASCII only.
std::string shown(std::string_view token) {
  std::string out;
  for (char c : token.substr(0, 24)) {
    const auto byte = static_cast<unsigned char>(c);
    out += byte >= 0x20 && byte < 0x7f ? c : '?';
  }
  return "'" + out + (token.size() > 24 ? "...'" : "'");
}

bool finite_number(std::string_view token) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  double value = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size() && std::isfinite(value);
}

bool parse_integer(std::string_view token, std::int64_t& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

// Saturating arithmetic for byte counts a hostile header may make overflow.
std::uint64_t saturating_add(std::uint64_t a, std::uint64_t b) {
  return a > std::numeric_limits<std::uint64_t>::max() - b
             ? std::numeric_limits<std::uint64_t>::max()
             : a + b;
}
std::uint64_t saturating_multiply(std::uint64_t a, std::uint64_t b) {
  if (a != 0 && b > std::numeric_limits<std::uint64_t>::max() / a)
    return std::numeric_limits<std::uint64_t>::max();
  return a * b;
}

Error problem(std::string message) { return scene_error(std::move(message)); }

}  // namespace

Status check_obj_text(std::string_view text) {
  // First pass: how many of each element the file holds (Assimp resolves indices after reading
  // the whole file, so a face may name a vertex defined after it).
  struct Counts {
    std::int64_t v = 0, vt = 0, vn = 0;
  };
  const auto each_line = [&](auto&& visit) -> Status {
    std::size_t start = 0;
    int line_number = 0;
    while (start < text.size()) {
      std::size_t end = text.find('\n', start);
      if (end == std::string_view::npos) end = text.size();
      std::string_view line = text.substr(start, end - start);
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      if (const auto hash = line.find('#'); hash != std::string_view::npos)
        line = line.substr(0, hash);
      ++line_number;
      Status status = visit(line_number, tokens_of(line));
      if (!status) return status;
      start = end + 1;
    }
    return Ok{};
  };
  Counts total;
  Status counted = each_line([&](int line, const std::vector<std::string_view>& t) -> Status {
    if (t.empty()) return Ok{};
    const std::size_t wanted = t[0] == "v" || t[0] == "vn" ? 3 : t[0] == "vt" ? 1 : 0;
    if (wanted == 0) return Ok{};
    if (t.size() < wanted + 1) {
      return problem(fmt::format("line {}: '{}' needs {} number(s), got {}", line, t[0], wanted,
                                 t.size() - 1));
    }
    const char* what = t[0] == "v" ? "a vertex position" : t[0] == "vt" ? "a UV" : "a normal";
    for (std::size_t i = 1; i < t.size(); ++i) {
      if (!finite_number(t[i])) {
        return problem(fmt::format("line {}: {} ('{}') has {} where a finite number must be", line,
                                   what, t[0], shown(t[i])));
      }
    }
    if (t[0] == "v") ++total.v;
    if (t[0] == "vt") ++total.vt;
    if (t[0] == "vn") ++total.vn;
    return Ok{};
  });
  if (!counted) return counted;

  Counts so_far;
  return each_line([&](int line, const std::vector<std::string_view>& t) -> Status {
    if (t.empty()) return Ok{};
    if (t[0] == "v") ++so_far.v;
    if (t[0] == "vt") ++so_far.vt;
    if (t[0] == "vn") ++so_far.vn;
    if (t[0] != "f") return Ok{};
    if (t.size() < 4) {
      return problem(
          fmt::format("line {}: a face needs at least 3 corners, got {}", line, t.size() - 1));
    }
    for (std::size_t c = 1; c < t.size(); ++c) {
      // v, v/vt, v//vn or v/vt/vn
      std::string_view parts[3];
      std::size_t count = 0;
      std::string_view rest = t[c];
      while (count < 3) {
        const auto slash = rest.find('/');
        parts[count++] = rest.substr(0, slash);
        if (slash == std::string_view::npos) break;
        rest.remove_prefix(slash + 1);
      }
      static const char* const kinds[3] = {"vertex", "UV", "normal"};
      static const char* const keys[3] = {"v", "vt", "vn"};
      const std::int64_t totals[3] = {total.v, total.vt, total.vn};
      const std::int64_t before[3] = {so_far.v, so_far.vt, so_far.vn};
      for (std::size_t k = 0; k < count; ++k) {
        if (parts[k].empty() && k > 0) continue;  // v//vn leaves vt out
        std::int64_t index = 0;
        if (!parse_integer(parts[k], index) || index == 0) {
          return problem(fmt::format("line {}: face corner {} has {} where a {} index must be",
                                     line, shown(t[c]), shown(parts[k]), kinds[k]));
        }
        const std::int64_t resolved = index > 0 ? index : before[k] + 1 + index;
        if (resolved < 1 || resolved > totals[k]) {
          return problem(
              fmt::format("line {}: face references {} index {}, but the file has {} '{}' line(s)",
                          line, kinds[k], index, totals[k], keys[k]));
        }
      }
    }
    return Ok{};
  });
}

Status check_ply_bytes(std::string_view bytes, std::uint64_t file_bytes) {
  constexpr std::size_t kMaxHeader = 1 << 20;
  const std::string_view start = bytes.substr(0, kMaxHeader);
  if (start.substr(0, 3) != "ply") return Ok{};  // not PLY after all: let Assimp say what it is
  std::size_t header_end = std::string_view::npos;
  for (std::size_t at = start.find("end_header"); at != std::string_view::npos;
       at = start.find("end_header", at + 1)) {
    if (at == 0 || start[at - 1] == '\n') {
      header_end = start.find('\n', at);
      break;
    }
  }
  if (header_end == std::string_view::npos) {
    return problem("PLY header has no 'end_header' line in its first 1 MiB");
  }
  const std::string_view header = start.substr(0, header_end + 1);
  bool ascii = true;
  struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::uint64_t min_bytes = 0;  // per element
    int line = 0;
  };
  std::vector<Element> elements;
  std::size_t at = 0;
  int line_number = 0;
  while (at < header.size()) {
    std::size_t end = header.find('\n', at);
    std::string_view line = header.substr(at, end - at);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    at = end + 1;
    ++line_number;
    const auto t = tokens_of(line);
    if (t.empty()) continue;
    if (t[0] == "format" && t.size() >= 2) {
      ascii = t[1] == "ascii";
    } else if (t[0] == "element") {
      std::int64_t count = 0;
      if (t.size() != 3 || !parse_integer(t[2], count) || count < 0) {
        return problem(fmt::format("PLY header line {}: an element needs a name and a count >= 0",
                                   line_number));
      }
      elements.push_back({std::string(t[1]), std::uint64_t(count), 0, line_number});
    } else if (t[0] == "property") {
      if (elements.empty()) {
        return problem(
            fmt::format("PLY header line {}: a property before any element", line_number));
      }
      // Smallest encoding of one value of this property.
      const auto size_of = [](std::string_view type) -> std::uint64_t {
        if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
        if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
        if (type == "double" || type == "float64") return 8;
        return 4;
      };
      const bool list = t.size() >= 2 && t[1] == "list";
      const std::uint64_t bytes_per_value =
          ascii ? 2 : size_of(t.size() >= 2 ? t[list ? 2 : 1] : "");
      elements.back().min_bytes += bytes_per_value;  // a list holds at least its count
    } else if (t[0] != "ply" && t[0] != "comment" && t[0] != "obj_info" && t[0] != "end_header") {
      return problem(
          fmt::format("PLY header line {}: unknown keyword {}", line_number, shown(t[0])));
    }
  }
  const std::uint64_t body = file_bytes > header.size() ? file_bytes - header.size() : 0;
  std::uint64_t needed = 0;
  for (const Element& e : elements) {
    // Each element still costs the reader a step, and in ASCII at least its line's end.
    if (e.count > 0 && e.min_bytes == 0) {
      return problem(fmt::format("PLY header line {} declares {} '{}' element(s) with no property",
                                 e.line, e.count, e.name));
    }
    const std::uint64_t element_bytes = saturating_multiply(e.count, e.min_bytes);
    needed = saturating_add(needed, element_bytes);
    if (needed > body) {
      return problem(fmt::format(
          "PLY header line {} declares {} '{}' element(s), which need at least {}, but the file "
          "holds {} after its header",
          e.line, e.count, e.name, format_bytes(double(element_bytes)),
          format_bytes(double(body))));
    }
  }
  return Ok{};
}

Status check_mesh_file(const fs::path& file, std::uint64_t max_bytes) {
  std::error_code ec;
  const auto status = fs::status(file, ec);
  if (ec) return problem(ec.message());
  if (!fs::is_regular_file(status)) {
    return problem(fs::is_directory(status) ? "it is a folder, not a mesh file"
                                            : "not a regular file (a device, a FIFO or a socket)");
  }
  const std::uintmax_t size = fs::file_size(file, ec);
  if (ec) return problem(ec.message());
  if (size > max_bytes) {
    return problem(
        fmt::format("the file is {}, more than the {} a mesh file may be under "
                    "[bake] max_memory",
                    format_bytes(double(size)), format_bytes(double(max_bytes))));
  }
  const std::string extension = lower(file.extension().string());
  if (extension != ".obj" && extension != ".ply") return Ok{};
  std::ifstream in(file, std::ios::binary);
  std::string bytes(size, '\0');
  if (!in.read(bytes.data(), std::streamsize(size))) return problem("cannot read the file");
  return extension == ".obj" ? check_obj_text(bytes) : check_ply_bytes(bytes, size);
}

}  // namespace sb
