// A report's comparisons: each run's textures against the reference's, receiver by receiver
// (image_metrics.h), the per-method summary over receivers, and the textures and difference heat
// maps the page shows, staged as they are made so that no more than one receiver's images are
// held at once.
#include "evaluation/report_data.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <string_view>

#include "core/image_io.h"
#include "formats/manifest.h"
#include "formats/outputs.h"

namespace sb {

namespace {

namespace fs = std::filesystem;

// A file-name stem that needs no escaping in a relative URL: letters, digits, '.', '_', '-'.
std::string url_safe(std::string_view name) {
  std::string out;
  for (const char c : name) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                       c == '_' || c == '-' || (c == '.' && !out.empty());
    out += plain ? c : '_';
  }
  return out.empty() ? std::string("_") : out;
}

// The run's manifest; none, with the reason in run.error, when it failed or has none.
std::optional<Manifest> manifest_of(MethodRun& run) {
  if (!run.error.empty()) return std::nullopt;
  auto manifest = read_manifest(run.folder);
  if (!manifest) {
    run.error = manifest.error().message;
    return std::nullopt;
  }
  return std::move(*manifest);
}

const ManifestReceiver* find_receiver(const std::optional<Manifest>& manifest,
                                      const std::string& name) {
  if (!manifest) return nullptr;
  for (const auto& r : manifest->receivers)
    if (r.name == name) return &r;
  return nullptr;
}

// Copies a file into the report's staging folder.
Status copy_into_staging(const fs::path& from, const fs::path& to) {
  std::ifstream in(from, std::ios::binary);
  if (!in) return input_error(from.string() + ": cannot read");
  std::stringstream bytes;
  bytes << in.rdbuf();
  return write_text_file(to, bytes.str());
}

// Names and stages the report's images, remembering every file it staged.
class ImageStager {
 public:
  ImageStager(OutputFolder& folder, bool irradiance, double white)
      : folder_(folder), irradiance_(irradiance), white_(white) {}

  // A name under images/, unique even where two stems map to one safe stem.
  std::string name(const std::string& stem) {
    const std::string base = "images/" + url_safe(stem);
    std::string candidate = base + ".png";
    for (int i = 2; used_.count(candidate); ++i) candidate = fmt::format("{}_{}.png", base, i);
    used_.insert(candidate);
    return candidate;
  }

  // The texture shown for a bake: its preview, or for irradiance its EXR tone-mapped with the
  // reference's white point, so every method is shown at one exposure.
  Status stage_texture(const fs::path& bake_folder, const ManifestReceiver& entry, const Image& exr,
                       const std::string& relative) {
    staged_.push_back(relative);
    if (irradiance_) {
      return write_image(folder_.staged(relative), tone_map_irradiance(exr, white_),
                         PixelFormat::uint8);
    }
    return copy_into_staging(bake_folder / entry.files->preview->file, folder_.staged(relative));
  }

  Status stage_image(const Image& image, const std::string& relative) {
    staged_.push_back(relative);
    return write_image(folder_.staged(relative), image, PixelFormat::uint8);
  }

  std::vector<std::string> staged() && { return std::move(staged_); }

 private:
  OutputFolder& folder_;
  bool irradiance_;
  double white_;
  std::set<std::string> used_;
  std::vector<std::string> staged_;
};

MethodSummary summarise(const std::vector<ReceiverReport>& receivers, std::size_t method) {
  MethodSummary s;
  double square_sum = 0, abs_sum = 0, ssim_sum = 0, penumbra_square_sum = 0, peak = 0;
  for (const auto& receiver : receivers) {
    const ReportCell& cell = receiver.cells[method];
    // An empty region's metrics are NaN; it adds nothing.
    if (!cell.comparison || cell.comparison->covered.texels == 0) continue;
    const Comparison& c = *cell.comparison;
    const double w = double(c.covered.texels);
    s.has_metrics = true;
    s.texels += c.covered.texels;
    square_sum += w * c.covered.overall.rmse * c.covered.overall.rmse;
    abs_sum += w * c.covered.overall.mae;
    ssim_sum += w * c.covered.overall.ssim;
    s.max_abs = std::max(s.max_abs, c.covered.overall.max_abs);
    peak = std::max(peak, c.peak);
    if (c.penumbra.texels == 0) continue;
    s.penumbra_texels += c.penumbra.texels;
    penumbra_square_sum +=
        double(c.penumbra.texels) * c.penumbra.overall.rmse * c.penumbra.overall.rmse;
  }
  if (s.texels > 0) {
    const double mse = square_sum / double(s.texels);
    s.rmse = std::sqrt(mse);
    s.mae = abs_sum / double(s.texels);
    s.ssim = ssim_sum / double(s.texels);
    s.psnr = mse > 0 ? 10 * std::log10(peak * peak / mse) : std::numeric_limits<double>::infinity();
  }
  if (s.penumbra_texels > 0)
    s.penumbra_rmse = std::sqrt(penumbra_square_sum / double(s.penumbra_texels));
  return s;
}

// Compares every method with the reference on the receiver of the reference manifest's `entry`,
// staging its images.
Expected<ReceiverReport> compare_receiver(const ManifestReceiver& entry, const MethodRun& reference,
                                          const std::vector<MethodSection>& methods,
                                          const std::vector<std::optional<Manifest>>& manifests,
                                          bool irradiance, ImageStager& images) {
  ReceiverReport receiver;
  receiver.name = entry.name;
  receiver.cells.resize(methods.size());
  if (!entry.files || !entry.files->preview) {
    receiver.error = (reference.folder / kManifestFile).string() + ": receiver '" + entry.name +
                     "' has no float lightmap of its own (an atlas, or an 8-bit encoding)";
    for (auto& cell : receiver.cells) cell.error = "no reference: " + receiver.error;
    return receiver;
  }
  auto ref_image = read_image(reference.folder / entry.files->lightmap.file);
  auto coverage = read_image(reference.folder / entry.files->coverage.file);
  if (!ref_image || !coverage) {
    receiver.error = !ref_image ? ref_image.error().message : coverage.error().message;
    for (auto& cell : receiver.cells) cell.error = "no reference: " + receiver.error;
    return receiver;
  }
  CompareOptions options;
  options.peak = irradiance ? 0.0 : 1.0;
  options.mask.resize(std::size_t(coverage->width) * coverage->height);
  for (std::size_t i = 0; i < options.mask.size(); ++i)
    options.mask[i] = coverage->pixels[i * coverage->channels] > 0.5f ? 1 : 0;

  // Named after its folder (reference-<N>spp): a `reference` method may be compared too.
  receiver.reference_texture =
      images.name(reference.folder.filename().string() + "_" + receiver.name);
  if (auto s =
          images.stage_texture(reference.folder, entry, *ref_image, receiver.reference_texture);
      !s)
    return s.error();

  std::vector<std::optional<Image>> method_images(methods.size());
  for (std::size_t m = 0; m < methods.size(); ++m) {
    const MethodRun& run = methods[m].run;
    ReportCell& cell = receiver.cells[m];
    if (!run.error.empty()) {
      cell.error = run.error;
      continue;
    }
    const ManifestReceiver* run_entry = find_receiver(manifests[m], receiver.name);
    if (!run_entry) {
      cell.error = (run.folder / kManifestFile).string() + ": no receiver '" + receiver.name + "'";
      continue;
    }
    // The convolution's own entry (its MethodReport::manifest).
    if (const auto& own = run_entry->method_entries; own.contains("penumbra_error")) {
      cell.predicted_metres = own["penumbra_error"].value("metres", 0.0);
      cell.predicted_texels = own["penumbra_error"].value("texels", 0.0);
    }
    if (!run_entry->files || !run_entry->files->preview) {
      cell.error = (run.folder / kManifestFile).string() + ": receiver '" + receiver.name +
                   "' has no float lightmap of its own";
      continue;
    }
    const fs::path exr = run.folder / run_entry->files->lightmap.file;
    auto image = read_image(exr);
    if (!image) {
      cell.error = image.error().message;
      continue;
    }
    auto comparison = compare_images(*image, *ref_image, options, exr.string(),
                                     (reference.folder / receiver.name).string() + ".exr");
    if (!comparison) {
      cell.error = comparison.error().message;
      continue;
    }
    receiver.heat_scale = std::max(receiver.heat_scale, comparison->covered.overall.max_abs);
    receiver.covered_texels = comparison->covered.texels;
    receiver.penumbra_texels = comparison->penumbra.texels;
    cell.comparison = std::move(*comparison);
    cell.texture = images.name(run.method + "_" + receiver.name);
    if (auto s = images.stage_texture(run.folder, *run_entry, *image, cell.texture); !s)
      return s.error();
    method_images[m] = std::move(*image);
  }
  // One scale for every method's map of this receiver, so the maps compare at a glance.
  if (receiver.heat_scale <= 0) receiver.heat_scale = irradiance ? 1.0 : 0.01;
  for (std::size_t m = 0; m < methods.size(); ++m) {
    if (!method_images[m]) continue;
    ReportCell& cell = receiver.cells[m];
    cell.difference = images.name(methods[m].run.method + "_" + receiver.name + "_diff");
    const Image map =
        difference_heat_map(*method_images[m], *ref_image, options.mask, receiver.heat_scale, true);
    if (auto s = images.stage_image(map, cell.difference); !s) return s.error();
  }
  if (receiver.covered_texels == 0) receiver.covered_texels = entry.covered_texels;
  return receiver;
}

}  // namespace

double median_seconds(const MethodRun& run) {
  std::vector<double> values = run.bake_seconds;
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

Expected<ReportData> compute_report_data(const Scene& scene, const std::vector<MethodRun>& runs,
                                         const MethodRun& reference, OutputFolder& folder) {
  ReportData data;
  data.scene = scene;
  data.irradiance = scene.bake.quantity == Quantity::irradiance;
  std::vector<std::optional<Manifest>> manifests;
  for (const auto& run : runs) {
    data.methods.push_back({run, {}});
    manifests.push_back(manifest_of(data.methods.back().run));
  }
  data.reference = reference;
  const std::optional<Manifest> reference_manifest = manifest_of(data.reference);
  const double white = reference_manifest ? reference_manifest->png_white_point.value_or(1.0) : 1.0;
  data.reference_samples = reference_manifest ? reference_manifest->samples : 0;

  ImageStager images(folder, data.irradiance, white);
  if (reference_manifest) {
    for (const auto& entry : reference_manifest->receivers) {
      auto receiver =
          compare_receiver(entry, data.reference, data.methods, manifests, data.irradiance, images);
      if (!receiver) return receiver.error();
      data.receivers.push_back(std::move(*receiver));
    }
  }
  for (std::size_t m = 0; m < data.methods.size(); ++m)
    data.methods[m].overall = summarise(data.receivers, m);
  data.images = std::move(images).staged();
  return data;
}

}  // namespace sb
