// The bake pipeline: scene → meshes → ray scene and lights → texel space per receiver →
// method → dilation. Methods are chosen by name (methods.cpp lists them).
#include "pipeline/bake.h"

#include <fmt/format.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>
#include <optional>
#include <thread>

#include "methods/baselines.h"
#include "occluders/clusters.h"
#include "methods/convolution/convolution_bake.h"
#include "methods/convolution/fft_convolution.h"
#include "scene/lights.h"
#include "pipeline/memory_budget.h"
#include "scene/mesh.h"
#include "occluders/ray_scene.h"
#include "methods/reference_bake.h"
#include "occluders/shaft_culling.h"
#include "texels/texel_space.h"
#include "methods/convolution/traced_convolution.h"

namespace sb {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Every object's mesh, in scene order; skipped degenerate triangles become warnings. A mesh file
// may be a quarter of the memory budget, and its reader may use half of it: Assimp's scene and
// the working mesh take several times the file's size.
Expected<std::vector<Mesh>> load_meshes(const Scene& scene, std::vector<std::string>* warnings) {
  std::vector<Mesh> meshes;
  meshes.reserve(scene.objects.size());
  ImportLimits limits;
  limits.max_file_bytes = memory_budget(scene.bake) / 4;
  limits.max_memory = memory_budget(scene.bake) / 2;
  for (const auto& obj : scene.objects) {
    auto mesh = import_mesh(obj, scene.file, limits);
    if (!mesh) return mesh.error();
    if (mesh->skipped_degenerate > 0 && warnings) {
      warnings->push_back(scene.file.string() + ":" + std::to_string(obj.line) + ": object '" +
                          obj.name + "': skipped " + std::to_string(mesh->skipped_degenerate) +
                          " degenerate (zero-area) triangles");
    }
    meshes.push_back(std::move(*mesh));
  }
  return meshes;
}

std::vector<const Mesh*> blocker_meshes(const Scene& scene, const std::vector<Mesh>& meshes) {
  std::vector<const Mesh*> blockers;
  for (std::size_t i = 0; i < meshes.size(); ++i)
    if (scene.objects[i].blocker) blockers.push_back(&meshes[i]);
  return blockers;
}

std::unique_ptr<tbb::global_control> limit_threads(const BakeOptions& options) {
  if (options.threads <= 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                               std::size_t(options.threads));
}

}  // namespace

Expected<BakeResult> bake(const Scene& scene, const BakeOptions& options) {
  const auto& methods = known_methods();
  if (std::find(methods.begin(), methods.end(), scene.bake.method) == methods.end()) {
    std::string known;
    for (const auto& m : methods) known += (known.empty() ? "" : ", ") + m;
    return scene_error(scene.file.string() + ": [bake]: unknown method '" + scene.bake.method +
                       "' (known: " + known + ")");
  }
  if (scene.bake.method == "convolution" && !scene.bake.convolve && !scene.bake.trace)
    return scene_error(scene.file.string() +
                       ": [bake]: convolve = false needs trace = true (with neither, nothing "
                       "would compute the shadows)");
  const std::vector<MemoryItem> estimate = bake_memory_estimate(scene);
  if (Status fits = check_memory(scene, estimate, memory_budget(scene.bake),
                                 "lower 'resolution' (--resolution) or raise max_memory "
                                 "(--max-memory)");
      !fits)
    return fits.error();
  const auto thread_limit = limit_threads(options);
  FftConvolver::shared().set_threads(options.threads > 0
                                         ? options.threads
                                         : int(std::max(1u, std::thread::hardware_concurrency())));

  BakeResult result;
  const auto load_start = std::chrono::steady_clock::now();
  auto loaded = load_meshes(scene, &result.warnings);
  if (!loaded) return loaded.error();
  const std::vector<Mesh>& meshes = *loaded;
  const std::vector<const Mesh*> blockers = blocker_meshes(scene, meshes);
  // The methods that cast rays: the reference and accumulation for their shadows, erosion for
  // its hard shadow and blocker distances. The convolution and the shadow-map filters do not.
  const std::string& method = scene.bake.method;
  const bool ray_traced = method == "reference" || method == "accumulation" ||
                          method == "erosion" || (method == "convolution" && scene.bake.trace);
  std::optional<RayScene> rays;
  if (ray_traced) {
    auto built = RayScene::build(blockers);
    if (!built) return built.error();
    rays.emplace(std::move(*built));
  }
  // The convolution's cluster hierarchy (clusters.h), over the blockers in this order.
  ClusterTree clusters;
  std::optional<ShaftCuller> culler;
  if (method == "convolution") {
    if (scene.bake.convolve || !scene.bake.trace) clusters = build_clusters(blockers);
    culler.emplace(blockers);
  }
  auto lights_or = make_lights(scene.lights, scene.file);
  if (!lights_or) return lights_or.error();
  const std::vector<Light>& lights = *lights_or;

  result.load_seconds = seconds_since(load_start);

  // The bake proper, timed from here: texel space, the method, dilation.
  const auto bake_start = std::chrono::steady_clock::now();
  const int res = scene.bake.resolution;
  std::vector<std::size_t> receivers;
  std::vector<TexelSpace> spaces;
  std::vector<double> raster_seconds;
  std::int64_t total_texels = 0;
  std::vector<UvLayoutReport> layouts;
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const ObjectDesc& obj = scene.objects[i];
    if (!obj.receiver) continue;
    const auto start = std::chrono::steady_clock::now();
    receivers.push_back(i);
    spaces.push_back(rasterise_texels(meshes[i], res, res));
    raster_seconds.push_back(seconds_since(start));
    total_texels += std::int64_t(spaces.back().texels.size());
    layouts.push_back(check_uv_layout(meshes[i], spaces.back(), scene.bake.margin));
    const std::string where =
        scene.file.string() + ":" + std::to_string(obj.line) + ": object '" + obj.name + "': ";
    if (spaces.back().texels.empty()) {
      const UvLayoutReport& uv = layouts.back();
      const std::string problem = fmt::format(
          "its lightmap UVs (channel {}) cover no texel at {}² (UV area {:.3g}, of which {:.3g} "
          "inside [0, 1])",
          obj.uv_channel, res, uv.uv_area, uv.uv_area - uv.uv_area_outside);
      if (!obj.allow_uncovered) {
        return scene_error(where + problem +
                           "; fix the UVs, set 'uv' to the lightmap channel, or set "
                           "allow_uncovered = true");
      }
      result.warnings.push_back(where + problem + "; its lightmap is black");
    }
    for (const std::string& w : uv_layout_warnings(layouts.back()))
      result.warnings.push_back(where + w);
  }

  // A light that reaches no receiver texel (facing away, or below every texel's horizon) is
  // most often a normal pointing the wrong way: say so.
  for (std::size_t l = 0; l < lights.size() && total_texels > 0; ++l) {
    bool reached = false;
    for (std::size_t r = 0; r < spaces.size() && !reached; ++r)
      for (const Texel& t : spaces[r].texels)
        if ((reached = lights[l].reaches(t.position.cast<double>(), t.normal.cast<double>())))
          break;
    if (!reached) {
      const LightDesc& d = scene.lights[l];
      result.warnings.push_back(fmt::format(
          "{}:{}: light '{}': reaches no texel of any receiver (is its 'normal' the right way, or "
          "its 'position' behind the receivers?); it adds nothing",
          scene.file.string(), d.line, d.name));
    }
  }

  std::atomic<std::int64_t> texels_done{0};
  ProgressFn progress;
  if (options.progress && total_texels > 0) {
    progress = [&](double done) { options.progress(done / double(total_texels)); };
  }
  for (std::size_t r = 0; r < receivers.size(); ++r) {
    const auto start = std::chrono::steady_clock::now();
    const ObjectDesc& obj = scene.objects[receivers[r]];
    ReceiverBake out;
    out.seconds_texels = raster_seconds[r];
    out.name = obj.name;
    out.uv_channel = obj.uv_channel;
    if (method != "convolution" && method != "reference") {
      BaselineInputs in;
      in.lights = &lights;
      in.rays = rays ? &*rays : nullptr;
      in.blockers = blockers;
      in.receiver = &meshes[receivers[r]];
      in.settings = &scene.bake;
      in.stream = receivers[r];
      if (method == "accumulation") {
        out.image = bake_accumulation(spaces[r], in, &out.stats, &result.shadow_rays);
      } else if (method == "erosion") {
        out.image = bake_erosion(spaces[r], in, &out.stats, &result.shadow_rays);
      } else {
        out.image = bake_shadow_map_filter(spaces[r], in, &out.stats);
      }
      texels_done += std::int64_t(spaces[r].texels.size());
      if (progress) progress(double(texels_done.load()));
    } else if (method == "reference") {
      ReferenceInputs in;
      in.lights = &lights;
      in.rays = &*rays;
      in.quantity = scene.bake.quantity;
      in.samples = scene.bake.samples;
      in.seed = scene.bake.seed;
      in.stream = receivers[r];
      in.texels_done = &texels_done;
      in.progress = progress;
      out.image = bake_reference(spaces[r], in, &result.shadow_rays);
    } else {
      ConvolutionInputs in;
      in.lights = &lights;
      in.receiver = &meshes[receivers[r]];
      in.blockers = blockers;
      in.clusters = &clusters;
      in.quantity = scene.bake.quantity;
      in.error_texels = scene.bake.error_texels;
      in.max_image = scene.bake.max_image;
      in.max_triples = scene.bake.max_triples;
      in.light_parts = scene.bake.light_parts;
      in.combine =
          scene.bake.blocker_combine == "sum" ? BlockerCombine::sum : BlockerCombine::product;
      in.weighted = scene.bake.weighting == "irradiance";
      // What the budget leaves the leaves' images, beyond what the estimate above counted.
      in.memory_for_images = double(memory_budget(scene.bake)) - total_bytes(estimate);
      TracedConvolutionInputs traced;
      traced.convolution = in;
      traced.culler = &*culler;
      traced.rays = rays ? &*rays : nullptr;
      traced.convolve = scene.bake.convolve;
      traced.samples = scene.bake.samples;
      traced.trace_error_texels = scene.bake.trace_error_texels;
      traced.seed = scene.bake.seed;
      traced.stream = receivers[r];
      ConvolutionPlan plan;
      TracedConvolutionStats stats;
      auto image = bake_traced_convolution(spaces[r], traced, &out.pairs, &plan, &stats);
      if (!image) {
        return scene_error(scene.file.string() + ":" + std::to_string(obj.line) + ": " +
                           image.error().message);
      }
      out.image = std::move(*image);
      result.shadow_rays += stats.rays;
      const double pairs = std::max<double>(1.0, double(stats.pairs));
      out.stats.emplace_back("clear_fraction", double(stats.clear) / pairs);
      out.stats.emplace_back("convolved_fraction", double(stats.convolved) / pairs);
      out.stats.emplace_back("traced_fraction", double(stats.traced) / pairs);
      out.stats.emplace_back(
          "rays_per_texel",
          double(stats.rays) / std::max<double>(1.0, double(spaces[r].texels.size())));
      out.plan = describe_plan(plan);
      for (const auto& w : plan.warnings) result.warnings.push_back(scene.file.string() + ": " + w);
      texels_done += std::int64_t(spaces[r].texels.size());
      if (progress) progress(double(texels_done.load()));
    }
    out.seconds_method = seconds_since(start);
    const auto dilate_start = std::chrono::steady_clock::now();
    dilate(out.image, spaces[r].covered, scene.bake.margin);
    out.seconds_dilate = seconds_since(dilate_start);
    out.covered_texels = std::int64_t(spaces[r].texels.size());
    out.uv = layouts[r];
    out.covered = spaces[r].covered;
    out.seconds = raster_seconds[r] + seconds_since(start);
    result.receivers.push_back(std::move(out));
  }
  result.bake_seconds = seconds_since(bake_start);
  if (options.progress) options.progress(1.0);
  return result;
}

Expected<std::vector<std::string>> plan(const Scene& scene, const BakeOptions& options) {
  if (Status fits = check_memory(scene, bake_memory_estimate(scene), memory_budget(scene.bake),
                                 "lower 'resolution' (--resolution) or raise max_memory");
      !fits)
    return fits.error();
  const auto thread_limit = limit_threads(options);
  auto loaded = load_meshes(scene, nullptr);
  if (!loaded) return loaded.error();
  const std::vector<Mesh>& meshes = *loaded;
  const std::vector<const Mesh*> blockers = blocker_meshes(scene, meshes);
  const ClusterTree clusters = build_clusters(blockers);
  auto lights = make_lights(scene.lights, scene.file);
  if (!lights) return lights.error();
  std::vector<std::string> out;
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    if (!scene.objects[i].receiver) continue;
    const TexelSpace space =
        rasterise_texels(meshes[i], scene.bake.resolution, scene.bake.resolution);
    PlanInputs in;
    in.lights = &*lights;
    in.receiver = &meshes[i];
    in.blockers = blockers;
    in.clusters = &clusters;
    in.error_texels = scene.bake.error_texels;
    in.max_image = scene.bake.max_image;
    in.max_triples = scene.bake.max_triples;
    in.light_parts = scene.bake.light_parts;
    out.push_back(describe_plan(plan_convolution(space, in)));
  }
  return out;
}

}  // namespace sb
