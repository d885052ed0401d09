// The shaft test's cost per receiver (ShaftCuller::maybe_blocked) on corpus scenes at 512², beside
// the reference's rays for the same texels, to see what the convolution method's first step
// costs against what it saves. Run: build/shadowbake_bench --benchmark_filter=ShaftCulling
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "methods/method.h"
#include "occluders/ray_scene.h"
#include "occluders/shaft_culling.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "scene/scene.h"
#include "texels/texel_space.h"

namespace sb {
namespace {

const char* const kShaftScenes[] = {"room/scene.toml", "showcase/scene.toml", "dense/scene.toml"};

void BM_ShaftCulling(benchmark::State& state) {
  auto scene = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/" + kShaftScenes[state.range(0)]);
  if (!scene) {
    state.SkipWithError(scene.error().message.c_str());
    return;
  }
  std::vector<Mesh> meshes;
  std::vector<const Mesh*> blockers;
  for (const auto& obj : scene->objects) meshes.push_back(*import_mesh(obj, scene->file));
  for (std::size_t i = 0; i < meshes.size(); ++i)
    if (scene->objects[i].blocker) blockers.push_back(&meshes[i]);
  const auto lights = *make_lights(scene->lights, scene->file);
  const ShaftCuller culler(blockers);
  std::vector<TexelSpace> spaces;
  for (std::size_t i = 0; i < meshes.size(); ++i)
    if (scene->objects[i].receiver) spaces.push_back(rasterise_texels(meshes[i], 512, 512));
  std::int64_t texels = 0;
  for (auto _ : state) {
    for (const TexelSpace& s : spaces)
      for (const Light& l : lights) {
        auto m = culler.maybe_blocked(s, l, 1e-4);
        benchmark::DoNotOptimize(m.data());
        texels += std::int64_t(s.texels.size());
      }
  }
  state.SetLabel(kShaftScenes[state.range(0)]);
  state.counters["texels/s"] = benchmark::Counter(double(texels), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ShaftCulling)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace sb
