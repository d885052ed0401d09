// Linear 2D convolution of a blocker image with a source kernel through FFTW's real transforms
// (single precision). design-notes §2: the occluded fraction is the source image, scaled and
// mirrored, convolved with the blocker image; the FFT turns that into a pointwise product of
// spectra. FFTW's types stay in fft_convolution.cpp.
#pragma once

#include <memory>
#include <span>
#include <vector>

namespace sb {

// The spectrum of a kernel padded to a transform size; opaque, shareable between threads.
struct KernelSpectrum;

class FftConvolver {
 public:
  // The process-wide instance: plans are created once per transform size and reused by every
  // receiver and light (FFTW's planner is not thread-safe; this class serialises it, and the
  // plans are then executed from any thread on fresh arrays).
  static FftConvolver& shared();

  // The smallest size >= n whose prime factors are all 2, 3, 5 or 7 (sizes FFTW is fast at).
  static int fast_size(int n);

  // The transform size for an image n pixels wide: at least 8, then the smallest of
  // 2^a · {4, 6} / 4 >= n up to 64 (at most 50 % padding), and of 2^a · {4, 5, 6, 7} / 4 beyond
  // (at most 25 %). A few sizes per octave let the many images of a bake share FFTW plans, whose
  // making (0.5–4 ms a pair) costs more than the transforms of a ~300² image (0.4 ms a round
  // trip; tests/bench/fft_bench.cpp); below 64 pixels a transform costs microseconds, and sharing
  // plans matters more than padding.
  static int transform_size(int n);

  // Whether a tw × th transform runs on several FFTW threads (set_threads) or on one: two
  // threads slow transforms below ~400² down on 2 cores (fft_bench), so those run on one, and
  // callers may run several such convolutions at once on their own threads.
  static bool threaded(int tw, int th);

  // Spectrum of `kernel` (kw × kh floats, row-major, both odd; its centre pixel (kw/2, kh/2) is
  // the origin) for transforms of size tw × th (tw >= kw, th >= kh). Cached: a second call with
  // the same kernel values and sizes returns the same spectrum without transforming again.
  std::shared_ptr<const KernelSpectrum> kernel_spectrum(const std::vector<float>& kernel, int kw,
                                                        int kh, int tw, int th);

  // out(x, y) = Σ_u kernel(u) · image((x, y) − u), with the image taken as 0 outside its
  // w × h pixels, for the whole w × h output. Uses a transform of the spectrum's size, which must
  // be at least w × h: values within (kw−1)/2, (kh−1)/2 of the border of a tw × th transform may
  // wrap around, so callers that need exact values everywhere make tw >= w + kw − 1 (and
  // likewise th), and callers that pad their image by the kernel radius use the interior only.
  // `out` is resized to w·h.
  void convolve(const std::vector<float>& image, int w, int h, const KernelSpectrum& kernel,
                std::vector<float>& out);

  // The same image convolved with several kernels of one transform size: the image is
  // transformed once, then multiplied and transformed back per kernel (a leaf's occlusion and
  // its two moments cost 4 transforms instead of 6). outs[i] gets kernels[i]'s result.
  void convolve(const std::vector<float>& image, int w, int h,
                std::span<const KernelSpectrum* const> kernels,
                std::span<std::vector<float>* const> outs);

  // Number of FFTW threads used for one threaded() transform (default: all cores). Call before
  // baking.
  void set_threads(int threads);

  FftConvolver(const FftConvolver&) = delete;
  FftConvolver& operator=(const FftConvolver&) = delete;
  ~FftConvolver();

 private:
  FftConvolver();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sb
