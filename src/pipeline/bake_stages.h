// The stages bake() runs, in order, each in its own file; what one hands the next is a struct
// here. A stage's errors name the scene file and the item (core/error.h).
//
//   check_request     bake_request.cpp   the method, and settings that cannot go together
//   load_scene_for    bake_load.cpp      meshes, lightmap sides, lights, this bake's receivers
//                                        (a shard's and its tiles), the memory budget, what the
//                                        method needs built (rays, clusters, shafts)
//   reuse_from_cache  bake_cache.cpp     each receiver's key, and those an earlier bake holds
//   build_texels      texel_stage.cpp    texel space per receiver, its UV layout and warnings
//   bake_receivers    method_stage.cpp   the method on each receiver, then dilation and seams
//   finish_bake       finish_bake.cpp    what needs every receiver (shadow-mask channels,
//                                        warnings)
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "methods/method.h"
#include "occluders/clusters.h"
#include "occluders/ray_scene.h"
#include "occluders/shaft_culling.h"
#include "pipeline/bake_types.h"
#include "pipeline/memory_budget.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "scene/scene.h"
#include "texels/texel_space.h"
#include "texels/uv_checks.h"

namespace sb {

// The scene's method entry, once the settings are checked to go together (the quantity with
// the method, outputs of lights with an ambient-occlusion bake, lights where they are needed);
// [bake] keys the method does not read become warnings in `warnings`.
Expected<const MethodEntry*> check_request(const Scene& scene, std::vector<std::string>* warnings);

// The scene as this bake reads it, and what it bakes.
struct LoadedScene {
  std::vector<Mesh> meshes;  // per object
  std::vector<Light> lights;
  std::vector<const Mesh*> blockers;
  // This bake's receivers (every receiver, or a shard's receivers and tiles): object index,
  // lightmap side and, for a tile, its rows.
  std::vector<std::size_t> receivers;
  std::vector<int> sides;
  std::vector<std::optional<RowRange>> tiles;
  std::vector<MemoryItem> estimate;  // the memory the bake was checked to fit
  // What the method asked for (MethodEntry::needs), built once for every receiver.
  std::optional<RayScene> rays;
  std::optional<ClusterTree> clusters;
  std::optional<ShaftCuller> shafts;
};

// Loads the meshes and lights into `loaded` (where they stay: what it builds points into
// them), deals a shard its receivers, checks the memory budget and builds what the method
// needs. Puts the atlas layout and the glTF's blockers into `result`, and the meshes' and
// lightmap sizes' warnings into result->setup_warnings.
Status load_scene_for(const Scene& scene, const MethodEntry& method, const BakeOptions& options,
                      LoadedScene* loaded, BakeResult* result);

// Per receiver of the bake: its key, and its result where an earlier bake's cache holds it
// unchanged (or --only leaves it as it was), with why it was or was not reused.
struct Reuse {
  std::vector<ReceiverKey> keys;
  std::vector<std::optional<ReceiverBake>> reused;
  std::vector<std::string> why;
};

// Nothing reused and no keys unless options.keys.
Expected<Reuse> reuse_from_cache(const Scene& scene, const MethodEntry& method,
                                 const LoadedScene& loaded, const BakeOptions& options);

// Per receiver of the bake: its texel space (empty where reused), and what the layout checks
// found.
struct Texels {
  std::vector<TexelSpace> spaces;
  std::vector<double> seconds;  // rasterising each
  std::vector<UvLayoutReport> layouts;
  std::vector<std::vector<std::string>> warnings;  // its UV layout's
  std::vector<std::vector<std::uint8_t>> reached;  // per light: 1 where it reaches a texel
  // Per receiver baked here, which lights may reach each block of its texels (empty where
  // reused).
  std::vector<std::optional<LightLists>> lists;
  std::int64_t total = 0;  // covered texels, reused ones too
};

Expected<Texels> build_texels(const Scene& scene, const MethodEntry& method,
                              const LoadedScene& loaded, const Reuse& reuse);

// The method on each receiver not reused, in order, then what follows it (dilation, seams; a
// tile's crop); the reused ones as the cache held them. Appends to result->receivers and adds
// the rays to result->shadow_rays. Frees each receiver's texel space once it is baked.
Status bake_receivers(const Scene& scene, const MethodEntry& method, const LoadedScene& loaded,
                      Reuse reuse, Texels texels, const BakeOptions& options, BakeResult* result);

// What needs every receiver: the shadow-mask channels and the warnings list, from the
// receivers' own parts. A bake does it itself; the merge of shards does it on their receivers.
// `whole`: false for a shard alone, whose warnings leave out what only all receivers tell.
void finish_bake(const Scene& scene, BakeResult& result, bool whole = true);

}  // namespace sb
