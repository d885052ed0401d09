// Tests of the lightmap encodings (src/lightmaps/encodings.h): what a reader decodes from each
// file is the baked value to within the encoding's step, by the formula the manifest states.
#include "lightmaps/encodings.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "core/image_io.h"

namespace sb {
namespace {

namespace fs = std::filesystem;

class Encodings : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("sb_encodings_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

// An irradiance-like ramp over four decades, and black.
Image ramp() {
  Image image(64, 4, 3, 0.0f);
  for (int y = 0; y < image.height; ++y)
    for (int x = 1; x < image.width; ++x)
      for (int c = 0; c < 3; ++c)
        image.at(x, y)[c] =
            float(0.01 * std::pow(10.0, 4.0 * x / 63.0) * (1.0 - 0.2 * c) / (1 + y));
  return image;
}

TEST_F(Encodings, RgbmDecodesToTheValueWithinOneStep) {
  const Image in = ramp();  // up to 100, beyond RGBM's 34.49: the scale takes it
  double peak = 0;
  for (float v : in.pixels) peak = std::max(peak, double(v));
  const double scale = encoding_scale(Encoding::rgbm_png, Quantity::irradiance, peak);
  EXPECT_NEAR(scale, peak / kRgbmRange, 1e-12);
  ASSERT_TRUE(write_encoded(dir_ / "l.png", in, Encoding::rgbm_png, scale));
  auto stored = read_image(dir_ / "l.png");
  ASSERT_TRUE(stored) << stored.error().message;
  ASSERT_EQ(stored->channels, 4);
  const Image out = decode_rgbm(*stored, scale);
  for (std::size_t i = 0; i < in.pixels.size(); ++i) {
    const std::size_t texel = i / 3;
    // One step of RGB at the stored multiplier: range · A^2.2 / 255 · scale.
    const double a = stored->pixels[texel * 4 + 3];
    const double step = scale * kRgbmRange * std::pow(a, kRgbmExponent) / 255.0;
    EXPECT_NEAR(out.pixels[i], in.pixels[i], 0.5 * step + 1e-6) << "texel " << texel;
  }
}

TEST_F(Encodings, PngStoresValueOverScale) {
  const Image in = ramp();
  ASSERT_TRUE(write_encoded(dir_ / "l.png", in, Encoding::png, 100.0));
  auto stored = read_image(dir_ / "l.png");
  ASSERT_TRUE(stored);
  for (std::size_t i = 0; i < in.pixels.size(); ++i)
    EXPECT_NEAR(stored->pixels[i] * 100.0, in.pixels[i], 100.0 * 0.5 / 255 + 1e-4);
  // Visibility is stored as is.
  EXPECT_EQ(encoding_scale(Encoding::png, Quantity::visibility, 0.9), 1.0);
}

TEST_F(Encodings, ExrIsLinearFloatOrHalf) {
  const Image in = ramp();
  ASSERT_TRUE(write_encoded(dir_ / "f.exr", in, Encoding::linear_exr, 1.0));
  ASSERT_TRUE(write_encoded(dir_ / "h.exr", in, Encoding::half_exr, 1.0));
  auto f = read_image(dir_ / "f.exr");
  auto h = read_image(dir_ / "h.exr");
  ASSERT_TRUE(f && h);
  EXPECT_EQ(f->pixels, in.pixels);
  for (std::size_t i = 0; i < in.pixels.size(); ++i)
    EXPECT_NEAR(h->pixels[i], in.pixels[i], std::abs(in.pixels[i]) * 1e-3 + 1e-7);
  EXPECT_LT(fs::file_size(dir_ / "h.exr"), fs::file_size(dir_ / "f.exr"));
}

}  // namespace
}  // namespace sb
