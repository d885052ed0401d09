// The report of `shadowbake report` (report.cpp): every method's bake of a scene compared with
// the reference, as report.json and a self-contained index.html (docs/reports.md).
#pragma once

#include <vector>

#include "core/error.h"
#include "evaluation/report_data.h"
#include "formats/output_folder.h"
#include "scene/scene.h"

namespace sb {

// Compares each run's textures with the reference's, receiver by receiver (report_data.h), and
// publishes into `folder` (all or nothing): report.json (report_json.h), index.html
// (report_page.h; no external resources: images are files in the folder referenced relatively,
// the plot is inline SVG), the textures and difference heat maps it shows. A failed run appears
// with its error and without metrics.
Status write_report(const Scene& scene, const std::vector<MethodRun>& runs,
                    const MethodRun& reference, OutputFolder& folder);

}  // namespace sb
