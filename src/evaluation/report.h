// The report of `shadowbake report` (report.cpp): every method's bake of a scene compared with
// the reference, as report.json and a self-contained index.html (docs/reports.md).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"
#include "pipeline/output_folder.h"
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

// Compares each run's textures with the reference's, receiver by receiver (image_metrics), and
// publishes into `folder` (all or nothing): report.json, index.html (no external resources: images
// are files in out_dir referenced relatively, the plot is inline SVG), the textures and difference
// heat maps it shows. A failed run appears with its error and without metrics.
Status write_report(const Scene& scene, const std::vector<MethodRun>& runs,
                    const MethodRun& reference, OutputFolder& folder);

}  // namespace sb
