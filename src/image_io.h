// Reading and writing images through OpenImageIO, behind project types. Writes are atomic:
// the file appears under its name only once complete (written to a temporary name, then
// renamed), so a failed or interrupted write never leaves a half-written file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "error.h"
#include "image.h"

namespace sb {

enum class PixelFormat { float32, uint8 };

// Writes `image` to `path` (format from the extension) with pixels stored as `format`; uint8
// clamps to [0, 1] and rounds value·255 (no transfer curve: encode first if one is wanted).
Status write_image(const std::filesystem::path& path, const Image& image, PixelFormat format);

// Writes to `path`'s temporary sibling and returns that sibling's name; commit_file renames it.
// Lets a caller stage several files and publish them only when all were written.
Expected<std::filesystem::path> stage_image(const std::filesystem::path& path, const Image& image,
                                            PixelFormat format);
Expected<std::filesystem::path> stage_text(const std::filesystem::path& path,
                                           const std::string& text);
Status commit_file(const std::filesystem::path& staged, const std::filesystem::path& path);
void discard_file(const std::filesystem::path& staged);

// Reads any OIIO-readable image as float, keeping its channel count. With `linearise`, values
// of an image whose colour space OIIO reports as sRGB (8-bit PNG, JPEG, ...) are decoded to
// linear, so they can be used as emission.
Expected<Image> read_image(const std::filesystem::path& path, bool linearise = false);

}  // namespace sb
