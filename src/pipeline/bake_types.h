// The data a bake takes and gives (pipeline/bake.h runs it): what part of a scene it does
// (ShardSpec), its options, and per receiver what it baked (ReceiverBake), which the outputs,
// the shard files and the cache write.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/image.h"
#include "core/tiled_images.h"
#include "formats/receiver_record.h"
#include "lightmaps/gltf_export.h"
#include "methods/method.h"
#include "texels/atlas_packing.h"
#include "texels/seams.h"
#include "texels/texel_space.h"
#include "texels/uv_checks.h"

namespace sb {

// Which part of a scene's receivers a bake does (docs/distributed.md): receivers are dealt to
// `count` shards by their estimated cost, and this bake does shard `index` (0 ≤ index < count).
enum class ShardBalance {
  cost,  // longest first onto the least loaded shard (LPT); cost ~ the (texel, light) pairs
  count  // round robin in scene order, for comparison
};
struct ShardSpec {
  int index = 0, count = 1;
  ShardBalance balance = ShardBalance::cost;
  // Whether a receiver that costs more than a shard's share may be split into tiles of rows
  // (pipeline/tiles.h), for a method that allows it (MethodEntry::tile_halo).
  bool tiles = true;
};

// A receiver's key for incremental bakes (pipeline/bake_cache.h): four hashes, 32 hex digits each.
struct ReceiverKey {
  std::string settings, receiver, lights, blockers;
  bool operator==(const ReceiverKey&) const = default;
};

struct BakeOptions {
  int threads = 0;  // 0: all cores
  // Called from worker threads with the fraction of the bake done, in [0, 1]; may be empty.
  ProgressFn progress;
  // Per-light images to keep beyond what the scene's [output] asks for (per_light: values,
  // shadowmask: visibility).
  KeepPerLight keep_per_light;
  // Bake only this shard's receivers, and leave what needs every receiver (shadow-mask channels,
  // the warnings about lights that reach nothing) to the merge (pipeline/shards.h).
  std::optional<ShardSpec> shard;
  // Incremental bakes (pipeline/bake_cache.h): compute each receiver's key (for the cache the
  // bake's outputs keep), and take a receiver from the cache of `reuse_from` (an output folder;
  // empty: none) where its key is unchanged, unless `force`. A receiver `only` names is always
  // baked; when `only` is not empty, the others are taken from the cache when there, changed or
  // not (said in the manifest), and baked when not. A receiver one of the `relight` lights may
  // reach is baked too.
  bool keys = false;
  std::filesystem::path reuse_from;
  bool force = false;
  std::vector<std::string> only;
  // Scene lights whose receivers are baked whatever their keys say (those each may reach); as
  // with `only`, the others are then taken from the cache when there, changed or not.
  std::vector<std::string> relight;
};

// A receiver's bake: its record (what every file that keeps it says) and its images.
struct ReceiverBake : ReceiverRecord {
  std::size_t object = 0;  // its index among the scene's objects
  std::string name;
  int uv_channel = 0;
  // A tile's bake (pipeline/tiles.h): its rows of the side × side lightmap, which its images and
  // coverage hold alone, undilated; its layout, seams, reached lights and glTF mesh are left to
  // the join. None: the whole receiver.
  std::optional<RowRange> tile;
  Image image;  // RGB, the receiver's side² (resolution, or its texels_per_metre size), dilated
  std::vector<std::uint8_t> covered;  // width × height: 1 where a triangle covers the texel
  double seconds = 0;                 // texel space + method + dilation + seams, this receiver only
  double seconds_texels = 0, seconds_method = 0, seconds_dilate = 0, seconds_seams = 0;
  // Per light, in scene order, when kept: its own V (or H0·V), dilated like the image; and what
  // its shadow mask needs (MixedImages::per_light_visibility, its influence cleared beyond its
  // shadowmask_range), dilated too. Kept by tiles (TiledImages): each holds what its light
  // reaches, with the dilation and stitching around it.
  TiledImages per_light;
  TiledImages per_light_visibility;
  // The receiver's mesh as a glTF carries it, when [output] gltf.
  std::shared_ptr<const GltfMesh> gltf_mesh;
  // What the method reports beyond its values: named figures, its own manifest entries, what
  // --explain prints and its warnings (gathered into BakeResult::warnings by finish_bake).
  MethodReport report;
  std::int64_t rays = 0;                     // shadow rays the method traced for it
  std::vector<std::string> uv_warnings;      // its UV layout's (and a black lightmap's) warnings
  std::vector<std::uint8_t> lights_reached;  // per light: 1 where it reaches a texel of it
  // Incremental bakes (BakeOptions::keys): its key; whether it was taken from the cache
  // ("reused") or baked ("baked"; empty without keys), and why.
  ReceiverKey key;
  std::string reuse, reuse_why;
};

struct BakeResult {
  std::vector<ReceiverBake> receivers;  // in scene order (a shard's: its own)
  // Every warning, in the order they arise: the setup's (settings a method ignores, meshes,
  // lightmap sizes), each receiver's UV layout, lights that reach no receiver, each receiver's
  // method, shadow-mask channels (finish_bake).
  std::vector<std::string> warnings;
  std::vector<std::string> setup_warnings;  // the first part, the same for every shard
  // The receivers' places in atlases ([output] atlas), placements in receiver order.
  std::optional<AtlasLayout> atlas;
  // With [output] shadowmask, each light's channel (lightmaps/shadowmask.h); the lights left
  // out are warnings.
  std::vector<int> shadowmask_channels;
  // With [output] gltf, the objects that are blockers only, in scene order, as a glTF shows them.
  std::vector<std::pair<std::string, std::shared_ptr<const GltfMesh>>> gltf_blockers;
  double load_seconds = 0;       // mesh import and acceleration structures
  double bake_seconds = 0;       // all receivers: texel space, method, dilation, seams
  std::int64_t shadow_rays = 0;  // rays traced, for sampling methods
};

}  // namespace sb
