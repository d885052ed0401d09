// The convolution method's speed goals (issue: "The convolution method"): the whole bake of a
// 512² and a 2048² receiver under one light, time per stage, writing, and the reference method at
// 64 samples on the same scene for the speed-up. The scene is scenes/parallel (a 2 m floor, a
// parallel square blocker, a 0.5 m square light).
//
// Run: build/shadowbake_bench --benchmark_filter='Bake|Write' --benchmark_repetitions=5
//      --benchmark_report_aggregates_only=true
// Counters are milliseconds per iteration of each stage, from the bake's own report.
#include <benchmark/benchmark.h>
#include <fftw3.h>

#include <filesystem>
#include <memory>
#include <string>

#include "formats/outputs.h"
#include "methods/convolution/pair_report.h"
#include "pipeline/bake.h"

namespace sb {
namespace {

Scene parallel_scene(int resolution, const std::string& method, int samples) {
  auto scene = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/parallel/scene.toml");
  if (!scene) throw std::runtime_error(scene.error().message);
  scene->bake.resolution = resolution;
  scene->bake.method = method;
  scene->bake.samples = samples;
  return *scene;
}

void BM_ConvolutionBake(benchmark::State& state) {
  const Scene scene = parallel_scene(int(state.range(0)), "convolution", 1);
  double texels = 0, configure = 0, source = 0, blocker = 0, fft = 0, lookup = 0, dilate = 0;
  int fft_size = 0;
  for (auto _ : state) {
    auto result = bake(scene);
    if (!result) {
      state.SkipWithError(result.error().message.c_str());
      return;
    }
    const ReceiverBake& r = result->receivers[0];
    const PairReport& p = convolution_pairs(r.report.details)[0];
    texels += r.seconds_texels;
    dilate += r.seconds_dilate;
    configure += p.seconds_configure;
    source += p.seconds_source;
    blocker += p.seconds_blocker;
    fft += p.seconds_fft;
    lookup += p.seconds_lookup;
    fft_size = p.fft_width;
  }
  const double per_ms = 1e3 / double(state.iterations());
  state.counters["texels_ms"] = texels * per_ms;
  state.counters["configure_ms"] = configure * per_ms;
  state.counters["source_ms"] = source * per_ms;
  state.counters["blocker_ms"] = blocker * per_ms;
  state.counters["fft_ms"] = fft * per_ms;
  state.counters["lookup_ms"] = lookup * per_ms;
  state.counters["dilate_ms"] = dilate * per_ms;
  state.counters["fft_size"] = fft_size;
}
BENCHMARK(BM_ConvolutionBake)->Arg(512)->Arg(2048)->Unit(benchmark::kMillisecond)->UseRealTime();

// The floor under the FFT stage: one bare FFTW r2c + c2r of the padded size the bake above used
// (found by baking once before timing), planned as the convolver plans (FFTW_ESTIMATE, all
// cores), on arrays allocated once.
void BM_BareFftOfBake(benchmark::State& state) {
  const Scene scene = parallel_scene(int(state.range(0)), "convolution", 1);
  auto result = bake(scene);
  if (!result || convolution_pairs(result->receivers[0].report.details).empty()) {
    state.SkipWithError("bake failed");
    return;
  }
  const int w = convolution_pairs(result->receivers[0].report.details)[0].fft_width;
  const int h = convolution_pairs(result->receivers[0].report.details)[0].fft_height;
  const auto free = [](void* p) { fftwf_free(p); };
  std::unique_ptr<float, decltype(free)> real(fftwf_alloc_real(std::size_t(w) * h), free);
  std::unique_ptr<fftwf_complex, decltype(free)> spectrum(
      fftwf_alloc_complex(std::size_t(h) * (w / 2 + 1)), free);
  std::fill(real.get(), real.get() + std::size_t(w) * h, 0.5f);
  // bake() has set FFTW's thread count for this process; plans below inherit it.
  fftwf_plan forward = fftwf_plan_dft_r2c_2d(h, w, real.get(), spectrum.get(), FFTW_ESTIMATE);
  fftwf_plan inverse = fftwf_plan_dft_c2r_2d(h, w, spectrum.get(), real.get(), FFTW_ESTIMATE);
  for (auto _ : state) {
    fftwf_execute(forward);
    fftwf_execute(inverse);
    benchmark::DoNotOptimize(real.get());
  }
  fftwf_destroy_plan(forward);
  fftwf_destroy_plan(inverse);
  state.counters["fft_size"] = w;
}
BENCHMARK(BM_BareFftOfBake)->Arg(512)->Arg(2048)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ReferenceBake64(benchmark::State& state) {
  const Scene scene = parallel_scene(int(state.range(0)), "reference", 64);
  for (auto _ : state) {
    auto result = bake(scene);
    if (!result) {
      state.SkipWithError(result.error().message.c_str());
      return;
    }
    benchmark::DoNotOptimize(result->receivers[0].image.pixels.data());
  }
}
BENCHMARK(BM_ReferenceBake64)->Arg(512)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_WriteOutputs(benchmark::State& state) {
  const Scene scene = parallel_scene(int(state.range(0)), "convolution", 1);
  auto result = bake(scene);
  if (!result) {
    state.SkipWithError(result.error().message.c_str());
    return;
  }
  const auto dir = std::filesystem::temp_directory_path() / "shadowbake_bench_write";
  for (auto _ : state) {
    auto folder = OutputFolder::open(dir);
    if (!folder) {
      state.SkipWithError(folder.error().message.c_str());
      return;
    }
    auto written = write_outputs(*folder, scene, scene.bake, *result);
    if (!written) {
      state.SkipWithError(written.error().message.c_str());
      return;
    }
  }
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_WriteOutputs)->Arg(512)->Arg(2048)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace sb
