// Bakes split into shards and merged back (docs/distributed.md). A shard bakes a deterministic
// part of a scene's receivers (BakeOptions::shard) and writes their raw results — every image as
// float, the coverage, the method's figures, warnings and glTF meshes — with shard.json, which
// names the scene, its content hash and the settings. `merge` checks that the shards are of one
// scene and settings, that none is missing or given twice, and writes from their receivers
// exactly the files one bake of the whole scene writes (write_outputs on the same data).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"
#include "formats/output_folder.h"
#include "pipeline/bake_types.h"
#include "scene/scene.h"

namespace sb {

// A shard's description file, and the file of timings (the one file a rerun changes).
inline constexpr const char* kShardFile = "shard.json";
inline constexpr const char* kShardTimingsFile = "timings.json";

// The scene's content hash, 32 hex digits (XXH3-128, libxxhash): of the shadowbake version, the
// scene file's bytes, every mesh's and light texture's bytes, and the settings that change what a
// bake writes (settings_json.h). Errors name an unreadable file.
Expected<std::string> scene_content_hash(const Scene& scene);

// Parses "K/N" (0 ≤ K < N ≤ 4096) or "auto/N", taking K from SLURM_ARRAY_TASK_ID or
// JOB_COMPLETION_INDEX (Kubernetes Indexed Jobs) for "auto"; an error says what is wrong.
Expected<ShardSpec> parse_shard(const std::string& text);

// The files a shard's bake writes (timings last but for shard.json).
std::vector<std::string> shard_output_names(const BakeResult& result);

// Writes shard `spec`'s bake of `scene` into `folder` and publishes it. The same inputs give the
// same bytes in every file but timings.json.
Status write_shard(OutputFolder& folder, const Scene& scene, const ShardSpec& spec,
                   const BakeResult& result);

// A merged bake: the scene as the shards baked it (settings included) and the whole result,
// ready for write_outputs.
struct MergedBake {
  Scene scene;
  BakeResult result;
};

// Reads the shard folders and merges them. The scene is read from where the shards read it, or
// from `scene_file` when given (the merge runs where the scene lies elsewhere); its content hash
// must be the shards'. Errors (one line, naming the folder): a folder that is not a shard, shards
// of different scenes, settings or shard counts, a shard given twice, a missing shard, a scene
// changed since the shards were baked, damaged data.
Expected<MergedBake> merge_shards(const std::vector<std::filesystem::path>& folders,
                                  const std::filesystem::path& scene_file = {});

}  // namespace sb
