// Shards and their merge (shards.h).
#include "pipeline/shards.h"

#include <fmt/format.h>
#include <xxhash.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include "formats/settings_json.h"
#include "formats/shard_files.h"
#include "pipeline/bake_stages.h"
#include "pipeline/tiles.h"
#include "texels/atlas_packing.h"

namespace sb {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

namespace {

constexpr const char* kBlockerMeshPrefix = "blocker_";

// Feeds a file's bytes to the hash, a megabyte at a time.
Status hash_file(XXH3_state_t* state, const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return input_error(path.string() + ": cannot read it to hash the scene");
  std::vector<char> buffer(std::size_t(1) << 20);
  while (in) {
    in.read(buffer.data(), std::streamsize(buffer.size()));
    XXH3_128bits_update(state, buffer.data(), std::size_t(in.gcount()));
  }
  if (in.bad()) return input_error(path.string() + ": cannot read it to hash the scene");
  return Ok{};
}

void hash_text(XXH3_state_t* state, const std::string& text) {
  // Length first, so that "ab" + "c" and "a" + "bc" differ.
  const std::uint64_t size = text.size();
  XXH3_128bits_update(state, &size, sizeof size);
  XXH3_128bits_update(state, text.data(), text.size());
}

Expected<json> read_json(const fs::path& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return input_error(path.string() + ": cannot read " + what);
  std::stringstream text;
  text << in.rdbuf();
  json parsed = json::parse(text.str(), nullptr, /*allow_exceptions=*/false);
  if (parsed.is_discarded()) return input_error(path.string() + ": not valid JSON (" + what + ")");
  return parsed;
}

const char* to_string(ShardBalance b) { return b == ShardBalance::cost ? "cost" : "count"; }

// One shard folder as read.
struct ShardRead {
  fs::path folder;
  json description;
  int index = 0, count = 0;
};

}  // namespace

Expected<std::string> scene_content_hash(const Scene& scene) {
  std::unique_ptr<XXH3_state_t, decltype(&XXH3_freeState)> state(XXH3_createState(),
                                                                 &XXH3_freeState);
  XXH3_128bits_reset(state.get());
  hash_text(state.get(), std::string("shadowbake ") + SHADOWBAKE_VERSION);
  if (Status s = hash_file(state.get(), scene.file); !s) return s.error();
  std::set<fs::path> hashed = {scene.file};  // a level's file once, not once per node
  for (const ObjectDesc& obj : scene.objects) {
    hash_text(state.get(), obj.name);
    if (hashed.insert(obj.mesh).second)
      if (Status s = hash_file(state.get(), obj.mesh); !s) return s.error();
  }
  for (const LightDesc& light : scene.lights) {
    hash_text(state.get(), light.name);
    if (!light.texture.empty())
      if (Status s = hash_file(state.get(), light.texture); !s) return s.error();
  }
  hash_text(state.get(), settings_to_json(scene.bake, scene.output).dump());
  XXH128_canonical_t canonical;
  XXH128_canonicalFromHash(&canonical, XXH3_128bits_digest(state.get()));
  std::string hex;
  for (const unsigned char byte : canonical.digest) hex += fmt::format("{:02x}", byte);
  return hex;
}

Expected<ShardSpec> parse_shard(const std::string& text) {
  const auto fail = [&](const std::string& why) {
    return scene_error("--shard " + text + ": " + why);
  };
  const auto slash = text.find('/');
  if (slash == std::string::npos) return fail("must be K/N (0 <= K < N) or auto/N");
  const auto number = [](std::string_view digits, int& out) {
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), out);
    return ec == std::errc() && end == digits.data() + digits.size() && !digits.empty();
  };
  ShardSpec spec;
  if (!number(std::string_view(text).substr(slash + 1), spec.count) || spec.count < 1 ||
      spec.count > 4096)
    return fail("N must be a whole number from 1 to 4096");
  const std::string k = text.substr(0, slash);
  if (k == "auto") {
    const char* from = nullptr;
    const char* value = nullptr;
    for (const char* variable : {"SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"}) {
      if ((value = std::getenv(variable))) {
        from = variable;
        break;
      }
    }
    if (!from)
      return fail(
          "auto takes K from SLURM_ARRAY_TASK_ID or JOB_COMPLETION_INDEX, and neither is set");
    if (!number(value, spec.index) || spec.index < 0 || spec.index >= spec.count)
      return fail(fmt::format("{} is '{}', not a shard from 0 to {}", from, value, spec.count - 1));
    return spec;
  }
  if (!number(k, spec.index) || spec.index < 0 || spec.index >= spec.count)
    return fail(fmt::format("K must be a whole number from 0 to {}", spec.count - 1));
  return spec;
}

std::vector<std::string> shard_output_names(const BakeResult& result) {
  std::vector<std::string> names;
  for (const ReceiverBake& r : result.receivers)
    names.push_back(receiver_data_file(r.object, r.tile));
  for (std::size_t b = 0; b < result.gltf_blockers.size(); ++b)
    names.push_back(fmt::format("{}{}.bin", kBlockerMeshPrefix, b));
  names.push_back(kShardTimingsFile);
  names.push_back(kShardFile);
  return names;
}

Status write_shard(OutputFolder& folder, const Scene& scene, const ShardSpec& spec,
                   const BakeResult& result) {
  auto hash = scene_content_hash(scene);
  if (!hash) return hash.error();
  const std::vector<std::string> names = shard_output_names(result);
  if (Status s = folder.check_targets(names); !s) return s;
  std::error_code ec;
  json description = {{"shadowbake_shard", SHADOWBAKE_VERSION},
                      {"hash", *hash},
                      {"scene", scene.file.string()},
                      {"scene_path", fs::absolute(scene.file, ec).lexically_normal().string()},
                      {"shard",
                       {{"index", spec.index},
                        {"count", spec.count},
                        {"balance", to_string(spec.balance)},
                        {"tiles", spec.tiles}}},
                      {"settings", settings_to_json(scene.bake, scene.output)},
                      {"setup_warnings", result.setup_warnings},
                      {"receivers", json::array()},
                      {"gltf_blockers", json::array()}};
  json timings = {{"load_seconds", result.load_seconds},
                  {"bake_seconds", result.bake_seconds},
                  {"receivers", json::object()}};
  for (const ReceiverBake& r : result.receivers) {
    const std::string data = receiver_data(r);
    json metadata = receiver_metadata(r);
    metadata["checksum"] = data_checksum(data);
    description["receivers"].push_back(std::move(metadata));
    timings["receivers"][receiver_data_file(r.object, r.tile)] = {{"seconds", r.seconds},
                                                                  {"texels", r.seconds_texels},
                                                                  {"method", r.seconds_method},
                                                                  {"dilate", r.seconds_dilate},
                                                                  {"seams", r.seconds_seams}};
    if (Status s = write_text_file(folder.staged(receiver_data_file(r.object, r.tile)), data); !s)
      return s;
  }
  for (std::size_t b = 0; b < result.gltf_blockers.size(); ++b) {
    const std::string file = fmt::format("{}{}.bin", kBlockerMeshPrefix, b);
    const std::string data = gltf_mesh_data(*result.gltf_blockers[b].second);
    description["gltf_blockers"].push_back({{"name", result.gltf_blockers[b].first},
                                            {"file", file},
                                            {"checksum", data_checksum(data)}});
    if (Status s = write_text_file(folder.staged(file), data); !s) return s;
  }
  if (Status s = write_text_file(folder.staged(kShardTimingsFile), timings.dump(2) + "\n"); !s)
    return s;
  if (Status s = write_text_file(folder.staged(kShardFile), description.dump(2) + "\n"); !s)
    return s;
  return folder.publish(names);
}

namespace {

using ReceiversByObject = std::map<std::size_t, ReceiverBake>;
using TilesByObject = std::map<std::size_t, std::vector<ReceiverBake>>;

// Reads each folder's shard description, with the shard's index and the split's count.
Expected<std::vector<ShardRead>> read_shards(const std::vector<fs::path>& folders) {
  std::vector<ShardRead> shards;
  for (const fs::path& folder : folders) {
    const fs::path file = folder / kShardFile;
    std::error_code ec;
    if (!fs::is_regular_file(file, ec))
      return input_error(folder.string() + ": not a shadowbake shard (no " + kShardFile + ")");
    auto description = read_json(file, "the shard's description");
    if (!description) return description.error();
    ShardRead s{folder, std::move(*description), 0, 0};
    try {
      s.index = s.description.at("shard").at("index").get<int>();
      s.count = s.description.at("shard").at("count").get<int>();
      s.description.at("hash").get<std::string>();
    } catch (const json::exception&) {
      return input_error(file.string() + ": not a shadowbake shard description");
    }
    shards.push_back(std::move(s));
  }
  return shards;
}

// Checks that every shard comes from the first one's version, scene, settings and split.
Status check_shards_match(const std::vector<ShardRead>& shards) {
  // One scene, one set of settings, one split, each shard once.
  const ShardRead& first = shards[0];
  const auto same = [&](const ShardRead& s, const char* key) {
    return s.description.value(key, json()) == first.description.value(key, json());
  };
  const auto same_split = [&](const ShardRead& s) {
    return s.count == first.count &&
           s.description["shard"].value("balance", "") ==
               first.description["shard"].value("balance", "") &&
           s.description["shard"].value("tiles", true) ==
               first.description["shard"].value("tiles", true);
  };
  for (const ShardRead& s : shards) {
    const char* what = !same(s, "shadowbake_shard") ? "another shadowbake version"
                       : !same(s, "hash")           ? "another scene, meshes or settings"
                       : !same_split(s) ? "another split (shard count, balance or tiles)"
                                        : nullptr;
    if (what)
      return input_error(fmt::format("{}: a shard of {} than {} (scene hash {} against {})",
                                     s.folder.string(), what, first.folder.string(),
                                     s.description.value("hash", "?"),
                                     first.description.value("hash", "?")));
  }
  return Ok{};
}

// Orders the shards by index, checking that each shard of the split is given exactly once;
// `folder_count` is how many folders were given, for the message on a missing shard.
Expected<std::vector<const ShardRead*>> shards_by_index(const std::vector<ShardRead>& shards,
                                                        std::size_t folder_count) {
  const int count = shards[0].count;
  std::vector<const ShardRead*> by_index(std::size_t(std::max(count, 0)), nullptr);
  for (const ShardRead& s : shards) {
    if (s.index < 0 || s.index >= count)
      return input_error(fmt::format("{}: shard {}/{} is not a shard of {}", s.folder.string(),
                                     s.index, count, count));
    const ShardRead*& slot = by_index[std::size_t(s.index)];
    if (slot)
      return input_error(fmt::format("shard {}/{} given twice: {} and {}", s.index, count,
                                     slot->folder.string(), s.folder.string()));
    slot = &s;
  }
  for (int k = 0; k < count; ++k)
    if (!by_index[std::size_t(k)])
      return input_error(
          fmt::format("shard {}/{} is missing: none of the {} folder(s) given holds "
                      "it (bake it with --shard {}/{})",
                      k, count, folder_count, k, count));
  return by_index;
}

// Loads the scene from `path` with the shards' settings, naming it `as_given` as the shards did,
// and checks that its content still hashes to the shards' hash.
Status load_baked_scene(const ShardRead& first, const std::string& path,
                        const std::string& as_given, MergedBake& merged) {
  const json& d = first.description;
  auto scene = load_scene(path);
  if (!scene) return scene.error();
  merged.scene = std::move(*scene);
  merged.scene.file = as_given;
  if (Status s = settings_from_json(d.at("settings"), (first.folder / kShardFile).string(),
                                    merged.scene.bake, merged.scene.output);
      !s)
    return s.error();
  {
    Scene hashed = merged.scene;
    hashed.file = path;
    auto hash = scene_content_hash(hashed);
    if (!hash) return hash.error();
    if (*hash != d.value("hash", ""))
      return input_error(
          fmt::format("{}: the scene, a mesh or a texture changed since the shards "
                      "were baked (content hash {} against the shards' {}); bake "
                      "the shards again",
                      path, *hash, d.value("hash", "")));
  }
  return Ok{};
}

// Reads one shard's receivers with their timings into `receivers`, or into `tiled` for those
// baked in tiles, and adds the shard's load and bake times to `result`.
Status read_shard_receivers(const ShardRead& shard, const Scene& scene, BakeResult& result,
                            ReceiversByObject& receivers, TilesByObject& tiled) {
  const std::string where = (shard.folder / kShardFile).string();
  // Timings are not checked: a shard's time is what it is, and the merged manifest sums them.
  const auto timings = read_json(shard.folder / kShardTimingsFile, "the shard's timings");
  if (timings) {
    result.load_seconds = std::max(result.load_seconds, timings->value("load_seconds", 0.0));
    result.bake_seconds += timings->value("bake_seconds", 0.0);
  }
  for (const json& meta : shard.description.at("receivers")) {
    std::optional<RowRange> tile;
    if (const json rows = meta.value("tile", json());
        rows.is_array() && rows.size() == 2 && rows[0].is_number_integer())
      tile = RowRange{rows[0].get<int>(), rows[1].get<int>()};
    const std::string file = receiver_data_file(meta.value("object", 0), tile);
    auto r = read_receiver(meta, shard.folder / file, where);
    if (!r) return r.error();
    if (timings && timings->contains("receivers") && (*timings)["receivers"].contains(file)) {
      const json& t = (*timings)["receivers"][file];
      r->seconds = t.value("seconds", 0.0);
      r->seconds_texels = t.value("texels", 0.0);
      r->seconds_method = t.value("method", 0.0);
      r->seconds_dilate = t.value("dilate", 0.0);
      r->seconds_seams = t.value("seams", 0.0);
    }
    const std::size_t object = r->object;
    if (object >= scene.objects.size() || !scene.objects[object].receiver ||
        scene.objects[object].name != r->name)
      return input_error(where + ": receiver '" + r->name + "' is not in the scene");
    if (r->tile) {
      tiled[object].push_back(std::move(*r));
    } else if (!receivers.emplace(object, std::move(*r)).second) {
      return input_error(where + ": receiver '" + r->name + "' is in two shards");
    }
  }
  return Ok{};
}

// Joins each tiled receiver's tiles into one receiver and adds it to `receivers`; the scene is
// read from `path` but its warnings name it `as_given`, as the shards did.
Status join_tiled_receivers(const Scene& scene, const std::string& path,
                            const std::string& as_given, TilesByObject& tiled,
                            ReceiversByObject& receivers) {
  std::vector<std::vector<ReceiverBake>> lists;
  for (auto& [object, tiles] : tiled) {
    if (receivers.count(object))
      return input_error(fmt::format("receiver '{}' is both whole and in tiles in the shards",
                                     tiles.front().name));
    lists.push_back(std::move(tiles));
  }
  Scene as_read = scene;
  as_read.file = path;  // where its meshes lie
  auto joined = join_tiles(as_read, std::move(lists), "merge");
  if (!joined) return joined.error();
  for (ReceiverBake& r : *joined) {
    // Its warnings name the scene as the shards did.
    for (std::string& w : r.uv_warnings)
      if (w.rfind(path, 0) == 0) w = as_given + w.substr(path.size());
    const std::size_t object = r.object;
    receivers.emplace(object, std::move(r));
  }
  return Ok{};
}

// Reads the glTF blocker meshes that the first shard wrote.
Status read_gltf_blockers(const ShardRead& first, BakeResult& result) {
  for (const json& blocker : first.description.at("gltf_blockers")) {
    auto mesh =
        read_gltf_mesh(first.folder / blocker.value("file", ""), blocker.value("checksum", ""));
    if (!mesh) return mesh.error();
    result.gltf_blockers.emplace_back(blocker.value("name", ""),
                                      std::make_shared<const GltfMesh>(std::move(*mesh)));
  }
  return Ok{};
}

}  // namespace

Expected<MergedBake> merge_shards(const std::vector<fs::path>& folders,
                                  const fs::path& scene_file) {
  if (folders.empty()) return scene_error("merge: no shard folders given");
  auto shards = read_shards(folders);
  if (!shards) return shards.error();
  if (Status s = check_shards_match(*shards); !s) return s.error();
  auto by_index = shards_by_index(*shards, folders.size());
  if (!by_index) return by_index.error();

  // The scene, as the shards baked it.
  const ShardRead& first = *(*by_index)[0];
  const json& d = first.description;
  MergedBake merged;
  const std::string as_given = d.value("scene", "");
  const std::string path = scene_file.empty() ? d.value("scene_path", "") : scene_file.string();
  if (Status s = load_baked_scene(first, path, as_given, merged); !s) return s.error();

  // Every receiver once, in scene order; a receiver baked in tiles once its tiles are joined.
  BakeResult& result = merged.result;
  ReceiversByObject receivers;
  TilesByObject tiled;
  for (const ShardRead* s : *by_index)
    if (Status status = read_shard_receivers(*s, merged.scene, result, receivers, tiled); !status)
      return status.error();
  if (Status s = join_tiled_receivers(merged.scene, path, as_given, tiled, receivers); !s)
    return s.error();
  for (std::size_t i = 0; i < merged.scene.objects.size(); ++i) {
    const ObjectDesc& obj = merged.scene.objects[i];
    if (obj.receiver && !receivers.count(i))
      return input_error(fmt::format("no shard holds receiver '{}' (line {} of {})", obj.name,
                                     obj.line, as_given));
  }
  std::vector<int> sides;
  for (auto& [object, r] : receivers) {
    result.shadow_rays += r.rays;
    sides.push_back(r.image.width);
    result.receivers.push_back(std::move(r));
  }
  result.setup_warnings = d.at("setup_warnings").get<std::vector<std::string>>();
  if (Status s = read_gltf_blockers(first, result); !s) return s.error();
  if (merged.scene.output.atlas) result.atlas = pack_atlases(sides, *merged.scene.output.atlas);
  finish_bake(merged.scene, result, true);
  return merged;
}

}  // namespace sb
