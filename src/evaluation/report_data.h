// What a report says, before it is drawn (report_data.cpp): every method's bake of a scene
// compared with the reference's, receiver by receiver, with the images the page shows staged.
// report_json.h and report_page.h render it; docs/reports.md explains every number.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "evaluation/image_metrics.h"
#include "formats/output_folder.h"
#include "scene/scene.h"

namespace sb {

// One method's bakes of the scene, as the report command ran them.
struct MethodRun {
  std::string method;
  std::vector<double> bake_seconds;  // per repetition, in-process (manifest.json bake_seconds)
  double peak_memory_mib = 0;        // largest resident set of a bake process
  std::filesystem::path folder;      // one bake's outputs: manifest.json, <receiver>.exr, .png,
                                     // <receiver>.coverage.png
  std::string error;                 // non-empty: the method failed; the message says why
};

// The median of a run's bake times; NaN when it has none.
double median_seconds(const MethodRun& run);

// One method on one receiver.
struct ReportCell {
  std::string error;  // why there are no metrics
  std::optional<Comparison> comparison;
  std::string texture, difference;  // image paths relative to the report folder ("" if none)
  // The manifest's penumbra_error (the convolution's own estimate), when it has one.
  std::optional<double> predicted_metres, predicted_texels;
};

struct ReceiverReport {
  std::string name;
  std::string error;  // the reference's images could not be read
  std::int64_t covered_texels = 0, penumbra_texels = 0;
  std::string reference_texture;  // relative to the report folder
  double heat_scale = 0;          // the difference maps saturate at ±heat_scale
  std::vector<ReportCell> cells;  // one per method, in ReportData::methods' order
};

// A method's metrics over all receivers. Covered metrics weight each receiver by its covered
// texels (RMSE as the root of the weighted mean square); the penumbra RMSE pools penumbra texels.
struct MethodSummary {
  bool has_metrics = false;
  std::int64_t texels = 0, penumbra_texels = 0;
  double rmse = 0, mae = 0, max_abs = 0, psnr = 0, ssim = 0, penumbra_rmse = 0;
};

struct MethodSection {
  MethodRun run;  // its error also says when its manifest could not be read
  MethodSummary overall;
};

struct ReportData {
  Scene scene;
  bool irradiance = false;                // the scene bakes irradiance (W/m²), else visibility
  MethodRun reference;                    // its error also says when its manifest could not be read
  int reference_samples = 0;              // the reference manifest's samples; 0 when unknown
  std::vector<MethodSection> methods;     // in the order they were given
  std::vector<ReceiverReport> receivers;  // the reference manifest's, in its order; none when
                                          // the reference failed
  std::vector<std::string> images;        // every image staged, relative to the report folder
};

// Reads the manifests and EXRs of every run and of the reference, compares each run with the
// reference receiver by receiver over the reference's coverage (image_metrics.h), and stages in
// `folder` the textures and difference heat maps the page shows. A run that failed, or whose
// files cannot be read, keeps the reason as an error and has no metrics. Errors only for an image
// that cannot be staged.
Expected<ReportData> compute_report_data(const Scene& scene, const std::vector<MethodRun>& runs,
                                         const MethodRun& reference, OutputFolder& folder);

}  // namespace sb
