// A shard's receivers on disk (shard_files.h).
#include "formats/shard_files.h"

#include "formats/json_fields.h"
#include "formats/receiver_record.h"
#include "methods/light_mix.h"

#include <fmt/format.h>
#include <xxhash.h>

#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

namespace sb {

namespace {

using json = nlohmann::ordered_json;

constexpr std::uint32_t kReceiverMagic = 0x52535342;  // "SBSR"
constexpr std::uint32_t kMeshMagic = 0x4D535342;      // "SBSM"
// 2: receivers' seams; 3: UV stretch, density spread; 4: tiles, the method's tallies; 5: the
// receiver's record as the manifest writes it (receiver_record.h); 6: per-light images by tiles.
constexpr std::uint32_t kVersion = 6;
// A lightmap side no bake makes (resolution ≤ 16384), so that a damaged header cannot make the
// reader allocate terabytes.
constexpr std::uint64_t kMaxSide = 16384;

// Appends values' bytes, then zeros up to a multiple of 4.
template <typename T>
void put(std::string& out, const T* values, std::size_t count) {
  if (count > 0) out.append(reinterpret_cast<const char*>(values), count * sizeof(T));
  while (out.size() % 4 != 0) out.push_back('\0');
}
void put_u64(std::string& out, std::uint64_t v) { put(out, &v, 1); }

// Reads a binary file's arrays in order, each checked against what is left.
class Unpacker {
 public:
  explicit Unpacker(std::string bytes) : bytes_(std::move(bytes)) {}
  std::uint64_t u64() {
    std::uint64_t v = 0;
    take(&v, 1);
    return v;
  }
  std::uint32_t u32() {
    std::uint32_t v = 0;
    take(&v, 1);
    return v;
  }
  template <typename T>
  void take(T* out, std::size_t count) {
    const std::size_t size = count * sizeof(T);
    if (!ok_ || count > bytes_.size() / sizeof(T) || size > bytes_.size() - at_) {
      ok_ = false;
      return;
    }
    if (size == 0) return;  // an empty array: out may be null
    std::memcpy(out, bytes_.data() + at_, size);
    at_ += size;
    while (at_ % 4 != 0 && at_ < bytes_.size()) ++at_;
  }
  template <typename T>
  std::vector<T> vector(std::uint64_t count) {
    std::vector<T> out;
    if (!ok_ || count > bytes_.size() / sizeof(T)) {
      ok_ = false;
      return out;
    }
    out.resize(std::size_t(count));
    take(out.data(), out.size());
    return out;
  }
  bool at_end() const { return ok_ && at_ == bytes_.size(); }

 private:
  std::string bytes_;
  std::size_t at_ = 0;
  bool ok_ = true;
};

Expected<std::string> read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return input_error(path.string() + ": cannot read the shard's data");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

void put_mesh(std::string& out, const GltfMesh& m) {
  for (const auto* array : {&m.positions, &m.normals, &m.texcoord0, &m.texcoord1})
    put_u64(out, array->size());
  put_u64(out, m.indices.size());
  for (const auto* array : {&m.positions, &m.normals, &m.texcoord0, &m.texcoord1})
    put(out, array->data(), array->size());
  put(out, m.indices.data(), m.indices.size());
}

GltfMesh take_mesh(Unpacker& in) {
  std::uint64_t counts[5];
  for (auto& c : counts) c = in.u64();
  GltfMesh m;
  m.positions = in.vector<float>(counts[0]);
  m.normals = in.vector<float>(counts[1]);
  m.texcoord0 = in.vector<float>(counts[2]);
  m.texcoord1 = in.vector<float>(counts[3]);
  m.indices = in.vector<std::uint32_t>(counts[4]);
  return m;
}

Error damaged(const std::string& where, const std::string& what) {
  return input_error(where + ": damaged shard data: " + what + "; bake the shard again");
}

}  // namespace

std::string data_checksum(const std::string& bytes) {
  return fmt::format("{:016x}", XXH3_64bits(bytes.data(), bytes.size()));
}

std::string receiver_data_file(std::size_t object, std::optional<RowRange> tile) {
  return tile ? fmt::format("receiver_{}_rows_{}.bin", object, tile->begin)
              : fmt::format("receiver_{}.bin", object);
}

json receiver_metadata(const ReceiverBake& r) {
  json stats = json::array();
  for (const auto& [key, value] : r.report.stats) stats.push_back({key, value});
  json tallies = json::array();
  for (const auto& [key, value] : r.report.tallies) tallies.push_back({key, value});
  json out = {{"object", r.object},
              {"name", r.name},
              {"uv_channel", r.uv_channel},
              {"side", r.image.width},
              {"tile", r.tile ? json::array({r.tile->begin, r.tile->end}) : json()}};
  write_record(r, out);
  out.update(json{{"rays", r.rays},
                  {"uv_warnings", r.uv_warnings},
                  {"lights_reached", r.lights_reached},
                  {"method_stats", stats},
                  {"method_tallies", tallies},
                  {"method_entries", r.report.manifest},
                  {"explain", r.report.explain},
                  {"method_warnings", r.report.warnings},
                  {"per_light", r.per_light.size()},
                  {"per_light_visibility", r.per_light_visibility.size()},
                  {"gltf_mesh", bool(r.gltf_mesh)}});
  return out;
}

std::string receiver_data(const ReceiverBake& r) {
  std::string out;
  const std::uint32_t header[4] = {kReceiverMagic, kVersion, std::uint32_t(r.image.width),
                                   std::uint32_t(r.image.height)};
  put(out, header, 4);
  put(out, r.image.pixels.data(), r.image.pixels.size());
  put(out, r.covered.data(), r.covered.size());
  // Per-light images by their tiles: a count, the tiles, their values.
  for (const TiledImages* images : {&r.per_light, &r.per_light_visibility})
    for (std::size_t l = 0; l < images->size(); ++l) {
      put_u64(out, images->tiles(l).size());
      put(out, images->tiles(l).data(), images->tiles(l).size());
      const std::vector<float> values = images->values(l);
      put(out, values.data(), values.size());
    }
  if (r.gltf_mesh) put_mesh(out, *r.gltf_mesh);
  return out;
}

Expected<ReceiverBake> read_receiver(const json& meta, const std::filesystem::path& data,
                                     const std::string& where) {
  ReceiverBake r;
  std::size_t per_light = 0, visibility = 0;
  bool mesh = false;
  int side = 0;
  try {
    r.object = meta.at("object").get<std::size_t>();
    r.name = meta.at("name").get<std::string>();
    r.uv_channel = meta.at("uv_channel").get<int>();
    side = meta.at("side").get<int>();
    if (const json& tile = meta.at("tile"); !tile.is_null())
      r.tile = RowRange{tile.at(0).get<int>(), tile.at(1).get<int>()};
    r.rays = meta.at("rays").get<std::int64_t>();
    r.uv_warnings = meta.at("uv_warnings").get<std::vector<std::string>>();
    r.lights_reached = meta.at("lights_reached").get<std::vector<std::uint8_t>>();
    for (const json& stat : meta.at("method_stats"))
      r.report.stats.emplace_back(stat.at(0).get<std::string>(), stat.at(1).get<double>());
    for (const json& tally : meta.at("method_tallies"))
      r.report.tallies.emplace_back(tally.at(0).get<std::string>(),
                                    tally.at(1).get<std::int64_t>());
    r.report.manifest = meta.at("method_entries");
    r.report.explain = meta.at("explain").get<std::string>();
    r.report.warnings = meta.at("method_warnings").get<std::vector<std::string>>();
    per_light = meta.at("per_light").get<std::size_t>();
    visibility = meta.at("per_light_visibility").get<std::size_t>();
    mesh = meta.at("gltf_mesh").get<bool>();
  } catch (const json::exception& e) {
    return damaged(where, std::string("a receiver's entry: ") + e.what());
  }
  Status fields_read = Ok{};
  FieldReader fields(meta, where, "", fields_read, "the shard's data");
  read_record(fields, meta, r);
  if (!fields_read) return input_error(fields_read.error().message + "; bake the shard again");
  if (side <= 0 || std::uint64_t(side) > kMaxSide || per_light > 4096 || visibility > 4096 ||
      (r.tile && (r.tile->begin < 0 || r.tile->end <= r.tile->begin || r.tile->end > side)))
    return damaged(where, "receiver '" + r.name + "' has impossible sizes");
  // A tile's images hold its rows alone.
  const int rows = r.tile ? r.tile->end - r.tile->begin : side;
  auto bytes = read_bytes(data);
  if (!bytes) return bytes.error();
  if (data_checksum(*bytes) != meta.value("checksum", ""))
    return damaged(data.string(), "its checksum is not the one " + where + " gives");
  Unpacker in(std::move(*bytes));
  const std::uint32_t magic = in.u32(), version = in.u32(), width = in.u32(), height = in.u32();
  if (magic != kReceiverMagic || version != kVersion || int(width) != side || int(height) != rows)
    return damaged(data.string(), "not receiver '" + r.name + "'s data");
  const std::size_t texels = std::size_t(side) * std::size_t(rows);
  r.image = Image(side, rows, 3);
  in.take(r.image.pixels.data(), r.image.pixels.size());
  r.covered.resize(texels);
  in.take(r.covered.data(), r.covered.size());
  r.per_light = per_light_values(per_light, side, rows);
  r.per_light_visibility = per_light_visibilities(visibility, side, rows);
  for (TiledImages* images : {&r.per_light, &r.per_light_visibility})
    for (std::size_t l = 0; l < images->size(); ++l) {
      std::vector<std::uint32_t> tiles = in.vector<std::uint32_t>(in.u64());
      const std::size_t values = tiles.size() * std::size_t(TiledImages::kSide) *
                                 std::size_t(TiledImages::kSide) * std::size_t(images->channels());
      if (!images->restore(l, std::move(tiles), in.vector<float>(values)))
        return damaged(data.string(), "receiver '" + r.name + "'s per-light images are damaged");
    }
  if (mesh) r.gltf_mesh = std::make_shared<const GltfMesh>(take_mesh(in));
  if (!in.at_end()) return damaged(data.string(), "its size does not match its header");
  return r;
}

std::string gltf_mesh_data(const GltfMesh& mesh) {
  std::string out;
  const std::uint32_t header[2] = {kMeshMagic, kVersion};
  put(out, header, 2);
  put_mesh(out, mesh);
  return out;
}

Expected<GltfMesh> read_gltf_mesh(const std::filesystem::path& data, const std::string& checksum) {
  auto bytes = read_bytes(data);
  if (!bytes) return bytes.error();
  if (data_checksum(*bytes) != checksum)
    return damaged(data.string(), "its checksum is not the one shard.json gives");
  Unpacker in(std::move(*bytes));
  if (in.u32() != kMeshMagic || in.u32() != kVersion)
    return damaged(data.string(), "not a glTF mesh");
  GltfMesh mesh = take_mesh(in);
  if (!in.at_end()) return damaged(data.string(), "its size does not match its header");
  return mesh;
}

}  // namespace sb
