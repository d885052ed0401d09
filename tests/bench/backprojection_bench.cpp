// The default method's speed goals, each the default `backprojection` bake against the reference
// at equal error, both timed in process (scene loaded → lightmap in memory, the bake's own
// bake_seconds), side by side in one run:
//
// - ParallelPlanes (issue "Exact penumbrae without noise"): scenes/parallel at 512² against the
//   reference at 64 samples. Its accuracy against the closed form is a test
//   (BackprojectionBake.ExactParallelCaseIsWithinAThousandthOfTheClosedForm).
//   Run: build/shadowbake_bench --benchmark_filter=ParallelPlanes --benchmark_repetitions=5
//        --benchmark_report_aggregates_only=true --benchmark_enable_random_interleaving=true
// - SunAt4096 (issue "Outdoor light"): scenes/outdoor/scene_sun.toml (the courtyard's ground,
//   16.5 million texels, under the sun) against the reference at 24 samples, whose RMSE against
//   the reference at 256 samples is 0.0051 (equal error 0.005; docs/methods.md, "Suns at 4096²";
//   the default's own is below that reference's noise). One bake per repetition, the two
//   interleaved.
//   Run: build/shadowbake_bench --benchmark_filter=SunAt4096 --benchmark_repetitions=9
//        --benchmark_enable_random_interleaving=true
#include <benchmark/benchmark.h>

#include <optional>
#include <string>

#include "pipeline/bake.h"

namespace sb {
namespace {

// Bakes scenes/<file> once per iteration by `method` at `samples` (and `resolution`, where
// given), each iteration timed by the bake's own bake_seconds.
void time_bakes(benchmark::State& state, const std::string& file, const std::string& method,
                int samples, std::optional<int> resolution = std::nullopt) {
  auto scene = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/" + file);
  if (!scene) {
    state.SkipWithError(scene.error().message.c_str());
    return;
  }
  if (resolution) scene->bake.resolution = *resolution;
  scene->bake.method = method;
  scene->bake.samples = samples;
  for (auto _ : state) {
    auto result = bake(*scene);
    if (!result) {
      state.SkipWithError(result.error().message.c_str());
      return;
    }
    state.SetIterationTime(result->bake_seconds);
  }
  state.SetLabel(method);
}

void BM_ParallelPlanes(benchmark::State& state) {
  time_bakes(state, "parallel/scene.toml", state.range(1) == 0 ? "backprojection" : "reference", 64,
             int(state.range(0)));
}
BENCHMARK(BM_ParallelPlanes)
    ->ArgsProduct({{512}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();

void BM_SunAt4096(benchmark::State& state) {
  const bool reference = state.range(0) == 1;
  time_bakes(state, "outdoor/scene_sun.toml", reference ? "reference" : "backprojection",
             reference ? 24 : 32);
}
BENCHMARK(BM_SunAt4096)
    ->Arg(0)
    ->Arg(1)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();

}  // namespace
}  // namespace sb
