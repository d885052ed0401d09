// The transforms the convolution runs on, behind an interface a bake owns: the planner asks its
// backend which transform sizes it will use and whether a transform runs threaded (what a leaf
// costs and how leaves are batched), and the executor convolves through it. FftConvolver
// (fft_convolution.h) is this build's backend, on FFTW; another (a GPU's, say) implements the
// same calls.
#pragma once

#include <memory>
#include <span>
#include <vector>

namespace sb {

// The spectrum of a kernel padded to a transform size, as a backend keeps it; shareable between
// threads. Each backend derives its own.
struct KernelSpectrum {
  virtual ~KernelSpectrum() = default;
  int tw = 0, th = 0;  // transform size, pixels
  int kw = 0, kh = 0;  // kernel size, pixels
};

class ConvolutionBackend {
 public:
  virtual ~ConvolutionBackend() = default;

  // The transform size the backend uses for an image n pixels wide (n or more).
  virtual int transform_size(int n) const = 0;

  // Whether a tw × th transform runs on several threads, so that callers run it alone rather than
  // beside others on their own threads.
  virtual bool threaded(int tw, int th) const = 0;

  // Spectrum of `kernel` (kw × kh floats, row-major, both odd; its centre pixel (kw/2, kh/2) is
  // the origin) for transforms of size tw × th (tw >= kw, th >= kh); may be cached.
  virtual std::shared_ptr<const KernelSpectrum> kernel_spectrum(const std::vector<float>& kernel,
                                                                int kw, int kh, int tw, int th) = 0;

  // out(x, y) = Σ_u kernel(u) · image((x, y) − u), with the image taken as 0 outside its
  // w × h pixels, for the whole w × h output, in a transform of the spectra's size (at least
  // w × h; values within the kernel's radius of the transform's border may wrap around, so
  // callers pad). The image is transformed once for all kernels, which share one transform size;
  // outs[i] gets kernels[i]'s result, resized to w·h. Thread-safe.
  virtual void convolve(const std::vector<float>& image, int w, int h,
                        std::span<const KernelSpectrum* const> kernels,
                        std::span<std::vector<float>* const> outs) = 0;

  // One kernel.
  void convolve(const std::vector<float>& image, int w, int h, const KernelSpectrum& kernel,
                std::vector<float>& out) {
    const KernelSpectrum* kernels[1] = {&kernel};
    std::vector<float>* outs[1] = {&out};
    convolve(image, w, h, kernels, outs);
  }
};

}  // namespace sb
