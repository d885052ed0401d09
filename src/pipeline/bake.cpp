// The bake pipeline: scene → meshes → what the method needs (ray scene, clusters, shafts) and
// lights → texel space per receiver → method → dilation → seams. Methods come from the registry
// (methods/registry.cpp) and are called through their interface (methods/method.h).
#include "pipeline/bake.h"

#include <fmt/format.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <thread>

#include "core/sampling.h"
#include "core/stopwatch.h"
#include "lightmaps/shadowmask.h"
#include "methods/convolution/fft_convolution.h"
#include "methods/convolution/traced_convolution.h"
#include "methods/method.h"
#include "occluders/clusters.h"
#include "occluders/ray_scene.h"
#include "occluders/shaft_culling.h"
#include "pipeline/bake_cache.h"
#include "pipeline/memory_budget.h"
#include "pipeline/receiver_stages.h"
#include "pipeline/tiles.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "texels/lightmap_sizes.h"
#include "texels/texel_space.h"

namespace sb {

namespace {

std::unique_ptr<tbb::global_control> limit_threads(const BakeOptions& options) {
  if (options.threads <= 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                               std::size_t(options.threads));
}

// The [bake] keys every bake reads, whatever its method.
bool read_by_every_method(const std::string& key) {
  for (const char* k :
       {"resolution", "texels_per_metre", "method", "quantity", "margin", "seams", "max_memory"})
    if (key == k) return true;
  return false;
}

// "file:line: [bake] key: method 'm' does not use it (...)" for each key the scene sets that the
// chosen method does not read, naming the methods that do.
void report_ignored_settings(const Scene& scene, const MethodEntry& method,
                             std::vector<std::string>* warnings) {
  for (const SettingGiven& given : scene.bake_keys) {
    if (read_by_every_method(given.key)) continue;
    if (std::find(method.settings.begin(), method.settings.end(), given.key) !=
        method.settings.end())
      continue;
    std::string users;
    for (const MethodEntry& other : method_registry())
      if (std::find(other.settings.begin(), other.settings.end(), given.key) !=
          other.settings.end())
        users += (users.empty() ? "" : ", ") + other.name;
    warnings->push_back(fmt::format("{}:{}: [bake] {}: method '{}' does not use it (read by {})",
                                    scene.file.string(), given.line, given.key, method.name,
                                    users));
  }
}

}  // namespace

Expected<BakeResult> bake(const Scene& scene, const BakeOptions& options) {
  const MethodEntry* entry = find_method(scene.bake.method);
  if (!entry) {
    std::string known;
    for (const auto& m : known_methods()) known += (known.empty() ? "" : ", ") + m;
    return scene_error(scene.file.string() + ": [bake]: unknown method '" + scene.bake.method +
                       "' (known: " + known + ")");
  }
  const bool ambient_occlusion = scene.bake.quantity == Quantity::ambient_occlusion;
  {
    BakeSettings settings = scene.bake;
    if (Status paired =
            pair_quantity_and_method(settings, true, true, scene.file.string() + ": [bake]");
        !paired)
      return paired.error();
  }
  if (ambient_occlusion && (scene.output.per_light || scene.output.shadowmask))
    return scene_error(scene.file.string() +
                       ": [output]: per-light images and shadow masks are images of lights; an "
                       "ambient-occlusion bake has none (leave out per_light and shadowmask)");
  if (!ambient_occlusion && scene.lights.empty())
    return scene_error(scene.file.string() + ": no light: a " + to_string(scene.bake.quantity) +
                       " bake needs at least one (an ambient-occlusion bake needs none)");
  const std::string advice =
      scene.bake.texels_per_metre > 0
          ? "lower 'texels_per_metre' (--texels-per-metre) or raise max_memory (--max-memory)"
          : "lower 'resolution' (--resolution) or raise max_memory (--max-memory)";
  // With a resolution the sides are known before the meshes are read, and the budget is checked
  // first; with a density, once they are read.
  std::vector<MemoryItem> estimate;
  if (const std::vector<int> sides = sides_from_settings(scene); !sides.empty() && !options.shard) {
    estimate = bake_memory_estimate(scene, sides);
    if (Status fits = check_memory(scene, estimate, memory_budget(scene.bake), advice); !fits)
      return fits.error();
  }
  const auto thread_limit = limit_threads(options);

  BakeResult result;
  result.setup_warnings = scene.warnings;
  report_ignored_settings(scene, *entry, &result.setup_warnings);
  const auto load_start = std::chrono::steady_clock::now();
  auto loaded = load_meshes(scene, &result.setup_warnings);
  if (!loaded) return loaded.error();
  const std::vector<Mesh>& meshes = *loaded;
  const std::vector<int> sides = lightmap_sides(scene, meshes, &result.setup_warnings);
  auto lights_or = make_lights(placed_lights(scene, meshes), scene.file);
  if (!lights_or) return lights_or.error();
  const std::vector<Light>& lights = *lights_or;
  // What this bake does: every receiver, or its shard's receivers and tiles (tiles.h), as
  // object indices, their sides and, for a tile, its rows.
  std::vector<std::size_t> all_receivers;
  for (std::size_t i = 0; i < meshes.size(); ++i)
    if (scene.objects[i].receiver) all_receivers.push_back(i);
  std::vector<ShardUnit> units;
  if (options.shard) {
    std::vector<std::vector<double>> costs;
    for (std::size_t r = 0; r < all_receivers.size(); ++r)
      costs.push_back(row_block_costs(meshes[all_receivers[r]], sides[r], lights));
    units =
        shard_units(costs, sides, options.shard->tiles && entry->tile_halo >= 0, *options.shard);
  } else {
    for (std::size_t r = 0; r < all_receivers.size(); ++r) units.push_back({r, std::nullopt});
  }
  std::vector<std::size_t> receivers;
  std::vector<int> my_sides;
  std::vector<std::optional<RowRange>> tiles;
  for (const ShardUnit& u : units) {
    receivers.push_back(all_receivers[u.receiver]);
    my_sides.push_back(sides[u.receiver]);
    tiles.push_back(u.rows);
  }
  if (estimate.empty()) {
    estimate = bake_memory_estimate(scene, my_sides);
    if (Status fits = check_memory(scene, estimate, memory_budget(scene.bake), advice); !fits)
      return fits.error();
  }
  if (scene.output.atlas && !options.shard) result.atlas = pack_atlases(sides, *scene.output.atlas);
  if (scene.output.gltf && (!options.shard || options.shard->index == 0)) {
    for (std::size_t i = 0; i < meshes.size(); ++i)
      if (!scene.objects[i].receiver)
        result.gltf_blockers.emplace_back(
            scene.objects[i].name, std::make_shared<const GltfMesh>(gltf_mesh(meshes[i], false)));
  }
  const std::vector<const Mesh*> blockers = blocker_meshes(scene, meshes);
  // What the method asks for, built once and shared by every receiver.
  const MethodNeeds needs = entry->needs(scene.bake);
  std::optional<RayScene> rays;
  if (needs.rays) {
    auto built = RayScene::build(blockers);
    if (!built) return built.error();
    rays.emplace(std::move(*built));
  }
  ClusterTree clusters;
  if (needs.clusters) clusters = build_clusters(blockers);
  std::optional<ShaftCuller> shafts;
  if (needs.shafts) shafts.emplace(blockers);
  result.load_seconds = seconds_since(load_start);

  // The bake proper, timed from here: the receivers' keys, texel space, the method, dilation,
  // seams.
  const auto bake_start = std::chrono::steady_clock::now();
  // Incremental bakes: each receiver's key, and the receivers an earlier bake's cache holds
  // unchanged (or that --only leaves as they were).
  std::vector<std::optional<ReceiverBake>> reused(receivers.size());
  std::vector<ReceiverKey> keys(receivers.size());
  std::vector<std::string> reasons(receivers.size());
  if (options.keys) {
    std::optional<ShaftCuller> own_culler;
    const ShaftCuller* culler = shafts ? &*shafts : nullptr;
    if (!culler && !ambient_occlusion && method_is_local(scene.bake.method)) {
      own_culler.emplace(blockers);
      culler = &*own_culler;
    }
    KeyInputs key_inputs;
    key_inputs.scene = &scene;
    key_inputs.meshes = &meshes;
    key_inputs.lights = &lights;
    key_inputs.blockers = &blockers;
    key_inputs.culler = culler;
    key_inputs.keep_per_light = options.keep_per_light;
    key_inputs.keep_per_light.values |= scene.output.per_light;
    key_inputs.keep_per_light.visibility |= scene.output.shadowmask;
    std::vector<std::vector<int>> reaching;
    auto computed = receiver_keys(key_inputs, receivers, my_sides, &reaching);
    if (!computed) return computed.error();
    keys = std::move(*computed);
    auto decided = decide_reuse(scene, receivers, keys, reaching, options);
    if (!decided) return decided.error();
    for (std::size_t r = 0; r < receivers.size(); ++r) {
      reused[r] = std::move((*decided)[r].reused);
      reasons[r] = std::move((*decided)[r].why);
    }
  }

  std::vector<TexelSpace> spaces;
  std::vector<double> raster_seconds;
  std::int64_t total_texels = 0;
  std::vector<UvLayoutReport> layouts;
  std::vector<std::vector<std::string>> uv_warnings(receivers.size());
  std::vector<std::vector<std::uint8_t>> reached(receivers.size());
  for (std::size_t r = 0; r < receivers.size(); ++r) {
    const std::size_t i = receivers[r];
    const ObjectDesc& obj = scene.objects[i];
    const auto start = std::chrono::steady_clock::now();
    const int res = my_sides[r];
    std::int64_t covered = 0;
    if (reused[r]) {  // taken from the cache: nothing to rasterise, its layout as it was
      spaces.emplace_back();
      raster_seconds.push_back(0);
      layouts.push_back(reused[r]->uv);
      reached[r] = reused[r]->lights_reached;
      covered = reused[r]->covered_texels;
    } else if (tiles[r]) {  // a tile: its rows and the halo its method needs; the rest at the join
      spaces.push_back(
          rasterise_texels(meshes[i], res, res, tile_window(*tiles[r], entry->tile_halo, res)));
      spaces.back().kept = *tiles[r];
      raster_seconds.push_back(seconds_since(start));
      layouts.emplace_back();
      covered = std::int64_t(spaces.back().texels.size());
      total_texels += covered;
      continue;
    } else {
      spaces.push_back(rasterise_texels(meshes[i], res, res));
      raster_seconds.push_back(seconds_since(start));
      covered = std::int64_t(spaces.back().texels.size());
      layouts.push_back(check_uv_layout(meshes[i], spaces.back(), scene.bake.margin));
      // Which lights reach any of its texels (for the warning about lights that reach nothing).
      reached[r] = lights_reaching(scene, spaces.back(), lights);
    }
    total_texels += covered;
    auto warnings = layout_warnings(scene, obj, layouts.back(), covered, res);
    if (!warnings) return warnings.error();
    uv_warnings[r] = std::move(*warnings);
  }

  std::atomic<std::int64_t> texels_done{0};
  BakeContext context;
  context.scene = &scene;
  context.lights = &lights;
  context.blockers = blockers;
  context.rays = rays ? &*rays : nullptr;
  context.clusters = needs.clusters ? &clusters : nullptr;
  context.shafts = shafts ? &*shafts : nullptr;
  context.threads = options.threads > 0 ? options.threads
                                        : int(std::max(1u, std::thread::hardware_concurrency()));
  // What the budget leaves the method's images, beyond what the estimate above counted.
  context.memory_for_images = double(memory_budget(scene.bake)) - total_bytes(estimate);
  context.keep_per_light = options.keep_per_light;
  context.keep_per_light.values |= scene.output.per_light;
  context.keep_per_light.visibility |= scene.output.shadowmask;
  context.texels_done = &texels_done;
  if (options.progress && total_texels > 0) {
    context.progress = [&](double done) { options.progress(done / double(total_texels)); };
  }
  auto method = entry->make(context);
  if (!method) return method.error();

  for (std::size_t r = 0; r < receivers.size(); ++r) {
    if (reused[r]) {
      texels_done += reused[r]->covered_texels;
      reused[r]->object = receivers[r];
      reused[r]->uv_warnings = std::move(uv_warnings[r]);
      result.receivers.push_back(std::move(*reused[r]));
      continue;
    }
    const auto start = std::chrono::steady_clock::now();
    const ObjectDesc& obj = scene.objects[receivers[r]];
    ReceiverBake out;
    if (options.keys) {
      out.key = keys[r];
      out.reuse = "baked";
      out.reuse_why = reasons[r];
    }
    out.object = receivers[r];
    out.uv_warnings = std::move(uv_warnings[r]);
    out.lights_reached = std::move(reached[r]);
    out.seconds_texels = raster_seconds[r];
    out.name = obj.name;
    out.uv_channel = obj.auto_uv ? 1 : obj.uv_channel;  // generated: the glTF's TEXCOORD_1
    ReceiverInput input;
    input.space = &spaces[r];
    input.mesh = &meshes[receivers[r]];
    input.object = &obj;
    // Keyed by its name: adding or removing other objects leaves its samples as they were.
    input.stream = name_stream(obj.name);
    const std::int64_t done_before = texels_done.load();
    auto baked = (*method)->bake(input);
    if (!baked) return baked.error();
    // The receiver's texels are done, whatever the method counted on the way.
    texels_done = done_before + std::int64_t(spaces[r].texels.size());
    if (context.progress) context.progress(double(texels_done.load()));
    out.image = std::move(baked->images.image);
    out.per_light = std::move(baked->images.per_light);
    out.per_light_visibility = std::move(baked->images.per_light_visibility);
    out.report = std::move(baked->report);
    out.rays = baked->rays;
    result.shadow_rays += baked->rays;
    out.seconds_method = seconds_since(start);
    if (tiles[r]) {
      crop_to_tile(out, spaces[r], *tiles[r]);  // dilation, seams and the rest at the join
    } else {
      out.uv = layouts[r];
      finish_receiver(scene, meshes[receivers[r]], spaces[r], lights, out);
    }
    spaces[r] = TexelSpace();  // its memory back before the next receiver's
    out.seconds = raster_seconds[r] + seconds_since(start);
    result.receivers.push_back(std::move(out));
  }
  finish_bake(scene, result, !options.shard);
  result.bake_seconds = seconds_since(bake_start);
  if (options.progress) options.progress(1.0);
  return result;
}

void finish_bake(const Scene& scene, BakeResult& result, bool whole) {
  std::vector<std::string> warnings = result.setup_warnings;
  for (const ReceiverBake& r : result.receivers)
    warnings.insert(warnings.end(), r.uv_warnings.begin(), r.uv_warnings.end());
  // A light that reaches no receiver texel (facing away, or below every texel's horizon) is
  // most often a normal pointing the wrong way: say so.
  std::int64_t texels = 0;
  for (const ReceiverBake& r : result.receivers) texels += r.covered_texels;
  const bool lit = scene.bake.quantity != Quantity::ambient_occlusion;
  for (std::size_t l = 0; whole && lit && texels > 0 && l < scene.lights.size(); ++l) {
    bool reached = false;
    for (const ReceiverBake& r : result.receivers)
      reached = reached || (l < r.lights_reached.size() && r.lights_reached[l]);
    if (reached) continue;
    const LightDesc& d = scene.lights[l];
    warnings.push_back(fmt::format(
        "{}:{}: light '{}': reaches no texel of any receiver (is its 'normal' the right way, or "
        "its 'position' behind the receivers?); it adds nothing",
        scene.file.string(), d.line, d.name));
  }
  for (const ReceiverBake& r : result.receivers)
    warnings.insert(warnings.end(), r.report.warnings.begin(), r.report.warnings.end());
  result.shadowmask_channels.clear();
  if (whole && scene.output.shadowmask) {
    LightOverlaps overlaps(scene.lights.size());
    for (const ReceiverBake& r : result.receivers)
      add_overlaps(r.per_light_visibility, r.covered, overlaps);
    ShadowmaskChannels channels = assign_shadowmask_channels(overlaps, scene.lights, scene.file);
    result.shadowmask_channels = std::move(channels.channel);
    for (std::string& w : channels.warnings) warnings.push_back(std::move(w));
  }
  result.warnings = std::move(warnings);
}

std::vector<std::size_t> shard_receivers(const std::vector<double>& costs, const ShardSpec& spec) {
  const std::size_t n = costs.size(), shards = std::size_t(std::max(spec.count, 1));
  std::vector<std::size_t> shard_of(n, 0);
  if (spec.balance == ShardBalance::count) {
    for (std::size_t r = 0; r < n; ++r) shard_of[r] = r % shards;
  } else {
    // Longest processing time first: dearest receiver first (ties in scene order), each onto the
    // shard with the least cost so far (ties: the lowest shard). Within 4/3 of the best makespan.
    std::vector<std::size_t> order(n);
    for (std::size_t r = 0; r < n; ++r) order[r] = r;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return costs[a] > costs[b]; });
    std::vector<double> load(shards, 0.0);
    for (const std::size_t r : order) {
      const std::size_t least =
          std::size_t(std::min_element(load.begin(), load.end()) - load.begin());
      shard_of[r] = least;
      load[least] += costs[r];
    }
  }
  std::vector<std::size_t> mine;
  for (std::size_t r = 0; r < n; ++r)
    if (shard_of[r] == std::size_t(spec.index)) mine.push_back(r);
  return mine;
}

Expected<std::vector<std::string>> plan(const Scene& scene, const BakeOptions& options) {
  if (const std::vector<int> sides = sides_from_settings(scene); !sides.empty()) {
    if (Status fits =
            check_memory(scene, bake_memory_estimate(scene, sides), memory_budget(scene.bake),
                         "lower 'resolution' (--resolution) or raise max_memory");
        !fits)
      return fits.error();
  }
  const auto thread_limit = limit_threads(options);
  auto loaded = load_meshes(scene, nullptr);
  if (!loaded) return loaded.error();
  const std::vector<Mesh>& meshes = *loaded;
  const std::vector<int> sides = lightmap_sides(scene, meshes, nullptr);
  const ClusterTree clusters = build_clusters(blocker_meshes(scene, meshes));
  auto lights = make_lights(placed_lights(scene, meshes), scene.file);
  if (!lights) return lights.error();
  BakeContext context;
  context.scene = &scene;
  context.lights = &*lights;
  context.blockers = blocker_meshes(scene, meshes);
  context.clusters = &clusters;
  const FftConvolver fft;
  std::vector<std::string> out;
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    if (!scene.objects[i].receiver) continue;
    const int side = sides[out.size()];
    const TexelSpace space = rasterise_texels(meshes[i], side, side);
    out.push_back(describe_plan(plan_convolution(space, plan_inputs(context, &meshes[i], &fft))));
  }
  return out;
}

}  // namespace sb
