// Benchmarks of the FFT convolution (src/methods/convolution/fft_convolution.cpp) against its
// floor: one bare FFTW r2c + c2r round trip of the same size, planned with FFTW_ESTIMATE (what the
// convolver uses) and with FFTW_MEASURE (what a long-running program could afford). Convolve adds
// the padding copy, the spectrum product and the output copy to the round trip; the aim is to stay
// within 2× of the ESTIMATE round trip.
//
// Run: shadowbake_bench --benchmark_filter=Fft\|Convolve --benchmark_repetitions=5
//      --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <fftw3.h>

#include <algorithm>
#include <cstddef>
#include <map>
#include <memory>
#include <random>
#include <thread>
#include <utility>
#include <vector>

#include "methods/convolution/fft_convolution.h"

namespace sb {
namespace {

struct FftwFree {
  void operator()(void* p) const { fftwf_free(p); }
};

std::vector<float> random_values(std::size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  std::vector<float> values(count);
  for (float& v : values) v = uniform(rng);
  return values;
}

int default_threads() { return std::max(1, int(std::thread::hardware_concurrency())); }

struct RoundTripPlans {
  fftwf_plan forward, inverse;
};

// Plans for an n × n round trip, made once per (n, flags) for the whole run: Google Benchmark
// calls a benchmark function several times, and FFTW_MEASURE planning takes seconds.
const RoundTripPlans& round_trip_plans(int n, unsigned flags) {
  static std::map<std::pair<int, unsigned>, RoundTripPlans> cache;
  auto found = cache.find({n, flags});
  if (found != cache.end()) return found->second;
  FftConvolver init;  // runs fftwf_init_threads() before this first planner call
  fftwf_plan_with_nthreads(default_threads());  // as many threads as the convolver's default
  const std::size_t reals = std::size_t(n) * std::size_t(n);
  const std::size_t complexes = std::size_t(n) * std::size_t(n / 2 + 1);
  std::unique_ptr<float[], FftwFree> real(fftwf_alloc_real(reals));
  std::unique_ptr<fftwf_complex[], FftwFree> spectrum(fftwf_alloc_complex(complexes));
  RoundTripPlans plans{
      fftwf_plan_dft_r2c_2d(n, n, real.get(), spectrum.get(), flags),
      fftwf_plan_dft_c2r_2d(n, n, spectrum.get(), real.get(), flags),
  };
  // Wisdom of a measured plan is reused by later FFTW_ESTIMATE planning of the same size (FFTW
  // takes plans found with more patience); forget it so the ESTIMATE figures, and the
  // convolver's own plans made later in this process, stay what a fresh bake gets.
  fftwf_forget_wisdom();
  return cache.emplace(std::pair{n, flags}, plans).first->second;
}

// One r2c + c2r of n × n floats on preallocated fftwf_malloc'd arrays (the plans' alignment).
// The inverse writes to a second real array so the input is never scaled by n² round after
// round.
void round_trip(benchmark::State& state, unsigned flags) {
  const int n = int(state.range(0));
  const RoundTripPlans& plans = round_trip_plans(n, flags);
  const std::size_t reals = std::size_t(n) * std::size_t(n);
  const std::size_t complexes = std::size_t(n) * std::size_t(n / 2 + 1);
  std::unique_ptr<float[], FftwFree> input(fftwf_alloc_real(reals));
  std::unique_ptr<float[], FftwFree> output(fftwf_alloc_real(reals));
  std::unique_ptr<fftwf_complex[], FftwFree> spectrum(fftwf_alloc_complex(complexes));
  const std::vector<float> values = random_values(reals, 1);
  std::copy(values.begin(), values.end(), input.get());
  for (auto _ : state) {
    fftwf_execute_dft_r2c(plans.forward, input.get(), spectrum.get());
    fftwf_execute_dft_c2r(plans.inverse, spectrum.get(), output.get());
    benchmark::DoNotOptimize(output.get());
    benchmark::ClobberMemory();
  }
  state.counters["threads"] = double(default_threads());
}

void BM_BareFftRoundTrip(benchmark::State& state) { round_trip(state, FFTW_ESTIMATE); }
void BM_BareFftRoundTripMeasure(benchmark::State& state) { round_trip(state, FFTW_MEASURE); }

// FftConvolver::convolve of an n × n image in an n × n transform with a 65 × 65
// kernel whose spectrum is cached (made before the timing loop, as a bake reuses one per light).
void BM_Convolve(benchmark::State& state) {
  const int n = int(state.range(0)), kernel_size = 65;
  FftConvolver convolver;
  const std::vector<float> kernel =
      random_values(std::size_t(kernel_size) * std::size_t(kernel_size), 2);
  const auto spectrum = convolver.kernel_spectrum(kernel, kernel_size, kernel_size, n, n);
  const std::vector<float> image = random_values(std::size_t(n) * std::size_t(n), 3);
  std::vector<float> out;
  for (auto _ : state) {
    convolver.convolve(image, n, n, *spectrum, out);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.counters["threads"] = double(default_threads());
}

// 576 = 512 + 65 − 1 = 2^6 · 3^2 (a 512² blocker image padded for a 65² kernel) and its doubles,
// beside the powers of two.
void fft_sizes(benchmark::internal::Benchmark* b) {
  for (const int n : {576, 1024, 1152, 2048, 2304, 4096}) b->Arg(n);
  b->Unit(benchmark::kMillisecond)->UseRealTime();
}

BENCHMARK(BM_BareFftRoundTrip)->Apply(fft_sizes);
BENCHMARK(BM_BareFftRoundTripMeasure)->Apply(fft_sizes);
BENCHMARK(BM_Convolve)->Apply(fft_sizes);

}  // namespace
}  // namespace sb
