// The exact parallel case's speed goal (issue "Exact penumbrae without noise"): the default
// `backprojection` bake of scenes/parallel at 512² against the reference at 64 samples, both
// timed in process (scene loaded → lightmap in memory, the bake's own bake_seconds), side by
// side in one run. Its accuracy against the closed form is a test
// (BackprojectionBake.ExactParallelCaseIsWithinAThousandthOfTheClosedForm).
//
// Run: build/shadowbake_bench --benchmark_filter=ParallelPlanes --benchmark_repetitions=5
//      --benchmark_report_aggregates_only=true --benchmark_enable_random_interleaving=true
#include <benchmark/benchmark.h>

#include <string>

#include "pipeline/bake.h"

namespace sb {
namespace {

void BM_ParallelPlanes(benchmark::State& state) {
  auto scene = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/parallel/scene.toml");
  if (!scene) {
    state.SkipWithError(scene.error().message.c_str());
    return;
  }
  scene->bake.resolution = int(state.range(0));
  scene->bake.method = state.range(1) == 0 ? "backprojection" : "reference";
  scene->bake.samples = 64;
  for (auto _ : state) {
    auto result = bake(*scene);
    if (!result) {
      state.SkipWithError(result.error().message.c_str());
      return;
    }
    state.SetIterationTime(result->bake_seconds);
  }
  state.SetLabel(scene->bake.method);
}
BENCHMARK(BM_ParallelPlanes)
    ->ArgsProduct({{512}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();

}  // namespace
}  // namespace sb
