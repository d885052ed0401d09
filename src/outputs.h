// The files a bake leaves for a pipeline: per receiver <name>.exr (linear float RGB) and
// <name>.png (8-bit preview), and manifest.json describing them (docs/outputs.md).
#pragma once

#include <filesystem>
#include <string>

#include "bake.h"
#include "error.h"
#include "scene.h"

namespace sb {

// Writes every output into `dir` (created if missing). All files are written under temporary
// names first and renamed only when every one of them was written, so a failure leaves no
// partial or mixed output. `effective` holds the settings the bake ran with (after CLI
// overrides). The same inputs give the same image bytes; the manifest differs only in timings.
Status write_outputs(const std::filesystem::path& dir, const Scene& scene,
                     const BakeSettings& effective, const BakeResult& result);

// The 8-bit preview of an irradiance image: extended Reinhard per channel with the white point
// at `white` W/m², then the sRGB transfer curve. Visibility previews are written linearly.
Image tone_map_irradiance(const Image& irradiance, double white);

// The white point write_outputs uses: the 99th percentile of all receivers' covered texel
// values (one exposure for the whole scene, so receivers' previews match).
double irradiance_white_point(const BakeResult& result);

}  // namespace sb
