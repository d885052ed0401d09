// FFT convolution of a blocker image with a source kernel (docs/design.md §2: the occluded
// fraction is the scaled, mirrored source image convolved with the blocker image). Computes
// out(x) = Σ_u K(u) · image(x − u) as the product of two spectra, with FFTW's single-precision
// real-to-complex and complex-to-real 2D transforms (Frigo & Johnson, "The Design and
// Implementation of FFTW3", Proc. IEEE 93(2), 2005). Beyond the transform size the product is
// circular; callers pad to get the linear convolution (see fft_convolution.h).
//
// Threading: FFTW's planner is process-global and not thread-safe, so plans are made once per
// (tw, th, FFTW threads) and convolver under a mutex shared by all convolvers, and cached;
// execution is thread-safe, so convolve() runs the cached plans through the new-array interface on
// the calling thread's own arrays. Those come from fftwf_malloc, like the arrays the plans were
// made on, because a plan may only be executed on arrays with the alignment it was planned for.
#include "methods/convolution/fft_convolution.h"

#include <fftw3.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <thread>
#include <vector>

#include "core/error.h"

namespace sb {
namespace {

struct FftwFree {
  void operator()(void* p) const { fftwf_free(p); }
};
using RealBuffer = std::unique_ptr<float[], FftwFree>;
using ComplexBuffer = std::unique_ptr<fftwf_complex[], FftwFree>;

RealBuffer alloc_real(std::size_t count) {
  RealBuffer buffer(fftwf_alloc_real(count));
  if (!buffer) throw std::bad_alloc();
  return buffer;
}

ComplexBuffer alloc_complex(std::size_t count) {
  ComplexBuffer buffer(fftwf_alloc_complex(count));
  if (!buffer) throw std::bad_alloc();
  return buffer;
}

// Complex values of a real transform of tw × th: FFTW keeps only the tw/2 + 1 non-redundant
// columns of the Hermitian-symmetric spectrum.
std::size_t spectrum_count(int tw, int th) { return std::size_t(th) * std::size_t(tw / 2 + 1); }

std::uint64_t hash_values(const std::vector<float>& values) {
  // FNV-1a over the bytes: the cache compares values bytewise too, so -0/+0 and NaNs are
  // consistent between the hash and the compare.
  std::uint64_t hash = 14695981039346656037ull;
  const auto* bytes = reinterpret_cast<const unsigned char*>(values.data());
  for (std::size_t i = 0; i < values.size() * sizeof(float); ++i) {
    hash ^= bytes[i];
    hash *= 1099511628211ull;
  }
  return hash;
}

// Work arrays of the calling thread for convolve(), kept between calls and grown as needed:
// allocating them per call (tens of MiB, fresh pages) made a 2304² convolution cost twice the
// bare transforms in tests/bench/fft_bench.cpp, against 1.2× with reuse. Each thread keeps the
// largest pair it has needed until it ends.
struct Scratch {
  RealBuffer real;
  ComplexBuffer spectrum;
  std::size_t real_count = 0, spectrum_count = 0;
};

Scratch& thread_scratch(std::size_t real_count, std::size_t complex_count) {
  thread_local Scratch scratch;
  if (scratch.real_count < real_count) {
    scratch.real.reset();  // before allocating, so the old and new arrays are never both held
    scratch.real = alloc_real(real_count);
    scratch.real_count = real_count;
  }
  if (scratch.spectrum_count < complex_count) {
    scratch.spectrum.reset();
    scratch.spectrum = alloc_complex(complex_count);
    scratch.spectrum_count = complex_count;
  }
  return scratch;
}

// The cache keeps at most this many spectra, and at most this many bytes of them (a 4096²
// spectrum is 64 MiB); the least recently used go first. Callers hold the spectra they use
// through shared_ptr, so eviction only costs a recomputation.
constexpr std::size_t kMaxCachedSpectra = 64;
constexpr std::size_t kMaxCachedSpectrumBytes = std::size_t(512) << 20;

// FFTW's planner (and plan destruction) is process-global state: one lock for every convolver.
std::mutex& fftw_planner_mutex() {
  static std::mutex mutex;
  return mutex;
}

struct FftwSpectrum final : KernelSpectrum {
  std::uint64_t hash = 0;
  std::vector<float> kernel;  // the kernel's values, for the full compare on a hash hit
  ComplexBuffer values;       // spectrum_count(tw, th) values, already scaled by 1 / (tw·th)

  std::size_t bytes() const { return spectrum_count(tw, th) * sizeof(fftwf_complex); }
};

}  // namespace

struct FftConvolver::Impl {
  struct PlanKey {
    int tw, th, threads;
    auto operator<=>(const PlanKey&) const = default;
  };
  struct Plans {
    fftwf_plan forward = nullptr;  // r2c, tw × th reals → th × (tw/2 + 1) complex
    fftwf_plan inverse = nullptr;  // c2r, unnormalised
  };

  const FftConvolver* owner = nullptr;
  std::atomic<int> threads{1};

  std::map<PlanKey, Plans> plans;  // guarded by fftw_planner_mutex()

  std::mutex spectra_mutex;  // guards `spectra` and `spectra_bytes`
  // Most recently used first.
  std::list<std::shared_ptr<const FftwSpectrum>> spectra;
  std::size_t spectra_bytes = 0;

  // The plans for a tw × th transform with the current thread count. The reference stays valid:
  // std::map nodes do not move, and plans are destroyed only with the convolver.
  const Plans& plans_for(int tw, int th) {
    const PlanKey key{tw, th, owner->threaded(tw, th) ? threads.load() : 1};
    std::lock_guard lock(fftw_planner_mutex());
    auto found = plans.find(key);
    if (found != plans.end()) return found->second;
    // FFTW_ESTIMATE: a bake is one run of a command-line tool, and FFTW_MEASURE's planning (it
    // runs and times candidate plans) cannot pay for itself there. Measured on 2 cores: planning
    // an r2c + c2r pair takes ~4 ms with ESTIMATE, ~1.0 s (1024²) and ~1.9 s (2048²) with
    // MEASURE, whose plans save ~2 ms and ~10 ms per round trip: hundreds of convolutions of one
    // size before it breaks even (tests/bench/fft_bench.cpp). Saved wisdom would change that.
    fftwf_plan_with_nthreads(key.threads);
    RealBuffer real = alloc_real(std::size_t(tw) * std::size_t(th));
    ComplexBuffer complex = alloc_complex(spectrum_count(tw, th));
    Plans made;
    made.forward = fftwf_plan_dft_r2c_2d(th, tw, real.get(), complex.get(), FFTW_ESTIMATE);
    made.inverse = fftwf_plan_dft_c2r_2d(th, tw, complex.get(), real.get(), FFTW_ESTIMATE);
    assert(made.forward && made.inverse);
    return plans.emplace(key, made).first->second;
  }

  // A cached spectrum equal to the request, moved to the front of the list; null if none.
  std::shared_ptr<const FftwSpectrum> find_spectrum(const std::vector<float>& kernel, int kw,
                                                    int kh, int tw, int th, std::uint64_t hash) {
    for (auto it = spectra.begin(); it != spectra.end(); ++it) {
      const FftwSpectrum& s = **it;
      if (s.hash != hash || s.tw != tw || s.th != th || s.kw != kw || s.kh != kh) continue;
      if (std::memcmp(s.kernel.data(), kernel.data(), kernel.size() * sizeof(float)) != 0) continue;
      spectra.splice(spectra.begin(), spectra, it);
      return spectra.front();
    }
    return nullptr;
  }

  ~Impl() {
    std::lock_guard lock(fftw_planner_mutex());
    for (auto& [key, made] : plans) {
      fftwf_destroy_plan(made.forward);
      fftwf_destroy_plan(made.inverse);
    }
  }
};

FftConvolver::FftConvolver() : impl_(std::make_unique<Impl>()) {
  {
    // Must come before the first planner call; later calls are no-ops in FFTW 3.3.
    std::lock_guard lock(fftw_planner_mutex());
    [[maybe_unused]] const int initialised = fftwf_init_threads();
    assert(initialised);
  }
  impl_->owner = this;
  impl_->threads = std::max(1, int(std::thread::hardware_concurrency()));
}

FftConvolver::~FftConvolver() = default;

void FftConvolver::set_threads(int threads) {
  assert(threads >= 1);
  impl_->threads = threads;
}

int FftConvolver::fast_size(int n) {
  if (n <= 1) return 1;
  for (int candidate = n;; ++candidate) {
    int rest = candidate;
    for (const int factor : {2, 3, 5, 7})
      while (rest % factor == 0) rest /= factor;
    if (rest == 1) return candidate;
  }
}

int FftConvolver::transform_size(int n) const {
  if (n <= 8) return 8;
  if (n <= 64) {
    int octave = 2;
    while (6 * octave < n) octave *= 2;
    return 4 * octave >= n ? 4 * octave : 6 * octave;
  }
  int octave = 16;  // 2^a with 4·2^a >= 64
  while (7 * octave < n) octave *= 2;
  for (const int step : {4, 5, 6, 7})
    if (step * octave >= n) return step * octave;
  return 8 * octave;  // unreachable: 7·octave >= n
}

bool FftConvolver::threaded(int tw, int th) const {
  constexpr std::int64_t kThreadedPoints = 400 * 400;
  return std::int64_t(tw) * std::int64_t(th) >= kThreadedPoints;
}

std::shared_ptr<const KernelSpectrum> FftConvolver::kernel_spectrum(
    const std::vector<float>& kernel, int kw, int kh, int tw, int th) {
  SB_CHECK(kw >= 1 && kh >= 1 && kw % 2 == 1 && kh % 2 == 1);
  SB_CHECK(kernel.size() == std::size_t(kw) * std::size_t(kh));
  // The kernel's pixels wrap around the transform: one wider than it would write before it.
  SB_CHECK(tw >= kw && th >= kh);
  const std::uint64_t hash = hash_values(kernel);
  {
    std::lock_guard lock(impl_->spectra_mutex);
    if (auto cached = impl_->find_spectrum(kernel, kw, kh, tw, th, hash)) return cached;
  }

  // Transform outside the cache lock, so other threads' lookups do not wait for it.
  auto spectrum = std::make_shared<FftwSpectrum>();
  spectrum->tw = tw;
  spectrum->th = th;
  spectrum->kw = kw;
  spectrum->kh = kh;
  spectrum->hash = hash;
  spectrum->kernel = kernel;
  spectrum->values = alloc_complex(spectrum_count(tw, th));

  // The kernel's centre goes to (0, 0), the rest wraps around, so that the product of spectra
  // gives Σ_u K(u) image(x − u) with u relative to the centre. tw >= kw keeps pixels distinct.
  RealBuffer padded = alloc_real(std::size_t(tw) * std::size_t(th));
  std::fill_n(padded.get(), std::size_t(tw) * std::size_t(th), 0.0f);
  for (int j = 0; j < kh; ++j) {
    const int y = (j - kh / 2 + th) % th;
    for (int i = 0; i < kw; ++i) {
      const int x = (i - kw / 2 + tw) % tw;
      padded[std::size_t(y) * std::size_t(tw) + std::size_t(x)] =
          kernel[std::size_t(j) * std::size_t(kw) + std::size_t(i)];
    }
  }
  const Impl::Plans& plans = impl_->plans_for(tw, th);
  fftwf_execute_dft_r2c(plans.forward, padded.get(), spectrum->values.get());
  // FFTW's transforms are unnormalised: the round trip multiplies by tw·th. Folding the inverse
  // into the spectrum, computed once, saves a pass over every convolution's output.
  const float scale = 1.0f / (float(tw) * float(th));
  float* values = &spectrum->values[0][0];
  for (std::size_t i = 0; i < 2 * spectrum_count(tw, th); ++i) values[i] *= scale;

  std::lock_guard lock(impl_->spectra_mutex);
  // Another thread may have made the same spectrum meanwhile; keep one.
  if (auto cached = impl_->find_spectrum(kernel, kw, kh, tw, th, hash)) return cached;
  impl_->spectra.push_front(spectrum);
  impl_->spectra_bytes += spectrum->bytes();
  while (impl_->spectra.size() > 1 && (impl_->spectra.size() > kMaxCachedSpectra ||
                                       impl_->spectra_bytes > kMaxCachedSpectrumBytes)) {
    impl_->spectra_bytes -= impl_->spectra.back()->bytes();
    impl_->spectra.pop_back();
  }
  return spectrum;
}

void FftConvolver::convolve(const std::vector<float>& image, int w, int h,
                            std::span<const KernelSpectrum* const> kernels,
                            std::span<std::vector<float>* const> outs) {
  SB_CHECK(w >= 1 && h >= 1);
  SB_CHECK(image.size() == std::size_t(w) * std::size_t(h));
  SB_CHECK(!kernels.empty() && kernels.size() == outs.size());
  const int tw = kernels[0]->tw, th = kernels[0]->th;
  SB_CHECK(std::all_of(kernels.begin(), kernels.end(),
                       [&](const KernelSpectrum* k) { return k->tw == tw && k->th == th; }));
  SB_CHECK(tw >= w && th >= h);
  const std::size_t row = std::size_t(tw);
  const std::size_t count = spectrum_count(tw, th);
  const Impl::Plans& plans = impl_->plans_for(tw, th);

  // With several kernels the image's spectrum is kept aside and each product made in `product`,
  // which starts 64 bytes aligned like the arrays the plans were made for (FFTW's new-array
  // execute requires the planned alignment).
  const std::size_t offset = (count + 7) / 8 * 8;
  Scratch& scratch =
      thread_scratch(row * std::size_t(th), kernels.size() > 1 ? offset + count : count);
  float* padded = scratch.real.get();
  fftwf_complex* spectrum = scratch.spectrum.get();
  fftwf_complex* product = kernels.size() > 1 ? spectrum + offset : spectrum;
  // The image top-left, zeros around it; the scratch holds the previous call's output, so every
  // padding pixel is written.
  for (int y = 0; y < h; ++y) {
    float* dst = padded + std::size_t(y) * row;
    std::copy_n(image.data() + std::size_t(y) * std::size_t(w), w, dst);
    std::fill(dst + w, dst + tw, 0.0f);
  }
  std::fill(padded + std::size_t(h) * row, padded + std::size_t(th) * row, 0.0f);

  fftwf_execute_dft_r2c(plans.forward, padded, spectrum);
  for (std::size_t k = 0; k < kernels.size(); ++k) {
    // Pointwise complex product, on interleaved (re, im) floats so the compiler vectorises it.
    const float* a = &spectrum[0][0];
    // Every spectrum a caller holds came from this class's kernel_spectrum.
    const float* b = &static_cast<const FftwSpectrum*>(kernels[k])->values[0][0];
    float* p = &product[0][0];
    for (std::size_t i = 0; i < 2 * count; i += 2) {
      const float re = a[i] * b[i] - a[i + 1] * b[i + 1];
      const float im = a[i] * b[i + 1] + a[i + 1] * b[i];
      p[i] = re;
      p[i + 1] = im;
    }
    // The c2r transform overwrites its input: `product`, never the kept spectrum.
    fftwf_execute_dft_c2r(plans.inverse, product, padded);
    std::vector<float>& out = *outs[k];
    out.resize(std::size_t(w) * std::size_t(h));
    for (int y = 0; y < h; ++y)
      std::copy_n(padded + std::size_t(y) * row, w, out.data() + std::size_t(y) * std::size_t(w));
  }
}

}  // namespace sb
