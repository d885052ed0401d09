// The bake pipeline: scene → meshes → ray scene and lights → texel space per receiver →
// method → dilation. Methods are chosen by name (methods.cpp lists them).
#include "bake.h"

#include <tbb/global_control.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>

#include "lights.h"
#include "mesh.h"
#include "ray_scene.h"
#include "reference_bake.h"
#include "texel_space.h"

namespace sb {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
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
  std::unique_ptr<tbb::global_control> thread_limit;
  if (options.threads > 0) {
    thread_limit = std::make_unique<tbb::global_control>(
        tbb::global_control::max_allowed_parallelism, std::size_t(options.threads));
  }

  BakeResult result;
  const auto load_start = std::chrono::steady_clock::now();
  std::vector<Mesh> meshes;
  meshes.reserve(scene.objects.size());
  for (const auto& obj : scene.objects) {
    auto mesh = import_mesh(obj, scene.file);
    if (!mesh) return mesh.error();
    if (mesh->skipped_degenerate > 0) {
      result.warnings.push_back(scene.file.string() + ":" + std::to_string(obj.line) +
                                ": object '" + obj.name + "': skipped " +
                                std::to_string(mesh->skipped_degenerate) +
                                " degenerate (zero-area) triangles");
    }
    meshes.push_back(std::move(*mesh));
  }
  std::vector<const Mesh*> blockers;
  for (std::size_t i = 0; i < meshes.size(); ++i)
    if (scene.objects[i].blocker) blockers.push_back(&meshes[i]);
  auto rays = RayScene::build(blockers);
  if (!rays) return rays.error();
  const std::vector<Light> lights = make_lights(scene.lights);

  const int res = scene.bake.resolution;
  std::vector<std::size_t> receivers;
  std::vector<TexelSpace> spaces;
  std::vector<double> raster_seconds;
  std::int64_t total_texels = 0;
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    if (!scene.objects[i].receiver) continue;
    const auto start = std::chrono::steady_clock::now();
    receivers.push_back(i);
    spaces.push_back(rasterise_texels(meshes[i], res, res));
    raster_seconds.push_back(seconds_since(start));
    total_texels += std::int64_t(spaces.back().texels.size());
  }
  result.load_seconds = seconds_since(load_start);

  const auto bake_start = std::chrono::steady_clock::now();
  std::atomic<std::int64_t> texels_done{0};
  ProgressFn progress;
  if (options.progress && total_texels > 0) {
    progress = [&](double done) { options.progress(done / double(total_texels)); };
  }
  for (std::size_t r = 0; r < receivers.size(); ++r) {
    const auto start = std::chrono::steady_clock::now();
    const ObjectDesc& obj = scene.objects[receivers[r]];
    ReferenceInputs in;
    in.lights = &lights;
    in.rays = &*rays;
    in.quantity = scene.bake.quantity;
    in.samples = scene.bake.samples;
    in.seed = scene.bake.seed;
    in.stream = receivers[r];
    in.texels_done = &texels_done;
    in.progress = progress;
    ReceiverBake out;
    out.name = obj.name;
    out.uv_channel = obj.uv_channel;
    out.image = bake_reference(spaces[r], in, &result.shadow_rays);
    dilate(out.image, spaces[r].covered, scene.bake.margin);
    out.covered_texels = std::int64_t(spaces[r].texels.size());
    out.seconds = raster_seconds[r] + seconds_since(start);
    result.receivers.push_back(std::move(out));
  }
  result.bake_seconds = seconds_since(bake_start);
  if (options.progress) options.progress(1.0);
  return result;
}

}  // namespace sb
