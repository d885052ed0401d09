// manifest.json, the description a bake leaves beside its images (docs/cli.md): its schema
// as C++ types, written by write_outputs (outputs.h) and read by the report. One definition of
// every key, in the order the file lists them.
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "formats/receiver_record.h"
#include "methods/method.h"
#include "scene/scene.h"

namespace sb {

// The manifest's file name in a bake's output folder.
inline constexpr const char* kManifestFile = "manifest.json";

struct ManifestLight {
  std::string name;
  LightShape shape = LightShape::rectangle;
  // With [output] shadowmask: its channel (0–3: R, G, B, A) or −1 (left out: "none").
  std::optional<int> shadowmask_channel;
  // Its reach, metres (LightDesc::range: the file's, or [bake] irradiance_floor's); none where
  // it reaches everywhere.
  std::optional<double> range;
};

// One file and how to decode it (docs/cli.md, "Encodings"): the quantity a texel stands for is
// scale · transfer⁻¹(decoded value); "reinhard-srgb" (an irradiance preview) is not inverted.
struct ManifestFile {
  std::string file;  // relative to the bake's folder
  Encoding encoding = Encoding::linear_exr;
  std::string transfer = "linear";  // "linear" or "reinhard-srgb"
  double scale = 1;
};

// One set of files: a receiver's, or an atlas's.
struct ManifestFiles {
  ManifestFile lightmap;                // the lightmap ([output] encoding)
  std::optional<ManifestFile> preview;  // an 8-bit preview, beside an EXR lightmap
  ManifestFile coverage;                // 1 where a triangle covers the texel (PNG)
  std::vector<std::pair<std::string, ManifestFile>> per_light;  // light name → its file
  std::optional<ManifestFile> shadowmask;  // RGBA: the lights' channels (ManifestLight)
};

// A receiver's place in an atlas: its image's first texel (x, y; row 0 at the top), its side,
// and Unity's lightmapScaleOffset: atlas uv = uv · (sx, sy) + (ox, oy), UVs with v up.
struct ManifestAtlasPlacement {
  int index = 0;
  int x = 0, y = 0, side = 0;
  std::array<double, 4> scale_offset{};
};

struct ManifestAtlas {
  int index = 0;
  int size = 0;  // texels per side
  ManifestFiles files;
};

// A receiver's entry: its record (receiver_record.h: covered_texels, uv_layout, seams, written
// after `samples`) and what the bake wrote of it.
struct ManifestReceiver : ReceiverRecord {
  std::string name;
  std::optional<ManifestFiles> files;           // its own files (no atlas)
  std::optional<ManifestAtlasPlacement> atlas;  // or its place in an atlas
  int uv_channel = 0;
  int width = 0, height = 0;  // texels ("resolution": [width, height])
  std::string method;
  Quantity quantity = Quantity::visibility;
  int samples = 0;
  double seconds = 0;
  // Incremental bakes: whether it was taken from the earlier bake's cache, and why it was or
  // was not (pipeline/bake_cache.h); absent for a shard's or a merge's receivers.
  struct Reuse {
    bool reused = false;
    std::string why;
  };
  std::optional<Reuse> bake;
  MethodStats method_stats;  // written only when there are some
  // The method's own entries (MethodReport::manifest), written after method_stats in their
  // order; on reading, every key the schema does not name. They must not reuse a schema key.
  nlohmann::ordered_json method_entries = nlohmann::ordered_json::object();
};

struct Manifest {
  std::string shadowbake;  // the version that baked
  std::string scene;       // the scene file, as given
  std::string method;
  Quantity quantity = Quantity::visibility;
  int resolution = 0, samples = 0;
  std::optional<double> texels_per_metre;  // when the lightmaps were sized by density
  std::uint64_t seed = 0;
  int margin = 0;
  // The method's own settings it records (MethodEntry::manifest_settings), in its order.
  std::vector<std::pair<std::string, SettingValue>> method_settings;
  OutputSettings output;  // [output] as the bake ran
  std::vector<ManifestLight> lights;
  std::optional<double> png_white_point;  // irradiance only: W/m² the previews map to white
  std::vector<ManifestAtlas> atlases;     // with [output] atlas
  std::optional<std::string> gltf;        // the glTF binary, with [output] gltf
  std::vector<ManifestReceiver> receivers;
  std::vector<std::string> warnings;
  double load_seconds = 0, bake_seconds = 0;
  std::int64_t shadow_rays = 0;
};

// The manifest as JSON, keys in the schema's order; `dump(2)` of it is the file's text.
nlohmann::ordered_json manifest_to_json(const Manifest& manifest);

// The manifest `json` describes. An error, naming `where` (the file), when it is not an object
// with a receivers array ("not a bake manifest"), or a key is missing ("no <key>") or has the
// wrong type.
Expected<Manifest> manifest_from_json(const nlohmann::ordered_json& json, const std::string& where);

// Parses manifest.json's text; malformed JSON is "not a bake manifest".
Expected<Manifest> parse_manifest(std::string_view text, const std::string& where);

// Reads `folder`/manifest.json; an error when it cannot be read or is not a manifest.
Expected<Manifest> read_manifest(const std::filesystem::path& folder);

}  // namespace sb
