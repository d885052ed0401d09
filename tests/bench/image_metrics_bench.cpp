// How long measuring a lightmap against its reference takes (src/evaluation/image_metrics.cpp):
// SSIM of one 2048² channel, and a whole three-channel comparison, on smooth deterministic
// patterns.
//
// Run: build/shadowbake_bench --benchmark_filter=Ssim\|Compare --benchmark_repetitions=5
//      --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>

#include "evaluation/image_metrics.h"

namespace sb {
namespace {

Image pattern(int size, int channels, double phase) {
  Image image(size, size, channels);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      for (int c = 0; c < channels; ++c)
        image.at(x, y)[c] = float(0.5 + 0.5 * std::sin(0.01 * x + 0.013 * y + phase + c));
  return image;
}

void BM_SsimMap(benchmark::State& state) {
  const int size = int(state.range(0));
  const Image a = pattern(size, 1, 0.0), b = pattern(size, 1, 0.1);
  for (auto _ : state) benchmark::DoNotOptimize(ssim_map(a, b, 0, 1.0).data());
}
BENCHMARK(BM_SsimMap)->Arg(512)->Arg(2048)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_CompareImages(benchmark::State& state) {
  const int size = int(state.range(0));
  const Image a = pattern(size, 3, 0.0), b = pattern(size, 3, 0.1);
  for (auto _ : state) {
    auto result = compare_images(a, b, {}, "a", "b");
    benchmark::DoNotOptimize(result.has_value());
  }
}
BENCHMARK(BM_CompareImages)->Arg(512)->Arg(2048)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace sb
