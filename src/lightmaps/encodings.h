// How a lightmap's values are stored in its file, and how a reader decodes them (docs/cli.md,
// "Encodings"; the manifest states each file's): linear float OpenEXR for pipelines, half-float
// EXR, and for engines 8-bit PNG (linear, with a scale) or RGBM as Unity decodes it.
#pragma once

#include <filesystem>
#include <string>

#include "core/error.h"
#include "core/image.h"
#include "scene/scene.h"

namespace sb {

// Unity's RGBM in linear colour space: value = kRgbmRange · A^kRgbmExponent · RGB, with A and
// RGB the stored bytes / 255 (Unity's decodeInstructions (34.49, 2.2): 5 in gamma space).
inline constexpr double kRgbmRange = 34.493242;  // 5^2.2
inline constexpr double kRgbmExponent = 2.2;

// What a reader multiplies a decoded value by to get the lightmap's quantity: 1 for EXR and for
// visibility; for irradiance in 8 bits, the bake's largest value (png) or what brings it into
// RGBM's range (rgbm-png), so that nothing clips. `peak` is the largest value of every image the
// encoding stores in the bake.
double encoding_scale(Encoding encoding, Quantity quantity, double peak);

// The file extension an encoding writes, with its dot.
const char* encoding_extension(Encoding encoding);

// RGB values over `scale` as RGBM (4 channels, each in [0, 1] as write_image stores bytes),
// rounded so that decoding the stored bytes gives the value to within one step of RGB:
// A = ceil(255·(max/range)^(1/2.2))/255, RGB = value / (range · A^2.2).
Image encode_rgbm(const Image& rgb, double scale);
// The inverse, from the bytes (as 0–1 floats) of an RGBM image: RGB values times `scale`.
Image decode_rgbm(const Image& rgbm, double scale);

// Writes `image` (RGB or grey, linear) to `path` in `encoding`: EXR as float or half, PNG as
// value/scale in 8 bits, RGBM as above. `path`'s extension must be encoding_extension's.
Status write_encoded(const std::filesystem::path& path, const Image& image, Encoding encoding,
                     double scale);

}  // namespace sb
