// Lightmap encodings (encodings.h). RGBM follows Unity's DecodeLightmapRGBM in linear colour
// space (UnityCG.cginc: decodeInstructions.x · pow(alpha, decodeInstructions.y) · rgb).
#include "lightmaps/encodings.h"

#include <algorithm>
#include <cmath>

#include "core/image_io.h"

namespace sb {

double encoding_scale(Encoding encoding, Quantity quantity, double peak) {
  if (quantity != Quantity::irradiance || !(peak > 0) || !std::isfinite(peak)) return 1.0;
  switch (encoding) {
    case Encoding::linear_exr:
    case Encoding::half_exr:
      return 1.0;
    case Encoding::png:
      return peak;
    case Encoding::rgbm_png:
      return peak > kRgbmRange ? peak / kRgbmRange : 1.0;
  }
  return 1.0;
}

const char* encoding_extension(Encoding encoding) {
  return encoding == Encoding::linear_exr || encoding == Encoding::half_exr ? ".exr" : ".png";
}

Image encode_rgbm(const Image& rgb, double scale) {
  Image out(rgb.width, rgb.height, 4, 0.0f);
  const double inverse_scale = scale > 0 ? 1.0 / scale : 0.0;
  for (int y = 0; y < rgb.height; ++y)
    for (int x = 0; x < rgb.width; ++x) {
      const float* in = rgb.at(x, y);
      double v[3];
      for (int c = 0; c < 3; ++c) {
        const double value = in[std::min(c, rgb.channels - 1)] * inverse_scale;
        v[c] = std::isfinite(value) ? std::clamp(value, 0.0, kRgbmRange) : 0.0;
      }
      const double peak = std::max({v[0], v[1], v[2]});
      float* px = out.at(x, y);
      if (peak <= 0) continue;  // black: all bytes 0
      // The smallest stored multiplier that holds the peak, so that RGB stays within 1.
      const double a = std::ceil(255.0 * std::pow(peak / kRgbmRange, 1.0 / kRgbmExponent)) / 255.0;
      const double multiplier = kRgbmRange * std::pow(a, kRgbmExponent);
      for (int c = 0; c < 3; ++c) px[c] = float(std::min(1.0, v[c] / multiplier));
      px[3] = float(a);
    }
  return out;
}

Image decode_rgbm(const Image& rgbm, double scale) {
  Image out(rgbm.width, rgbm.height, 3, 0.0f);
  for (int y = 0; y < rgbm.height; ++y)
    for (int x = 0; x < rgbm.width; ++x) {
      const float* in = rgbm.at(x, y);
      const double multiplier = scale * kRgbmRange * std::pow(double(in[3]), kRgbmExponent);
      for (int c = 0; c < 3; ++c) out.at(x, y)[c] = float(in[c] * multiplier);
    }
  return out;
}

Status write_encoded(const std::filesystem::path& path, const Image& image, Encoding encoding,
                     double scale) {
  switch (encoding) {
    case Encoding::linear_exr:
      return write_image(path, image, PixelFormat::float32);
    case Encoding::half_exr:
      return write_image(path, image, PixelFormat::float16);
    case Encoding::png: {
      Image scaled = image;
      const float inverse = scale > 0 ? float(1.0 / scale) : 0.0f;
      for (float& v : scaled.pixels) v *= inverse;
      return write_image(path, scaled, PixelFormat::uint8);
    }
    case Encoding::rgbm_png:
      return write_image(path, encode_rgbm(image, scale), PixelFormat::uint8);
  }
  return Ok{};
}

}  // namespace sb
