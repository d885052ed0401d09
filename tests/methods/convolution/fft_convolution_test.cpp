// Tests of FftConvolver (src/methods/convolution/fft_convolution.cpp) against a direct convolution:
// linear with enough padding, circular at the border without it, the kernel's centre and direction,
// the spectrum cache, fast transform sizes, and calls from several threads at once.
#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <random>
#include <set>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include "methods/convolution/fft_convolution.h"

namespace sb {
namespace {

std::vector<float> random_values(std::size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  std::vector<float> values(count);
  for (float& v : values) v = uniform(rng);
  return values;
}

float kernel_sum(const std::vector<float>& kernel) {
  double sum = 0.0;
  for (const float v : kernel) sum += std::abs(v);
  return float(sum);
}

// out(x, y) = Σ_u kernel(u) · image((x, y) − u), u relative to the kernel's centre. The image is
// 0 outside its pixels, or, with `wrap_w` × `wrap_h` > 0, repeats with that period (the circular
// convolution of a transform of that size, image zero-padded to it).
std::vector<float> direct_convolution(const std::vector<float>& image, int w, int h,
                                      const std::vector<float>& kernel, int kw, int kh,
                                      int wrap_w = 0, int wrap_h = 0) {
  std::vector<float> out(std::size_t(w) * std::size_t(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double sum = 0.0;
      for (int j = 0; j < kh; ++j)
        for (int i = 0; i < kw; ++i) {
          int sx = x - (i - kw / 2), sy = y - (j - kh / 2);
          if (wrap_w > 0) {
            sx = (sx % wrap_w + wrap_w) % wrap_w;
            sy = (sy % wrap_h + wrap_h) % wrap_h;
          }
          if (sx < 0 || sy < 0 || sx >= w || sy >= h) continue;
          sum += double(kernel[std::size_t(j) * std::size_t(kw) + std::size_t(i)]) *
                 double(image[std::size_t(sy) * std::size_t(w) + std::size_t(sx)]);
        }
      out[std::size_t(y) * std::size_t(w) + std::size_t(x)] = float(sum);
    }
  return out;
}

std::vector<float> fft_convolution(const std::vector<float>& image, int w, int h,
                                   const std::vector<float>& kernel, int kw, int kh, int tw, int th,
                                   int threads = 0) {
  FftConvolver convolver;
  if (threads > 0) convolver.set_threads(threads);
  const auto spectrum = convolver.kernel_spectrum(kernel, kw, kh, tw, th);
  std::vector<float> out;
  convolver.convolve(image, w, h, *spectrum, out);
  return out;
}

TEST(FftConvolution, PaddedTransformMatchesDirectConvolutionEverywhere) {
  const int w = 37, h = 23, kw = 5, kh = 7;
  const std::vector<float> image = random_values(std::size_t(w) * std::size_t(h), 1);
  const std::vector<float> kernel = random_values(std::size_t(kw) * std::size_t(kh), 2);
  const float tolerance = 1e-5f * kernel_sum(kernel);
  const std::vector<float> expected = direct_convolution(image, w, h, kernel, kw, kh);
  // A fast size, and the smallest exact one (41 × 29: both prime, FFTW's slow path).
  for (const auto& [tw, th] :
       {std::pair{FftConvolver::fast_size(w + kw - 1), FftConvolver::fast_size(h + kh - 1)},
        std::pair{w + kw - 1, h + kh - 1}}) {
    SCOPED_TRACE(testing::Message() << "transform " << tw << " x " << th);
    const std::vector<float> out = fft_convolution(image, w, h, kernel, kw, kh, tw, th);
    ASSERT_EQ(out.size(), expected.size());
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
        ASSERT_NEAR(out[i], expected[i], tolerance) << "at (" << x << ", " << y << ")";
      }
  }
}

TEST(FftConvolution, SeveralKernelsShareOneImageTransform) {
  // Three kernels against one image, at transform sizes whose spectra hold an odd number of
  // complex values ((31/2 + 1) x 41 = 656 is even, (33/2 + 1) x 29 = 493 odd), so that the kept
  // spectrum and the product would be misaligned without the rounding in convolve().
  const int w = 25, h = 21, kw = 5, kh = 7;
  const std::vector<float> image = random_values(std::size_t(w) * std::size_t(h), 11);
  FftConvolver convolver;
  for (const auto& [tw, th] : {std::pair{31, 41}, std::pair{33, 29}}) {
    SCOPED_TRACE(testing::Message() << "transform " << tw << " x " << th);
    std::vector<std::vector<float>> kernels, expected;
    std::vector<std::shared_ptr<const KernelSpectrum>> spectra;
    std::vector<const KernelSpectrum*> pointers;
    for (unsigned seed = 12; seed < 15; ++seed) {
      kernels.push_back(random_values(std::size_t(kw) * std::size_t(kh), seed));
      expected.push_back(direct_convolution(image, w, h, kernels.back(), kw, kh));
      spectra.push_back(convolver.kernel_spectrum(kernels.back(), kw, kh, tw, th));
      pointers.push_back(spectra.back().get());
    }
    std::vector<std::vector<float>> outs(3);
    std::vector<std::vector<float>*> out_pointers = {&outs[0], &outs[1], &outs[2]};
    convolver.convolve(image, w, h, pointers, out_pointers);
    for (std::size_t k = 0; k < 3; ++k) {
      ASSERT_EQ(outs[k].size(), expected[k].size());
      const float tolerance = 1e-5f * kernel_sum(kernels[k]);
      for (std::size_t i = 0; i < outs[k].size(); ++i)
        ASSERT_NEAR(outs[k][i], expected[k][i], tolerance) << "kernel " << k << ", pixel " << i;
    }
  }
}

TEST(FftConvolution, UnpaddedTransformIsExactInInteriorAndWrapsAtBorder) {
  const int w = 37, h = 23, kw = 5, kh = 7;
  const std::vector<float> image = random_values(std::size_t(w) * std::size_t(h), 3);
  const std::vector<float> kernel = random_values(std::size_t(kw) * std::size_t(kh), 4);
  const float tolerance = 1e-5f * kernel_sum(kernel);
  const std::vector<float> linear = direct_convolution(image, w, h, kernel, kw, kh);
  const std::vector<float> circular = direct_convolution(image, w, h, kernel, kw, kh, w, h);
  const std::vector<float> out = fft_convolution(image, w, h, kernel, kw, kh, w, h);
  ASSERT_EQ(out.size(), linear.size());
  float largest_wrap = 0.0f;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
      ASSERT_NEAR(out[i], circular[i], tolerance) << "at (" << x << ", " << y << ")";
      const bool interior = x >= kw / 2 && x < w - kw / 2 && y >= kh / 2 && y < h - kh / 2;
      if (interior) {
        ASSERT_NEAR(out[i], linear[i], tolerance) << "at (" << x << ", " << y << ")";
      }
      largest_wrap = std::max(largest_wrap, std::abs(out[i] - linear[i]));
    }
  EXPECT_GT(largest_wrap, 0.1f) << "the border should show the wrapped-around image";
}

// The atrium's wall sconce made a 63-pixel kernel for a 24-pixel window transform, and
// kernel_spectrum wrote before its buffer (the index i - kw/2 + tw went negative; the assert that
// guarded it is compiled out of release builds). The check holds in every build now.
TEST(FftConvolution, KernelWiderThanTransformIsRefusedNotWrittenPast) {
  FftConvolver convolver;
  const std::vector<float> kernel(63 * 9, 1.0f / (63 * 9));
  EXPECT_THROW(convolver.kernel_spectrum(kernel, 63, 9, 24, 16), std::logic_error);
  EXPECT_THROW(convolver.kernel_spectrum(kernel, 9, 63, 16, 24), std::logic_error);
  // A kernel that fits is fine, and so is an image no larger than the transform.
  const auto fits = convolver.kernel_spectrum(kernel, 63, 9, 64, 16);
  std::vector<float> out;
  EXPECT_NO_THROW(convolver.convolve(std::vector<float>(64 * 16, 1.0f), 64, 16, *fits, out));
  EXPECT_THROW(convolver.convolve(std::vector<float>(65 * 16, 1.0f), 65, 16, *fits, out),
               std::logic_error);
}

TEST(FftConvolution, IdentityKernelReturnsImage) {
  const int w = 37, h = 23;
  const std::vector<float> image = random_values(std::size_t(w) * std::size_t(h), 5);
  for (const auto& [tw, th] : {std::pair{w, h}, std::pair{40, 24}}) {
    const std::vector<float> out = fft_convolution(image, w, h, {1.0f}, 1, 1, tw, th);
    ASSERT_EQ(out.size(), image.size());
    for (std::size_t i = 0; i < image.size(); ++i) ASSERT_NEAR(out[i], image[i], 1e-5f);
  }
}

TEST(FftConvolution, ShiftedDeltaKernelShiftsImageByItsOffset) {
  // A delta at offset u = (+2, −1) from the kernel's centre: out(x) = image(x − u), so content
  // moves right by 2 and up (towards smaller y) by 1.
  const int w = 37, h = 23, kw = 5, kh = 5, ux = 2, uy = -1;
  std::vector<float> kernel(std::size_t(kw) * std::size_t(kh), 0.0f);
  kernel[std::size_t(kh / 2 + uy) * std::size_t(kw) + std::size_t(kw / 2 + ux)] = 1.0f;
  const std::vector<float> image = random_values(std::size_t(w) * std::size_t(h), 6);
  const std::vector<float> out =
      fft_convolution(image, w, h, kernel, kw, kh, FftConvolver::fast_size(w + kw - 1),
                      FftConvolver::fast_size(h + kh - 1));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int sx = x - ux, sy = y - uy;
      const bool inside = sx >= 0 && sy >= 0 && sx < w && sy < h;
      const float expected =
          inside ? image[std::size_t(sy) * std::size_t(w) + std::size_t(sx)] : 0.0f;
      ASSERT_NEAR(out[std::size_t(y) * std::size_t(w) + std::size_t(x)], expected, 1e-5f)
          << "at (" << x << ", " << y << ")";
    }
}

TEST(FftConvolution, SpectrumCacheReturnsSameSpectrumForSameKernel) {
  FftConvolver convolver;
  const std::vector<float> kernel = random_values(9 * 5, 7);
  const auto first = convolver.kernel_spectrum(kernel, 9, 5, 64, 48);
  const std::vector<float> same_values = kernel;  // a different vector with equal values
  EXPECT_EQ(convolver.kernel_spectrum(same_values, 9, 5, 64, 48).get(), first.get());

  std::vector<float> changed = kernel;
  changed[22] += 1e-3f;
  EXPECT_NE(convolver.kernel_spectrum(changed, 9, 5, 64, 48).get(), first.get());
  EXPECT_NE(convolver.kernel_spectrum(kernel, 9, 5, 72, 48).get(), first.get());
  EXPECT_NE(convolver.kernel_spectrum(kernel, 5, 9, 64, 48).get(), first.get());
  EXPECT_EQ(convolver.kernel_spectrum(kernel, 9, 5, 64, 48).get(), first.get());
}

TEST(FftConvolution, SpectrumCacheEvictsLeastRecentlyUsed) {
  // The cache holds 64 spectra. Fill it with 64 fresh ones (A, B, then 62 more), touch A, add one
  // more: B, now the least recently used, goes; A stays.
  FftConvolver convolver;
  auto kernel_number = [](int n) { return std::vector<float>{1000.0f + float(n)}; };
  const auto a = convolver.kernel_spectrum(kernel_number(0), 1, 1, 8, 8);
  const auto b = convolver.kernel_spectrum(kernel_number(1), 1, 1, 8, 8);
  for (int n = 2; n < 64; ++n) convolver.kernel_spectrum(kernel_number(n), 1, 1, 8, 8);
  EXPECT_EQ(convolver.kernel_spectrum(kernel_number(0), 1, 1, 8, 8).get(), a.get());
  convolver.kernel_spectrum(kernel_number(64), 1, 1, 8, 8);
  EXPECT_EQ(convolver.kernel_spectrum(kernel_number(0), 1, 1, 8, 8).get(), a.get());
  EXPECT_NE(convolver.kernel_spectrum(kernel_number(1), 1, 1, 8, 8).get(), b.get());
}

TEST(FftConvolution, FastSizeHasOnlyFactorsTwoThreeFiveSeven) {
  EXPECT_EQ(FftConvolver::fast_size(1), 1);
  EXPECT_EQ(FftConvolver::fast_size(2), 2);
  EXPECT_EQ(FftConvolver::fast_size(11), 12);
  EXPECT_EQ(FftConvolver::fast_size(13), 14);
  EXPECT_EQ(FftConvolver::fast_size(97), 98);
  EXPECT_EQ(FftConvolver::fast_size(121), 125);
  EXPECT_EQ(FftConvolver::fast_size(1021), 1024);
  EXPECT_EQ(FftConvolver::fast_size(1024), 1024);
  EXPECT_EQ(FftConvolver::fast_size(2113), 2160);  // 2^4 · 3^3 · 5
}

TEST(FftConvolution, TransformSizesAreFewPerOctave) {
  EXPECT_EQ(FftConvolver().transform_size(1), 8);
  EXPECT_EQ(FftConvolver().transform_size(11), 12);
  EXPECT_EQ(FftConvolver().transform_size(13), 16);
  EXPECT_EQ(FftConvolver().transform_size(25), 32);
  EXPECT_EQ(FftConvolver().transform_size(33), 48);
  EXPECT_EQ(FftConvolver().transform_size(64), 64);
  EXPECT_EQ(FftConvolver().transform_size(65), 80);
  EXPECT_EQ(FftConvolver().transform_size(113), 128);
  EXPECT_EQ(FftConvolver().transform_size(300), 320);
  EXPECT_EQ(FftConvolver().transform_size(449), 512);
  // Two sizes per octave up to 64 (at most half the size in padding), four beyond (a quarter).
  std::set<int> small, sizes;
  for (int n = 9; n <= 4096; ++n) {
    const int t = FftConvolver().transform_size(n);
    ASSERT_GE(t, n);
    ASSERT_LE(t, n + n / (n <= 64 ? 2 : 4) + 1) << n;
    ASSERT_EQ(FftConvolver::fast_size(t), t) << n;  // FFTW-friendly factors
    (n <= 64 ? small : sizes).insert(t);
  }
  EXPECT_LE(sizes.size(), 4u * 6u + 1u);
  EXPECT_EQ(small, (std::set<int>{12, 16, 24, 32, 48, 64}));
}

TEST(FftConvolution, SmallTransformsRunOnOneThread) {
  EXPECT_FALSE(FftConvolver().threaded(320, 320));
  EXPECT_TRUE(FftConvolver().threaded(512, 512));
}

TEST(FftConvolution, SingleThreadedPlansGiveSameResult) {
  // A convolver on one FFTW thread makes plans of its own: they must agree with the direct
  // convolution too.
  const int w = 37, h = 23, kw = 5, kh = 7;
  const std::vector<float> image = random_values(std::size_t(w) * std::size_t(h), 8);
  const std::vector<float> kernel = random_values(std::size_t(kw) * std::size_t(kh), 9);
  const std::vector<float> expected = direct_convolution(image, w, h, kernel, kw, kh);
  const std::vector<float> out = fft_convolution(image, w, h, kernel, kw, kh, 42, 30, 1);
  for (std::size_t i = 0; i < out.size(); ++i)
    ASSERT_NEAR(out[i], expected[i], 1e-5f * kernel_sum(kernel));
}

TEST(FftConvolution, ConcurrentCallsMatchSerialOnes) {
  const int w = 150, h = 97, kw = 15, kh = 9, images = 6, kernels = 3;
  const int tw = FftConvolver::fast_size(w + kw - 1), th = FftConvolver::fast_size(h + kh - 1);
  std::vector<std::vector<float>> image_set, kernel_set;
  for (int i = 0; i < images; ++i)
    image_set.push_back(random_values(std::size_t(w) * std::size_t(h), 100 + unsigned(i)));
  for (int k = 0; k < kernels; ++k)
    kernel_set.push_back(random_values(std::size_t(kw) * std::size_t(kh), 200 + unsigned(k)));

  std::vector<std::vector<float>> serial;
  for (int k = 0; k < kernels; ++k)
    for (int i = 0; i < images; ++i)
      serial.push_back(fft_convolution(image_set[std::size_t(i)], w, h, kernel_set[std::size_t(k)],
                                       kw, kh, tw, th));

  // Several rounds of every (kernel, image) pair, spectra requested and convolutions run from
  // many threads at once (the spectra are cached by now; the last kernel is new to the cache at
  // a new transform size, so spectra and plans are also made concurrently).
  const int pairs = images * kernels, rounds = 8;
  std::vector<std::vector<float>> parallel(std::size_t(pairs * rounds));
  std::vector<std::vector<float>> fresh(std::size_t(pairs * rounds));
  const std::vector<float> new_kernel = random_values(std::size_t(kw) * std::size_t(kh), 300);
  tbb::parallel_for(0, pairs * rounds, [&](int task) {
    const int pair = task % pairs, k = pair / images, i = pair % images;
    parallel[std::size_t(task)] = fft_convolution(image_set[std::size_t(i)], w, h,
                                                  kernel_set[std::size_t(k)], kw, kh, tw, th);
    fresh[std::size_t(task)] =
        fft_convolution(image_set[std::size_t(i)], w, h, new_kernel, kw, kh, tw + 2, th + 2);
  });
  for (int task = 0; task < pairs * rounds; ++task) {
    EXPECT_EQ(parallel[std::size_t(task)], serial[std::size_t(task % pairs)]) << "task " << task;
    const int i = task % pairs % images;
    EXPECT_EQ(fresh[std::size_t(task)], fresh[std::size_t(i)]) << "task " << task;
  }
}

}  // namespace
}  // namespace sb
