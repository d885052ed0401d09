// The hierarchy's speed goal (issue: "Clustering and error-driven subdivision"): the whole bake
// of each subdivision scene (scenes/table, scenes/posts, scenes/bracket; 512², every receiver)
// with the convolution at its defaults, beside the reference at 64 and 1024 samples, in one
// program run so that the ratios are measured side by side.
//
// Run: build/shadowbake_bench --benchmark_filter=Subdivision --benchmark_repetitions=5
//      --benchmark_report_aggregates_only=true
// (the 1024-sample reference takes several seconds a bake; add --benchmark_filter with
// 'Subdivision.*/(0|64)$' to leave it out). Counters: the convolution's leaf triples and worst
// penumbra error per receiver, from the bake's own report.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <string>

#include "methods/convolution/pair_report.h"
#include "pipeline/bake.h"

namespace sb {
namespace {

const char* const kScenes[] = {"table", "posts", "bracket"};

// samples 0: the convolution at its defaults; otherwise the reference with that many samples.
void BM_SubdivisionBake(benchmark::State& state) {
  const std::string name = kScenes[state.range(0)];
  auto scene = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/" + name + "/scene.toml");
  if (!scene) {
    state.SkipWithError(scene.error().message.c_str());
    return;
  }
  const int samples = int(state.range(1));
  scene->bake.method = samples == 0 ? "convolution" : "reference";
  if (samples > 0) scene->bake.samples = samples;
  double triples = 0, worst = 0;
  for (auto _ : state) {
    auto result = bake(*scene);
    if (!result) {
      state.SkipWithError(result.error().message.c_str());
      return;
    }
    triples = 0;
    for (const ReceiverBake& r : result->receivers) {
      for (const PairReport& p : convolution_pairs(r.report.details)) {
        triples += p.triples;
        worst = std::max(worst, p.penumbra_error_texels);
      }
    }
    benchmark::DoNotOptimize(result->receivers[0].image.pixels.data());
  }
  state.SetLabel(name + (samples == 0 ? " convolution" : " reference-" + std::to_string(samples)));
  if (samples == 0) {
    state.counters["leaves"] = triples;
    state.counters["worst_eps_texels"] = worst;
  }
}
BENCHMARK(BM_SubdivisionBake)
    ->ArgsProduct({{0, 1, 2}, {0, 64, 1024}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace sb
