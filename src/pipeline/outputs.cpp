#include "pipeline/outputs.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <system_error>
#include <utility>
#include <vector>

#include "core/image_io.h"
#include "pipeline/manifest.h"

namespace sb {

namespace fs = std::filesystem;

namespace {

double srgb_encode(double linear) {
  linear = std::clamp(linear, 0.0, 1.0);
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

}  // namespace

Image tone_map_irradiance(const Image& irradiance, double white) {
  // Extended Reinhard, L·(1 + L/Lw²)/(1 + L), with irradiance measured in quarters of the white
  // point (L = 4·v/white, Lw = 4): the white point maps to 1, a quarter of it to about 0.53.
  constexpr double kLw = 4.0;
  Image out = irradiance;
  const double scale = white > 0 ? kLw / white : 0.0;
  for (float& v : out.pixels) {
    const double l = std::isfinite(v) ? std::max(0.0, double(v)) * scale : 0.0;
    v = float(srgb_encode(l * (1.0 + l / (kLw * kLw)) / (1.0 + l)));
  }
  return out;
}

double irradiance_white_point(const BakeResult& result) {
  std::vector<float> values;
  for (const auto& r : result.receivers)
    for (std::size_t i = 0; i < r.image.pixels.size(); ++i)
      if (r.image.pixels[i] > 0) values.push_back(r.image.pixels[i]);
  if (values.empty()) return 1.0;
  const std::size_t k = std::min(values.size() - 1, std::size_t(0.99 * double(values.size())));
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(k), values.end());
  return std::max(1e-12, double(values[k]));
}

namespace {

// A receiver's files: the lightmap, its preview and its coverage mask.
std::vector<std::string> receiver_files(const std::string& name) {
  return {name + ".exr", name + ".png", name + ".coverage.png"};
}

// A receiver's manifest entry: its files, texels, UV layout checks, time and the method's own
// figures and entries.
ManifestReceiver describe_receiver(const ReceiverBake& r, const BakeSettings& effective,
                                   ManifestFiles files) {
  ManifestReceiver entry;
  entry.name = r.name;
  entry.files = std::move(files);
  entry.uv_channel = r.uv_channel;
  entry.width = r.image.width;
  entry.height = r.image.height;
  entry.method = effective.method;
  entry.quantity = effective.quantity;
  entry.samples = effective.samples;
  entry.covered_texels = r.covered_texels;
  entry.uv_layout = {.charts = r.uv.charts,
                     .uv_area = r.uv.uv_area,
                     .uv_area_outside = r.uv.uv_area_outside,
                     .overlapping_texels = r.uv.overlapping_texels,
                     .texels_near_other_charts = r.uv.texels_near_other_charts,
                     .margin = r.uv.margin};
  entry.seconds = r.seconds;
  entry.method_stats = r.report.stats;
  entry.method_entries = r.report.manifest;
  return entry;
}

std::string lower(std::string text) {
  for (char& c : text) c = char(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

}  // namespace

std::vector<std::string> output_names(const Scene& scene) {
  std::vector<std::string> names;
  for (const auto& obj : scene.objects) {
    if (!obj.receiver) continue;
    for (std::string& file : receiver_files(obj.name)) names.push_back(std::move(file));
  }
  names.push_back(kManifestFile);
  return names;
}

Status check_output_names(const Scene& scene) {
  std::map<std::string, const ObjectDesc*> owner;  // lower-case file name -> object
  for (const auto& obj : scene.objects) {
    if (!obj.receiver) continue;
    for (const std::string& file : receiver_files(obj.name)) {
      const std::string key = lower(file);
      if (key == kManifestFile) continue;  // no receiver file ends in .json
      const auto [it, inserted] = owner.emplace(key, &obj);
      if (inserted) continue;
      const ObjectDesc& first = *it->second;
      return scene_error(scene.file.string() + ":" + std::to_string(obj.line) + ": object '" +
                         obj.name + "': its output file '" + file + "' is also a file of object '" +
                         first.name + "' (line " + std::to_string(first.line) +
                         "); rename one of them");
    }
  }
  return Ok{};
}

Status write_outputs(OutputFolder& folder, const Scene& scene, const BakeSettings& effective,
                     const BakeResult& result) {
  if (Status s = check_output_names(scene); !s) return s;
  const std::vector<std::string> names = output_names(scene);
  if (Status s = folder.check_targets(names); !s) return s;

  const bool irradiance = effective.quantity == Quantity::irradiance;
  const double white = irradiance ? irradiance_white_point(result) : 1.0;

  Manifest manifest;
  manifest.shadowbake = SHADOWBAKE_VERSION;
  manifest.scene = scene.file.string();
  manifest.method = effective.method;
  manifest.quantity = effective.quantity;
  manifest.resolution = effective.resolution;
  manifest.samples = effective.samples;
  manifest.seed = effective.seed;
  manifest.margin = effective.margin;
  if (effective.method == "convolution") {
    manifest.trace = effective.trace;
    manifest.convolve = effective.convolve;
  }
  for (const auto& l : scene.lights) manifest.lights.push_back({l.name, l.shape});
  if (irradiance) manifest.png_white_point = white;

  for (const auto& r : result.receivers) {
    const std::vector<std::string> files = receiver_files(r.name);
    const fs::path exr = folder.staged(files[0]), png = folder.staged(files[1]),
                   coverage = folder.staged(files[2]);
    if (Status s = write_image(exr, r.image, PixelFormat::float32); !s) return s;
    const Image preview = irradiance ? tone_map_irradiance(r.image, white) : r.image;
    if (Status s = write_image(png, preview, PixelFormat::uint8); !s) return s;
    // Which texels the receiver's triangles cover: `compare` and `report` count only these.
    Image mask(r.image.width, r.image.height, 1, 0.0f);
    for (std::size_t i = 0; i < r.covered.size() && i < mask.pixels.size(); ++i)
      mask.pixels[i] = r.covered[i] ? 1.0f : 0.0f;
    if (Status s = write_image(coverage, mask, PixelFormat::uint8); !s) return s;
    manifest.receivers.push_back(describe_receiver(
        r, effective,
        {exr.filename().string(), png.filename().string(), coverage.filename().string()}));
  }
  manifest.warnings = result.warnings;
  manifest.load_seconds = result.load_seconds;
  manifest.bake_seconds = result.bake_seconds;
  manifest.shadow_rays = result.shadow_rays;

  if (Status s =
          write_text_file(folder.staged(kManifestFile), manifest_to_json(manifest).dump(2) + "\n");
      !s)
    return s;
  return folder.publish(names);
}

}  // namespace sb
