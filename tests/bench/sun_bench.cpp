// The outdoor speed goal (issue "Outdoor light"): under the sun at 4096²
// (scenes/outdoor/scene_sun.toml, the courtyard's ground, 16.5 million texels), the default bake
// (backprojection) against the reference at 24 samples, whose RMSE against the reference at 256
// samples is 0.0051 (equal error 0.005; docs/methods.md, "Suns at 4096²"), both timed in process
// (scene loaded → lightmap in memory, the bake's own bake_seconds), one bake per repetition, the
// two interleaved in one run. The default's accuracy there is below the 256-sample reference's own
// noise (docs/methods.md).
//
// Run: build/shadowbake_bench --benchmark_filter=SunAt4096 --benchmark_repetitions=5
//      --benchmark_enable_random_interleaving=true
#include <benchmark/benchmark.h>

#include <string>

#include "pipeline/bake.h"

namespace sb {
namespace {

void BM_SunAt4096(benchmark::State& state) {
  auto scene = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/outdoor/scene_sun.toml");
  if (!scene) {
    state.SkipWithError(scene.error().message.c_str());
    return;
  }
  const bool reference = state.range(0) == 1;
  scene->bake.method = reference ? "reference" : "backprojection";
  scene->bake.samples = reference ? 24 : 32;
  for (auto _ : state) {
    auto result = bake(*scene);
    if (!result) {
      state.SkipWithError(result.error().message.c_str());
      return;
    }
    state.SetIterationTime(result->bake_seconds);
  }
  state.SetLabel(reference ? "reference, 24 samples" : "backprojection (default)");
}
BENCHMARK(BM_SunAt4096)
    ->Arg(0)
    ->Arg(1)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();

}  // namespace
}  // namespace sb
