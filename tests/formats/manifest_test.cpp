// manifest.json's schema (formats/manifest.h): what is written reads back the same, keys keep
// the order the file has always listed them in, and a file that is not a whole manifest is
// refused with a line naming the file and the key.
#include "formats/manifest.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace sb {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

// A manifest with every key set, the optional ones included.
Manifest full_manifest() {
  Manifest m;
  m.shadowbake = "1.2.3";
  m.scene = "scenes/showcase/scene.toml";
  m.method = "convolution";
  m.quantity = Quantity::irradiance;
  m.resolution = 64;
  m.samples = 256;
  m.seed = 18446744073709551615ull;
  m.margin = 4;
  m.method_settings = {{"trace", true}, {"convolve", false}};
  m.lights = {{"panel", LightShape::rectangle, 0, std::nullopt},
              {"bulb", LightShape::sphere, -1, 14.75}};
  m.png_white_point = 12.5;
  ManifestReceiver& r = m.receivers.emplace_back();
  r.name = "floor";
  r.files.emplace();
  r.files->lightmap = {"floor.exr", Encoding::linear_exr};
  r.files->preview = ManifestFile{"floor.png", Encoding::png};
  r.files->coverage = {"floor.coverage.png", Encoding::png};
  r.uv_channel = 1;
  r.width = 64;
  r.height = 32;
  r.method = "convolution";
  r.quantity = Quantity::irradiance;
  r.samples = 256;
  r.covered_texels = 2000;
  r.most_lights_per_texel = 37;
  r.uv_layout.charts = 3;
  r.uv_layout.uv_area = 0.75;
  r.uv_layout.uv_area_outside = 0.125;
  r.uv_layout.overlapping_texels = 7;
  r.uv_layout.texels_near_other_charts = 11;
  r.uv_layout.margin = 4;
  r.seams.edges = 12;
  r.seams.texels = 300;
  r.seams.stitched = true;
  r.seams.before = {.largest = 0.5, .visible = 0.25};
  r.seams.after = {.largest = 0.001, .visible = 0.0};
  r.seconds = 0.25;
  r.method_stats = {{"clear_fraction", 0.5}, {"rays_per_texel", 3.0}};
  r.method_entries["penumbra_error"] = {{"metres", 0.01}, {"texels", 2.5}};
  r.method_entries["lights"] = json::array({json{{"light", "panel"}}});
  m.warnings = {"a warning"};
  m.load_seconds = 0.5;
  m.bake_seconds = 1.5;
  m.shadow_rays = 123456789012;
  return m;
}

std::vector<std::string> keys(const json& object) {
  std::vector<std::string> out;
  for (const auto& [key, value] : object.items()) out.push_back(key);
  return out;
}

std::string error_of(std::string_view text) {
  auto parsed = parse_manifest(text, "m.json");
  return parsed ? std::string("(accepted)") : parsed.error().message;
}

TEST(Manifest, RoundTripsEveryKey) {
  const Manifest written = full_manifest();
  const std::string text = manifest_to_json(written).dump(2);
  auto read = parse_manifest(text, "m.json");
  ASSERT_TRUE(read) << read.error().message;
  EXPECT_EQ(manifest_to_json(*read).dump(2), text);
  EXPECT_EQ(read->seed, written.seed);
  EXPECT_EQ(read->quantity, Quantity::irradiance);
  EXPECT_EQ(read->lights[1].shape, LightShape::sphere);
  EXPECT_EQ(read->lights[1].range, 14.75);
  EXPECT_FALSE(read->lights[0].range);
  EXPECT_EQ(read->receivers[0].most_lights_per_texel, 37);
  EXPECT_EQ(read->png_white_point, 12.5);
  EXPECT_EQ(read->method_settings, written.method_settings);  // trace true, convolve false
  ASSERT_EQ(read->receivers.size(), 1u);
  const ManifestReceiver& r = read->receivers[0];
  ASSERT_TRUE(r.files);
  EXPECT_EQ(r.files->coverage.file, "floor.coverage.png");
  EXPECT_EQ(r.width, 64);
  EXPECT_EQ(r.height, 32);
  EXPECT_EQ(r.uv_layout.texels_near_other_charts, 11);
  EXPECT_EQ(r.seams.edges, 12);
  EXPECT_EQ(r.seams.texels, 300);
  EXPECT_TRUE(r.seams.stitched);
  EXPECT_EQ(r.seams.before.largest, 0.5);
  EXPECT_EQ(r.seams.after.largest, 0.001);
  EXPECT_EQ(r.seams.before.visible, 0.25);
  EXPECT_EQ(r.method_stats, written.receivers[0].method_stats);
  EXPECT_EQ(r.method_entries, written.receivers[0].method_entries);
  EXPECT_EQ(read->shadow_rays, 123456789012);
}

TEST(Manifest, KeepsTheFilesKeyOrder) {
  const json j = manifest_to_json(full_manifest());
  EXPECT_EQ(keys(j),
            (std::vector<std::string>{"shadowbake", "scene", "method", "quantity", "resolution",
                                      "samples", "seed", "margin", "trace", "convolve", "output",
                                      "lights", "png_white_point", "receivers", "warnings",
                                      "load_seconds", "bake_seconds", "shadow_rays"}));
  // The method's own entries follow method_stats.
  EXPECT_EQ(
      keys(j["receivers"][0]),
      (std::vector<std::string>{"name", "files", "uv_channel", "resolution", "method", "quantity",
                                "samples", "covered_texels", "most_lights_per_texel", "uv_layout",
                                "seams", "seconds", "method_stats", "penumbra_error", "lights"}));
  EXPECT_EQ(keys(j["receivers"][0]["uv_layout"]),
            (std::vector<std::string>{"charts", "uv_area", "uv_area_outside", "overlapping_texels",
                                      "texels_near_other_charts", "margin", "stretch",
                                      "density_spread", "generated"}));
}

TEST(Manifest, LeavesOutWhatDoesNotApply) {
  Manifest m = full_manifest();
  m.method_settings.clear();
  m.png_white_point = std::nullopt;
  m.receivers[0].method_stats.clear();
  m.receivers[0].method_entries = json::object();
  const json j = manifest_to_json(m);
  for (const char* key : {"trace", "convolve", "png_white_point"}) EXPECT_FALSE(j.contains(key));
  EXPECT_FALSE(j["receivers"][0].contains("method_stats"));
  auto read = manifest_from_json(j, "m.json");
  ASSERT_TRUE(read) << read.error().message;
  EXPECT_TRUE(read->method_settings.empty());
  EXPECT_FALSE(read->png_white_point);
  EXPECT_TRUE(read->receivers[0].method_stats.empty());
  EXPECT_TRUE(read->receivers[0].method_entries.empty());
}

TEST(Manifest, RejectsWhatIsNotAManifest) {
  const std::string not_manifest = "m.json: not a bake manifest (no receivers array)";
  EXPECT_EQ(error_of("{\"receivers\": ["), not_manifest);
  EXPECT_EQ(error_of("[1, 2]"), not_manifest);
  EXPECT_EQ(error_of("{\"receivers\": {}}"), not_manifest);
  EXPECT_EQ(error_of(""), not_manifest);
}

TEST(Manifest, RejectsMissingOrMistypedKeys) {
  json j = manifest_to_json(full_manifest());
  j.erase("bake_seconds");
  EXPECT_EQ(error_of(j.dump()), "m.json: no bake_seconds in the bake's manifest");

  j = manifest_to_json(full_manifest());
  j["receivers"][0]["files"]["lightmap"]["file"] = 3;
  EXPECT_EQ(error_of(j.dump()),
            "m.json: receivers[0].files.lightmap.file in the bake's manifest is not a string");

  j = manifest_to_json(full_manifest());
  j["quantity"] = "brightness";
  EXPECT_EQ(error_of(j.dump()),
            "m.json: quantity in the bake's manifest is not \"visibility\", \"irradiance\" or "
            "\"ambient-occlusion\"");

  j = manifest_to_json(full_manifest());
  j["receivers"][0]["resolution"] = json::array({64});
  EXPECT_EQ(error_of(j.dump()),
            "m.json: receivers[0].resolution in the bake's manifest is not [width, height]");

  j = manifest_to_json(full_manifest());
  j["resolution"] = 1e12;
  EXPECT_EQ(error_of(j.dump()), "m.json: resolution in the bake's manifest is not an integer");

  j = manifest_to_json(full_manifest());
  j["seed"] = -1;
  EXPECT_EQ(error_of(j.dump()), "m.json: seed in the bake's manifest is not an integer ≥ 0");
}

TEST(Manifest, ReadsAFolderAndNamesAMissingFile) {
  const fs::path dir =
      fs::temp_directory_path() / ("shadowbake_manifest_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string path = (dir / kManifestFile).string();
  auto missing = read_manifest(dir);
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().message, path + ": cannot read the bake's manifest");

  std::ofstream(dir / kManifestFile) << manifest_to_json(full_manifest()).dump(2) << "\n";
  auto read = read_manifest(dir);
  ASSERT_TRUE(read) << read.error().message;
  EXPECT_EQ(read->receivers[0].name, "floor");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sb
