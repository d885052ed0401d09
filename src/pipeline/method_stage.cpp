// The fifth stage of a bake (bake_stages.h): the method on each receiver, through its interface
// (methods/method.h), then what follows it.
#include <atomic>
#include <chrono>
#include <thread>

#include "core/sampling.h"
#include "core/stopwatch.h"
#include "pipeline/bake_stages.h"
#include "pipeline/receiver_stages.h"
#include "pipeline/tiles.h"

namespace sb {

Status bake_receivers(const Scene& scene, const MethodEntry& method, const LoadedScene& loaded,
                      Reuse reuse, Texels texels, const BakeOptions& options, BakeResult* result) {
  std::atomic<std::int64_t> texels_done{0};
  BakeContext context;
  context.scene = &scene;
  context.lights = &loaded.lights;
  context.blockers = loaded.blockers;
  context.rays = loaded.rays ? &*loaded.rays : nullptr;
  context.clusters = loaded.clusters ? &*loaded.clusters : nullptr;
  context.shafts = loaded.shafts ? &*loaded.shafts : nullptr;
  context.threads = options.threads > 0 ? options.threads
                                        : int(std::max(1u, std::thread::hardware_concurrency()));
  // What the budget leaves the method's images, beyond what the estimate counted.
  context.memory_for_images = double(memory_budget(scene.bake)) - total_bytes(loaded.estimate);
  context.keep_per_light = options.keep_per_light;
  context.keep_per_light.values |= scene.output.per_light;
  context.keep_per_light.visibility |= scene.output.shadowmask;
  context.texels_done = &texels_done;
  const double total = double(texels.total);
  if (options.progress && texels.total > 0)
    context.progress = [&](double done) { options.progress(done / total); };
  auto baker = method.make(context);
  if (!baker) return baker.error();

  for (std::size_t r = 0; r < loaded.receivers.size(); ++r) {
    const std::size_t object = loaded.receivers[r];
    if (reuse.reused[r]) {
      texels_done += reuse.reused[r]->covered_texels;
      reuse.reused[r]->object = object;
      reuse.reused[r]->uv_warnings = std::move(texels.warnings[r]);
      result->receivers.push_back(std::move(*reuse.reused[r]));
      continue;
    }
    const auto start = std::chrono::steady_clock::now();
    const ObjectDesc& obj = scene.objects[object];
    ReceiverBake out;
    if (options.keys) {
      out.key = reuse.keys[r];
      out.reuse = "baked";
      out.reuse_why = reuse.why[r];
    }
    out.object = object;
    out.uv_warnings = std::move(texels.warnings[r]);
    out.lights_reached = std::move(texels.reached[r]);
    out.seconds_texels = texels.seconds[r];
    out.name = obj.name;
    out.uv_channel = obj.auto_uv ? 1 : obj.uv_channel;  // generated: the glTF's TEXCOORD_1
    ReceiverInput input;
    input.space = &texels.spaces[r];
    input.mesh = &loaded.meshes[object];
    input.object = &obj;
    // Keyed by its name: adding or removing other objects leaves its samples as they were.
    input.stream = name_stream(obj.name);
    input.lists = &*texels.lists[r];
    const std::int64_t done_before = texels_done.load();
    auto baked = (*baker)->bake(input);
    if (!baked) return baked.error();
    // The receiver's texels are done, whatever the method counted on the way.
    texels_done = done_before + std::int64_t(texels.spaces[r].texels.size());
    if (context.progress) context.progress(double(texels_done.load()));
    out.image = std::move(baked->images.image);
    out.most_lights_per_texel = baked->images.most_lights;
    out.per_light = std::move(baked->images.per_light);
    out.per_light_visibility = std::move(baked->images.per_light_visibility);
    out.report = std::move(baked->report);
    out.rays = baked->rays;
    result->shadow_rays += baked->rays;
    out.seconds_method = seconds_since(start);
    if (loaded.tiles[r]) {
      crop_to_tile(out, texels.spaces[r], *loaded.tiles[r]);  // the rest at the join
    } else {
      out.uv_layout = texels.layouts[r];
      finish_receiver(scene, loaded.meshes[object], texels.spaces[r], loaded.lights,
                      *texels.lists[r], out);
    }
    texels.spaces[r] = TexelSpace();  // its memory back before the next receiver's
    texels.lists[r].reset();
    out.seconds = texels.seconds[r] + seconds_since(start);
    result->receivers.push_back(std::move(out));
  }
  return Ok{};
}

}  // namespace sb
