// Reading and writing images through OpenImageIO, behind project types. A write is atomic: the
// file appears under its name only once complete (written to a temporary name, then renamed), so
// a failed or interrupted write never leaves a half-written file. Several files that must appear
// together go through an OutputFolder (output_folder.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/image.h"

namespace sb {

enum class PixelFormat { float32, float16, uint8 };

// Writes `image` to `path` (format from the extension) with pixels stored as `format`; uint8
// clamps to [0, 1] and rounds value·255 (no transfer curve: encode first if one is wanted).
Status write_image(const std::filesystem::path& path, const Image& image, PixelFormat format);

// The bytes of `image` as an 8-bit PNG file (uint8 as write_image stores it), made in memory
// (for files that embed images, such as a glTF binary). Errors name `what`.
Expected<std::vector<std::uint8_t>> png_bytes(const Image& image, const std::string& what);

// Reads any OIIO-readable image as float, keeping its channel count. With `linearise`, values
// of an image whose colour space OIIO reports as sRGB (8-bit PNG, JPEG, ...) are decoded to
// linear, so they can be used as emission. Only a regular file is read (a FIFO or a device is
// refused before it is opened), and one whose pixels as float would take more than `max_bytes`
// is refused from its header, before they are allocated.
inline constexpr std::uint64_t kDefaultMaxImageBytes = std::uint64_t(4) << 30;
Expected<Image> read_image(const std::filesystem::path& path, bool linearise = false,
                           std::uint64_t max_bytes = kDefaultMaxImageBytes);

}  // namespace sb
