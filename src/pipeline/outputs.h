// The files a bake leaves for a pipeline: per receiver <name>.exr (linear float RGB) and
// <name>.png (8-bit preview), and manifest.json describing them (docs/cli.md).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"
#include "pipeline/bake.h"
#include "pipeline/output_folder.h"
#include "scene/scene.h"

namespace sb {

// The files a bake of `scene` writes, in the order they are published (manifest.json last).
std::vector<std::string> output_names(const Scene& scene);

// Refuses a scene whose receivers' output files would collide (compared without case, as on the
// file systems outputs travel to): object `a.coverage` writes `a.coverage.png`, which is object
// `a`'s coverage mask. The error names the scene file, the line and both objects.
Status check_output_names(const Scene& scene);

// Writes every output into `folder`'s staging folder and publishes them together
// (output_folder.h): all files appear, or none and the previous bake stays. `effective` holds
// the settings the bake ran with (after CLI overrides). The same inputs give the same image
// bytes; the manifest differs only in timings.
Status write_outputs(OutputFolder& folder, const Scene& scene, const BakeSettings& effective,
                     const BakeResult& result);

// The 8-bit preview of an irradiance image: extended Reinhard per channel with the white point
// at `white` W/m², then the sRGB transfer curve. Visibility previews are written linearly.
Image tone_map_irradiance(const Image& irradiance, double white);

// The white point write_outputs uses: the 99th percentile of all receivers' covered texel
// values (one exposure for the whole scene, so receivers' previews match).
double irradiance_white_point(const BakeResult& result);

}  // namespace sb
