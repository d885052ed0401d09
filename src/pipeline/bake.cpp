// The bake pipeline as a list of stages (bake_stages.h, each in its own file): scene → method
// entry → meshes, lights and what the method needs → the cache's receivers → texel space per
// receiver → method → dilation and seams → what needs every receiver. Methods come from the
// registry (methods/registry.cpp) and are called through their interface (methods/method.h).
#include "pipeline/bake.h"

#include <tbb/global_control.h>

#include <chrono>
#include <memory>

#include "core/stopwatch.h"
#include "pipeline/bake_stages.h"
#include "pipeline/memory_budget.h"
#include "pipeline/receiver_stages.h"
#include "texels/lightmap_sizes.h"

namespace sb {

namespace {

std::unique_ptr<tbb::global_control> limit_threads(const BakeOptions& options) {
  if (options.threads <= 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                               std::size_t(options.threads));
}

}  // namespace

Expected<BakeResult> bake(const Scene& scene, const BakeOptions& options) {
  BakeResult result;
  result.setup_warnings = scene.warnings;
  auto method = check_request(scene, &result.setup_warnings);
  if (!method) return method.error();
  const MethodEntry& entry = **method;
  const auto thread_limit = limit_threads(options);

  // Load: meshes, lights, this bake's receivers, what the method needs built.
  const auto load_start = std::chrono::steady_clock::now();
  LoadedScene loaded;
  if (Status s = load_scene_for(scene, entry, options, &loaded, &result); !s) return s.error();
  result.load_seconds = seconds_since(load_start);

  // Bake, timed from here: the cache, texel space, the method, dilation, seams.
  const auto bake_start = std::chrono::steady_clock::now();
  auto reuse = reuse_from_cache(scene, entry, loaded, options);
  if (!reuse) return reuse.error();
  auto texels = build_texels(scene, entry, loaded, *reuse);
  if (!texels) return texels.error();
  if (Status s = bake_receivers(scene, entry, loaded, std::move(*reuse), std::move(*texels),
                                options, &result);
      !s)
    return s.error();
  finish_bake(scene, result, !options.shard);
  result.bake_seconds = seconds_since(bake_start);
  if (options.progress) options.progress(1.0);
  return result;
}

Expected<std::vector<std::string>> plan(const Scene& scene, const BakeOptions& options) {
  const MethodEntry* entry = find_method(scene.bake.method);
  if (!entry || !entry->plan) {
    std::string planned;
    for (const MethodEntry& m : method_registry())
      if (m.plan) planned += (planned.empty() ? "" : ", ") + m.name;
    return scene_error(scene.file.string() + ": [bake]: method '" + scene.bake.method +
                       "' has no plan to show (methods with one: " + planned + ")");
  }
  if (const std::vector<int> sides = sides_from_settings(scene); !sides.empty()) {
    if (Status fits =
            check_memory(scene, bake_memory_estimate(scene, sides), memory_budget(scene.bake),
                         "lower 'resolution' (--resolution) or raise max_memory");
        !fits)
      return fits.error();
  }
  const auto thread_limit = limit_threads(options);
  auto meshes = load_meshes(scene, nullptr);
  if (!meshes) return meshes.error();
  const std::vector<int> sides = lightmap_sides(scene, *meshes, nullptr);
  auto lights = make_lights(placed_lights(scene, *meshes), scene.file);
  if (!lights) return lights.error();
  const std::vector<const Mesh*> blockers = blocker_meshes(scene, *meshes);
  // Only what a plan reads: the blockers' clusters, where the method needs them.
  std::optional<ClusterTree> clusters;
  if (entry->needs(scene.bake).clusters) clusters.emplace(build_clusters(blockers));
  BakeContext context;
  context.scene = &scene;
  context.lights = &*lights;
  context.blockers = blockers;
  context.clusters = clusters ? &*clusters : nullptr;
  std::vector<std::string> out;
  for (std::size_t i = 0; i < meshes->size(); ++i) {
    if (!scene.objects[i].receiver) continue;
    const int side = sides[out.size()];
    const TexelSpace space = rasterise_texels((*meshes)[i], side, side);
    ReceiverInput input;
    input.space = &space;
    input.mesh = &(*meshes)[i];
    input.object = &scene.objects[i];
    auto text = entry->plan(context, input);
    if (!text) return text.error();
    out.push_back(std::move(*text));
  }
  return out;
}

}  // namespace sb
