// The bake's files (outputs.h): per sheet — a receiver, or an atlas of receivers — its lightmap,
// preview, coverage, per-light images and shadow mask, then the glTF and the manifest.
#include "formats/outputs.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <optional>
#include <system_error>
#include <utility>
#include <vector>

#include "core/image_io.h"
#include "formats/manifest.h"
#include "lightmaps/atlas_images.h"
#include "lightmaps/encodings.h"
#include "lightmaps/gltf_export.h"
#include "lightmaps/shadowmask.h"
#include "pipeline/bake_cache.h"

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

std::string atlas_stem(int index) { return fmt::format("lightmap_{}", index); }

namespace {

// The files of one sheet, named from its stem.
struct SheetNames {
  std::string lightmap;
  std::optional<std::string> preview;
  std::string coverage;
  std::vector<std::string> per_light;  // per light, in scene order, with per_light
  std::optional<std::string> shadowmask;
};

bool is_exr(Encoding e) { return e == Encoding::linear_exr || e == Encoding::half_exr; }

SheetNames sheet_names(const std::string& stem, const Scene& scene) {
  const OutputSettings& out = scene.output;
  SheetNames names;
  names.lightmap = stem + encoding_extension(out.encoding);
  if (is_exr(out.encoding)) names.preview = stem + ".png";
  names.coverage = stem + ".coverage.png";
  if (out.per_light)
    for (const LightDesc& l : scene.lights)
      names.per_light.push_back(stem + "." + l.name + encoding_extension(out.encoding));
  if (out.shadowmask)
    names.shadowmask = stem + ".shadowmask" + encoding_extension(out.shadowmask_encoding);
  return names;
}

std::vector<std::string> all_names(const SheetNames& n) {
  std::vector<std::string> names = {n.lightmap};
  if (n.preview) names.push_back(*n.preview);
  names.push_back(n.coverage);
  names.insert(names.end(), n.per_light.begin(), n.per_light.end());
  if (n.shadowmask) names.push_back(*n.shadowmask);
  return names;
}

std::string lower(std::string text) {
  for (char& c : text) c = char(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

// A set of files written together: a receiver's own, or an atlas's.
struct Sheet {
  std::string stem;
  int atlas = -1;                      // its atlas, or −1 for a receiver's own
  std::vector<std::size_t> receivers;  // indices into BakeResult::receivers
  int width = 0, height = 0;
};

std::vector<Sheet> make_sheets(const BakeResult& result) {
  std::vector<Sheet> sheets;
  if (result.atlas) {
    for (std::size_t a = 0; a < result.atlas->sizes.size(); ++a) {
      Sheet s{atlas_stem(int(a)), int(a), {}, result.atlas->sizes[a], result.atlas->sizes[a]};
      for (std::size_t r = 0; r < result.atlas->placements.size(); ++r)
        if (result.atlas->placements[r].atlas == int(a)) s.receivers.push_back(r);
      sheets.push_back(std::move(s));
    }
    return sheets;
  }
  for (std::size_t r = 0; r < result.receivers.size(); ++r) {
    const ReceiverBake& rb = result.receivers[r];
    sheets.push_back({rb.name, -1, {r}, rb.image.width, rb.image.height});
  }
  return sheets;
}

// The sheet's image of one kind: `image_of(receiver)` itself for a receiver's sheet, composed
// into the atlas (padding filled from each receiver's edge, or left at `background` with
// `pad` false) for an atlas's.
template <class ImageOf>
Image sheet_image(const Sheet& sheet, const BakeResult& result, int channels, float background,
                  bool pad, ImageOf image_of) {
  if (sheet.atlas < 0) return image_of(result.receivers[sheet.receivers[0]]);
  AtlasLayout layout = *result.atlas;
  if (!pad) layout.padding = 0;
  std::vector<Image> owned(result.receivers.size());
  std::vector<const Image*> images(result.receivers.size(), nullptr);
  for (const std::size_t r : sheet.receivers) {
    owned[r] = image_of(result.receivers[r]);
    images[r] = &owned[r];
  }
  return compose_atlas(layout, sheet.atlas, images, channels, background);
}

Image coverage_image(const ReceiverBake& r) {
  Image mask(r.image.width, r.image.height, 1, 0.0f);
  for (std::size_t i = 0; i < r.covered.size() && i < mask.pixels.size(); ++i)
    mask.pixels[i] = r.covered[i] ? 1.0f : 0.0f;
  return mask;
}

// The largest finite value of `image` at the receiver's covered texels.
double covered_peak(const ReceiverBake& r, const Image& image) {
  double peak = 0;
  for (std::size_t i = 0; i < r.covered.size(); ++i) {
    if (!r.covered[i]) continue;
    for (int c = 0; c < image.channels; ++c) {
      const float v = image.pixels[i * std::size_t(image.channels) + std::size_t(c)];
      if (std::isfinite(v)) peak = std::max(peak, double(v));
    }
  }
  return peak;
}

// The same over a per-light image's tiles (beyond them it holds 0).
double covered_peak(const ReceiverBake& r, const TiledImages& images, std::size_t l) {
  double peak = 0;
  images.each_pixel(l, [&](int x, int y, const float* px) {
    if (!r.covered[std::size_t(y) * std::size_t(images.width()) + std::size_t(x)]) return;
    for (int c = 0; c < images.channels(); ++c)
      if (std::isfinite(px[c])) peak = std::max(peak, double(px[c]));
  });
  return peak;
}

// The largest of the lightmaps' (per_light false) or of the per-light images'.
double covered_peak(const BakeResult& result, bool per_light) {
  double peak = 0;
  for (const ReceiverBake& r : result.receivers) {
    if (!per_light) peak = std::max(peak, covered_peak(r, r.image));
    if (per_light)
      for (std::size_t l = 0; l < r.per_light.size(); ++l)
        peak = std::max(peak, covered_peak(r, r.per_light, l));
  }
  return peak;
}

ManifestReceiver describe_receiver(const ReceiverBake& r, const BakeSettings& effective) {
  ManifestReceiver entry;
  entry.name = r.name;
  entry.uv_channel = r.uv_channel;
  entry.width = r.image.width;
  entry.height = r.image.height;
  entry.method = effective.method;
  entry.quantity = effective.quantity;
  entry.samples = effective.samples;
  static_cast<ReceiverRecord&>(entry) = r;
  entry.seconds = r.seconds;
  if (!r.reuse.empty()) entry.bake = ManifestReceiver::Reuse{r.reuse == "reused", r.reuse_why};
  entry.method_stats = r.report.stats;
  entry.method_entries = r.report.manifest;
  return entry;
}

// How the bake's files are encoded: the scales of each kind of file, one for the whole bake.
struct Scales {
  double lightmap = 1, per_light = 1, gltf = 1;
};

// Writes one sheet's files and says what they are.
Expected<ManifestFiles> write_sheet(OutputFolder& folder, const Scene& scene,
                                    const BakeResult& result, const Sheet& sheet,
                                    const Scales& scales, bool irradiance, double white,
                                    std::vector<GltfTexture>* gltf) {
  const OutputSettings& out = scene.output;
  const SheetNames names = sheet_names(sheet.stem, scene);
  ManifestFiles files;
  const auto entry = [](const std::string& file, Encoding encoding, double scale) {
    return ManifestFile{file, encoding, "linear", scale};
  };

  {
    const Image lightmap =
        sheet_image(sheet, result, 3, 0.0f, true, [](const ReceiverBake& r) { return r.image; });
    if (Status s =
            write_encoded(folder.staged(names.lightmap), lightmap, out.encoding, scales.lightmap);
        !s)
      return s.error();
    files.lightmap = entry(names.lightmap, out.encoding, scales.lightmap);
    if (names.preview) {
      const Image preview = irradiance ? tone_map_irradiance(lightmap, white) : lightmap;
      if (Status s = write_image(folder.staged(*names.preview), preview, PixelFormat::uint8); !s)
        return s.error();
      files.preview = irradiance
                          ? ManifestFile{*names.preview, Encoding::png, "reinhard-srgb", white}
                          : entry(*names.preview, Encoding::png, 1.0);
    }
    if (gltf) {
      // glTF's core images are PNG: the lightmap as linear 8 bits over the glTF scale.
      Image scaled = lightmap;
      for (float& v : scaled.pixels) v = float(v / scales.gltf);
      auto png = png_bytes(scaled, fs::path(kGltfFile).string());
      if (!png) return png.error();
      gltf->push_back({sheet.stem, std::move(*png)});
    }
  }
  const Image coverage = sheet_image(sheet, result, 1, 0.0f, false, coverage_image);
  if (Status s = write_image(folder.staged(names.coverage), coverage, PixelFormat::uint8); !s)
    return s.error();
  files.coverage = entry(names.coverage, Encoding::png, 1.0);

  for (std::size_t l = 0; l < names.per_light.size(); ++l) {
    const Image light = sheet_image(sheet, result, 3, 0.0f, true,
                                    [l](const ReceiverBake& r) { return r.per_light.dense(l); });
    if (Status s =
            write_encoded(folder.staged(names.per_light[l]), light, out.encoding, scales.per_light);
        !s)
      return s.error();
    files.per_light.emplace_back(scene.lights[l].name,
                                 entry(names.per_light[l], out.encoding, scales.per_light));
  }
  if (names.shadowmask) {
    const Image mask =
        sheet_image(sheet, result, kShadowmaskChannels, 1.0f, true, [&](const ReceiverBake& r) {
          return compose_shadowmask(r.per_light_visibility, result.shadowmask_channels,
                                    r.image.width, r.image.height);
        });
    if (Status s =
            write_encoded(folder.staged(*names.shadowmask), mask, out.shadowmask_encoding, 1.0);
        !s)
      return s.error();
    files.shadowmask = entry(*names.shadowmask, out.shadowmask_encoding, 1.0);
  }
  return files;
}

}  // namespace

std::vector<std::string> output_names(const Scene& scene, int atlases) {
  std::vector<std::string> names;
  if (scene.output.atlas) {
    for (int a = 0; a < std::max(atlases, 1); ++a)
      for (std::string& file : all_names(sheet_names(atlas_stem(a), scene)))
        names.push_back(std::move(file));
  } else {
    for (const auto& obj : scene.objects) {
      if (!obj.receiver) continue;
      for (std::string& file : all_names(sheet_names(obj.name, scene)))
        names.push_back(std::move(file));
    }
  }
  if (scene.output.gltf) names.push_back(kGltfFile);
  names.push_back(kManifestFile);
  return names;
}

Status check_output_names(const Scene& scene) {
  if (scene.output.per_light) {
    for (const LightDesc& l : scene.lights) {
      if (is_file_name_part(l.name)) continue;
      return scene_error(fmt::format(
          "{}:{}: light '{}': [output] per_light names a file after each light ('<object>.{}{}'); "
          "use letters, digits, '_', '.' and '-' in its name, not starting with '.'",
          scene.file.string(), l.line, l.name, l.name, encoding_extension(scene.output.encoding)));
    }
  }
  // Every file with what writes it: an object (with the light of a per-light file), or an atlas.
  struct Writer {
    int line = 0;             // where the error points: the object's line, or none for an atlas
    std::string item, named;  // "object 'a'", and how another claimant names it
  };
  std::map<std::string, Writer> owner;  // lower-case file name -> who writes it
  const auto claim_sheet = [&](const std::string& stem, const Writer& who) -> Status {
    const SheetNames names = sheet_names(stem, scene);
    for (const std::string& file : all_names(names)) {
      Writer by = who;
      for (std::size_t l = 0; l < names.per_light.size(); ++l) {
        if (names.per_light[l] != file) continue;
        const LightDesc& light = scene.lights[l];
        by.named += fmt::format(" with light '{}' (line {})", light.name, light.line);
        by.item += fmt::format(" with light '{}'", light.name);
      }
      const auto [it, inserted] = owner.emplace(lower(file), by);
      if (inserted) continue;
      const std::string at =
          by.line > 0 ? fmt::format("{}:{}", scene.file.string(), by.line) : scene.file.string();
      return scene_error(
          fmt::format("{}: {}: its output file '{}' is also a file of {}; rename one of them", at,
                      by.item, file, it->second.named));
    }
    return Ok{};
  };
  if (scene.output.atlas) {
    const std::string stem = atlas_stem(0);
    if (Status s = claim_sheet(stem, {0, "atlas " + stem, "atlas " + stem}); !s) return s;
  } else {
    for (const auto& obj : scene.objects) {
      if (!obj.receiver) continue;
      const Writer who{obj.line, fmt::format("object '{}'", obj.name),
                       fmt::format("object '{}' (line {})", obj.name, obj.line)};
      if (Status s = claim_sheet(obj.name, who); !s) return s;
    }
  }
  return Ok{};
}

Status write_outputs(OutputFolder& folder, const Scene& scene, const BakeSettings& effective,
                     const BakeResult& result) {
  if (Status s = check_output_names(scene); !s) return s;
  const int atlases = result.atlas ? int(result.atlas->sizes.size()) : 1;
  const std::vector<std::string> names = output_names(scene, atlases);
  if (Status s = folder.check_targets(names); !s) return s;

  const OutputSettings& out = scene.output;
  const bool irradiance = effective.quantity == Quantity::irradiance;
  const double white = irradiance ? irradiance_white_point(result) : 1.0;
  Scales scales;
  const double lightmap_peak = covered_peak(result, false);
  scales.lightmap = encoding_scale(out.encoding, effective.quantity, lightmap_peak);
  scales.gltf = encoding_scale(Encoding::png, effective.quantity, lightmap_peak);
  if (out.per_light)
    scales.per_light = encoding_scale(out.encoding, effective.quantity, covered_peak(result, true));

  Manifest manifest;
  manifest.shadowbake = SHADOWBAKE_VERSION;
  manifest.scene = scene.file.string();
  manifest.method = effective.method;
  manifest.quantity = effective.quantity;
  manifest.resolution = effective.resolution;
  if (effective.texels_per_metre > 0) manifest.texels_per_metre = effective.texels_per_metre;
  manifest.samples = effective.samples;
  manifest.seed = effective.seed;
  manifest.margin = effective.margin;
  if (const MethodEntry* entry = find_method(effective.method))
    for (const std::string& key : entry->manifest_settings) {
      const SettingSpec* spec = find_method_setting(key);
      const auto given = effective.own.find(key);
      manifest.method_settings.emplace_back(
          key, given != effective.own.end() ? given->second : spec->fallback);
    }
  manifest.output = out;
  for (std::size_t l = 0; l < scene.lights.size(); ++l) {
    ManifestLight& light = manifest.lights.emplace_back();
    light.name = scene.lights[l].name;
    light.shape = scene.lights[l].shape;
    const double range = std::isfinite(scene.lights[l].range)
                             ? scene.lights[l].range
                             : range_for_floor(scene.lights[l], scene.bake.irradiance_floor);
    if (std::isfinite(range)) light.range = range;
    if (out.shadowmask && l < result.shadowmask_channels.size())
      light.shadowmask_channel = result.shadowmask_channels[l];
  }
  if (irradiance) manifest.png_white_point = white;

  std::vector<GltfTexture> textures;
  for (const Sheet& sheet : make_sheets(result)) {
    auto files = write_sheet(folder, scene, result, sheet, scales, irradiance, white,
                             out.gltf ? &textures : nullptr);
    if (!files) return files.error();
    if (sheet.atlas >= 0) {
      manifest.atlases.push_back({sheet.atlas, sheet.width, std::move(*files)});
    } else {
      ManifestReceiver entry = describe_receiver(result.receivers[sheet.receivers[0]], effective);
      entry.files = std::move(*files);
      manifest.receivers.push_back(std::move(entry));
    }
  }
  if (result.atlas) {
    for (std::size_t r = 0; r < result.receivers.size(); ++r) {
      const AtlasPlacement& p = result.atlas->placements[r];
      ManifestReceiver entry = describe_receiver(result.receivers[r], effective);
      entry.atlas = ManifestAtlasPlacement{
          p.atlas, p.x, p.y, p.side,
          atlas_scale_offset(p, result.atlas->sizes[std::size_t(p.atlas)], /*v_up=*/true)};
      manifest.receivers.push_back(std::move(entry));
    }
  }

  if (out.gltf) {
    std::vector<GltfObject> objects;
    for (std::size_t r = 0; r < result.receivers.size(); ++r) {
      const ReceiverBake& rb = result.receivers[r];
      GltfLightmap lightmap;
      lightmap.intensity = scales.gltf;
      if (result.atlas) {
        const AtlasPlacement& p = result.atlas->placements[r];
        lightmap.texture = p.atlas;
        lightmap.transform =
            atlas_scale_offset(p, result.atlas->sizes[std::size_t(p.atlas)], /*v_up=*/false);
      } else {
        lightmap.texture = int(r);
      }
      objects.push_back({rb.name, rb.gltf_mesh.get(), lightmap});
    }
    for (const auto& [name, mesh] : result.gltf_blockers)
      objects.push_back({name, mesh.get(), std::nullopt});
    auto glb = glb_bytes(objects, textures, to_string(effective.quantity),
                         std::string("shadowbake ") + SHADOWBAKE_VERSION);
    if (!glb) return glb.error();
    if (Status s = write_text_file(folder.staged(kGltfFile), std::string(glb->begin(), glb->end()));
        !s)
      return s;
    manifest.gltf = kGltfFile;
  }

  manifest.warnings = result.warnings;
  manifest.load_seconds = result.load_seconds;
  manifest.bake_seconds = result.bake_seconds;
  manifest.shadow_rays = result.shadow_rays;

  if (Status s =
          write_text_file(folder.staged(kManifestFile), manifest_to_json(manifest).dump(2) + "\n");
      !s)
    return s;
  // Incremental bakes: every receiver's raw result, for the next bake into this folder.
  const bool keep_cache = !result.receivers.empty() && !result.receivers[0].reuse.empty();
  std::vector<std::string> all = names;
  if (keep_cache) {
    auto staged = stage_cache(folder, result);
    if (!staged) return staged.error();
    all.insert(all.end(), staged->begin(), staged->end());
  }
  if (Status s = folder.publish(all); !s) return s;
  if (keep_cache) prune_cache(folder.dir(), result);
  return Ok{};
}

}  // namespace sb
