// The files a bake leaves for a pipeline (docs/cli.md): per receiver, or per atlas with
// [output] atlas, a lightmap in the chosen encoding, an 8-bit preview beside an EXR, a coverage
// mask, and as asked each light's own image and a shadow mask; a glTF binary of the receivers
// with their lightmaps bound; and manifest.json describing every file.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"
#include "formats/output_folder.h"
#include "pipeline/bake_types.h"
#include "scene/scene.h"

namespace sb {

// The glTF binary's name in the output folder.
inline constexpr const char* kGltfFile = "scene.glb";

// The stem of atlas `index`'s files: lightmap_<index>.
std::string atlas_stem(int index);

// The files a bake of `scene` writes, in the order they are published (manifest.json last);
// with an atlas, those of `atlases` atlases (their number is known once the meshes are read).
std::vector<std::string> output_names(const Scene& scene, int atlases = 1);

// Refuses a scene whose output files would collide (compared without case, as on the file
// systems outputs travel to): object `a.coverage` writes `a.coverage.png`, which is object `a`'s
// coverage mask; light `coverage`'s per-light PNG is every receiver's coverage mask. And, with
// per_light, a light whose name cannot be part of a file name. The error names the scene file,
// the line and the items.
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
