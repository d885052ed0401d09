// Linear 2D convolution of a blocker image with a source kernel through FFTW's real transforms
// (single precision). docs/design.md §2: the occluded fraction is the source image, scaled and
// mirrored, convolved with the blocker image; the FFT turns that into a pointwise product of
// spectra. FFTW's types stay in fft_convolution.cpp.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "methods/convolution/convolution_backend.h"

namespace sb {

class FftConvolver final : public ConvolutionBackend {
 public:
  // A convolver of its own: plans are created once per transform size and reused by every
  // receiver and light it serves (FFTW's planner is process-global and not thread-safe; every
  // convolver serialises its calls to it through one lock, and plans are then executed from any
  // thread on fresh arrays). Kernel spectra are cached per convolver.
  FftConvolver();

  // The smallest size >= n whose prime factors are all 2, 3, 5 or 7 (sizes FFTW is fast at).
  static int fast_size(int n);

  // At least 8, then the smallest of 2^a · {4, 6} / 4 >= n up to 64 (at most 50 % padding), and
  // of 2^a · {4, 5, 6, 7} / 4 beyond (at most 25 %). A few sizes per octave let the many images of
  // a bake share FFTW plans, whose making (0.5–4 ms a pair) costs more than the transforms of a
  // ~300² image (0.4 ms a round trip; tests/bench/fft_bench.cpp); below 64 pixels a transform
  // costs microseconds, and sharing plans matters more than padding.
  int transform_size(int n) const override;

  // Transforms of 400² or more run on set_threads() FFTW threads, smaller ones on one: two
  // threads slow transforms below ~400² down on 2 cores (fft_bench).
  bool threaded(int tw, int th) const override;

  std::shared_ptr<const KernelSpectrum> kernel_spectrum(const std::vector<float>& kernel, int kw,
                                                        int kh, int tw, int th) override;

  using ConvolutionBackend::convolve;
  void convolve(const std::vector<float>& image, int w, int h,
                std::span<const KernelSpectrum* const> kernels,
                std::span<std::vector<float>* const> outs) override;

  // Number of FFTW threads used for one threaded() transform (default: all cores). Call before
  // convolving.
  void set_threads(int threads);

  FftConvolver(const FftConvolver&) = delete;
  FftConvolver& operator=(const FftConvolver&) = delete;
  ~FftConvolver() override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sb
