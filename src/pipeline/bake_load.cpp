// The second stage of a bake (bake_stages.h): the scene as the bake reads it, the receivers it
// bakes, the memory budget, and what the method needs built.
#include "occluders/clusters.h"
#include "pipeline/bake_stages.h"
#include "pipeline/receiver_stages.h"
#include "pipeline/tiles.h"
#include "texels/lightmap_sizes.h"

namespace sb {

Status load_scene_for(const Scene& scene, const MethodEntry& method, const BakeOptions& options,
                      LoadedScene* loaded, BakeResult* result) {
  const std::string advice =
      scene.bake.texels_per_metre > 0
          ? "lower 'texels_per_metre' (--texels-per-metre) or raise max_memory (--max-memory)"
          : "lower 'resolution' (--resolution) or raise max_memory (--max-memory)";
  // With a resolution the sides are known before the meshes are read, and the budget is checked
  // first; with a density, once they are read.
  if (const std::vector<int> sides = sides_from_settings(scene); !sides.empty() && !options.shard) {
    loaded->estimate = bake_memory_estimate(scene, sides);
    if (Status fits = check_memory(scene, loaded->estimate, memory_budget(scene.bake), advice);
        !fits)
      return fits.error();
  }
  auto meshes = load_meshes(scene, &result->setup_warnings);
  if (!meshes) return meshes.error();
  loaded->meshes = std::move(*meshes);
  const std::vector<Mesh>& all = loaded->meshes;
  const std::vector<int> sides = lightmap_sides(scene, all, &result->setup_warnings);
  // The ray scene first where the method traces (the lights' check below reads it).
  loaded->blockers = blocker_meshes(scene, all);
  const MethodNeeds needs = method.needs(scene.bake);
  if (needs.rays) {
    auto built = RayScene::build(loaded->blockers);
    if (!built) return built.error();
    loaded->rays.emplace(std::move(*built));
  }
  std::vector<LightDesc> descs = placed_lights(scene, all);
  if (Status checked =
          cut_enclosed_lights(scene, loaded->blockers, loaded->rays ? &*loaded->rays : nullptr,
                              descs, result->setup_warnings);
      !checked)
    return checked.error();
  auto lights = make_lights(descs, scene.file);
  if (!lights) return lights.error();
  loaded->lights = std::move(*lights);

  // What this bake does: every receiver, or its shard's receivers and tiles (tiles.h).
  std::vector<std::size_t> all_receivers;
  for (std::size_t i = 0; i < all.size(); ++i)
    if (scene.objects[i].receiver) all_receivers.push_back(i);
  std::vector<ShardUnit> units;
  if (options.shard) {
    std::vector<std::vector<double>> costs;
    for (std::size_t r = 0; r < all_receivers.size(); ++r)
      costs.push_back(row_block_costs(all[all_receivers[r]], sides[r], loaded->lights));
    units =
        shard_units(costs, sides, options.shard->tiles && method.tile_halo >= 0, *options.shard);
  } else {
    for (std::size_t r = 0; r < all_receivers.size(); ++r) units.push_back({r, std::nullopt});
  }
  for (const ShardUnit& u : units) {
    loaded->receivers.push_back(all_receivers[u.receiver]);
    loaded->sides.push_back(sides[u.receiver]);
    loaded->tiles.push_back(u.rows);
  }
  if (loaded->estimate.empty()) {
    loaded->estimate = bake_memory_estimate(scene, loaded->sides);
    if (Status fits = check_memory(scene, loaded->estimate, memory_budget(scene.bake), advice);
        !fits)
      return fits.error();
  }
  // The per-light images, once the lights' reach is known.
  std::vector<const Mesh*> baked;
  for (const std::size_t object : loaded->receivers) baked.push_back(&all[object]);
  if (const auto per_light = per_light_memory(scene, baked, loaded->sides, loaded->lights)) {
    loaded->estimate.push_back(*per_light);
    if (Status fits = check_memory(scene, loaded->estimate, memory_budget(scene.bake), advice);
        !fits)
      return fits.error();
  }
  if (scene.output.atlas && !options.shard)
    result->atlas = pack_atlases(sides, *scene.output.atlas);
  if (scene.output.gltf && (!options.shard || options.shard->index == 0)) {
    const bool y_up = world_is_y_up(scene);
    for (std::size_t i = 0; i < all.size(); ++i)
      if (!scene.objects[i].receiver)
        result->gltf_blockers.emplace_back(
            scene.objects[i].name,
            std::make_shared<const GltfMesh>(gltf_mesh(all[i], false, y_up)));
  }

  // What else the method asks for, built once and shared by every receiver.
  if (needs.clusters) loaded->clusters.emplace(build_clusters(loaded->blockers));
  if (needs.shafts) loaded->shafts.emplace(loaded->blockers);
  return Ok{};
}

}  // namespace sb
