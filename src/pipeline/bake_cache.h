// Incremental bakes (docs/cli.md, "Incremental bakes"): every bake keeps each receiver's raw
// result in its output folder's cache (kCacheFolder: the receiver's metadata and key as JSON, its
// arrays as the shards' binary file, formats/shard_files.h), and a later bake into that folder
// takes a receiver from there instead of baking it when its key is unchanged.
//
// A receiver's key is four hashes (XXH3-128) of what can change its result:
//   settings  — the shadowbake version, the settings that change what a bake writes
//               (settings_json.h), the per-light images kept and the number of scene lights;
//   receiver  — its name (its sampling stream's key), lightmap side and UV channel, and
//               its mesh as baked (world-space positions, normals, both UV sets, triangles);
//   lights    — each light that may reach it (one-sided planar lights whose plane the receiver's
//               box lies wholly behind cannot), in scene order: its index, every field of its
//               placed description, and its texture's bytes;
//   blockers  — each blocker that may lie in a shaft from the receiver to one of those lights
//               (ShaftCuller::tile_candidates with the receiver's whole box as the tile), or
//               within ao_distance of it for ambient occlusion, in scene order: its name and mesh.
// Blockers and lights keep their relative order when others are added or removed, and a
// method whose registry entry is marked local (MethodEntry::local) reads nothing of the scene
// beyond them, so a reused result is byte for byte what baking again would give; for the other
// methods (their shadow maps and clusters are fitted to the whole scene) every blocker counts.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "formats/output_folder.h"
#include "pipeline/bake_types.h"
#include "scene/lights.h"
#include "scene/mesh.h"

namespace sb {

class ShaftCuller;

// The cache's folder inside an output folder.
inline constexpr const char* kCacheFolder = ".shadowbake-cache";

// What the keys are computed from; `culler` holds `blockers` (may be null for ambient
// occlusion or a method that is not local).
struct KeyInputs {
  const Scene* scene = nullptr;
  bool local = false;                         // the method's MethodEntry::local
  const std::vector<Mesh>* meshes = nullptr;  // per object
  const std::vector<Light>* lights = nullptr;
  const std::vector<const Mesh*>* blockers = nullptr;
  const ShaftCuller* culler = nullptr;
  KeepPerLight keep_per_light;
};

// The keys of the receivers `objects` (object indices) at lightmap sides `sides`, and, when
// `reaching` is given, per receiver the scene lights (Light::output) that may reach it. Errors
// name an unreadable light texture.
Expected<std::vector<ReceiverKey>> receiver_keys(const KeyInputs& in,
                                                 const std::vector<std::size_t>& objects,
                                                 const std::vector<int>& sides,
                                                 std::vector<std::vector<int>>* reaching = nullptr);

// Which parts of the key differ ("its settings", "its mesh", "the lights that reach it", "the
// blockers in its shafts", joined by ", "); empty when none does.
std::string key_change(const ReceiverKey& before, const ReceiverKey& now);

// An earlier bake's entry for the receiver called `name` in `output_dir`: its key, and a way to
// read its result. Nothing when there is none or it cannot be read.
struct CachedReceiver {
  ReceiverKey key;
  std::filesystem::path metadata, data;
};
std::optional<CachedReceiver> find_cached(const std::filesystem::path& output_dir,
                                          const std::string& name);
// The result it holds; errors (damaged data) name the file.
Expected<ReceiverBake> read_cached(const CachedReceiver& entry);

// Per receiver (`receivers`, object indices, with their `keys` and the scene lights `reaching`
// each): its result when options.reuse_from's cache gives it (its key unchanged; or, with
// options.only or options.relight, any entry it has unless it is named or lit), and why it is
// taken or baked, as the manifest says it. Errors: a name in options.only that is no receiver's,
// one in options.relight that is no light's.
struct ReuseDecision {
  std::optional<ReceiverBake> reused;
  std::string why;
};
Expected<std::vector<ReuseDecision>> decide_reuse(const Scene& scene,
                                                  const std::vector<std::size_t>& receivers,
                                                  const std::vector<ReceiverKey>& keys,
                                                  const std::vector<std::vector<int>>& reaching,
                                                  const BakeOptions& options);

// Stages the receivers of `result` that were baked into `folder`'s cache (a reused one's entry
// is already there, unchanged); the names (relative to the folder) to publish with the bake's
// other files.
Expected<std::vector<std::string>> stage_cache(OutputFolder& folder, const BakeResult& result);

// After publishing: removes the cache's files of receivers `result` does not hold (no longer in
// the scene). Failures are ignored: a stale entry is never read for a receiver of another key.
void prune_cache(const std::filesystem::path& output_dir, const BakeResult& result);

}  // namespace sb
