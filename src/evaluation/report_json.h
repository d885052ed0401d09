// report.json (report_json.cpp): a report's data for scripts, its comparisons in the encoding
// compare.json uses (metrics_json.h); docs/reports.md lists the fields.
#pragma once

#include <filesystem>
#include <string>

#include "evaluation/report_data.h"

namespace sb {

// The text of report.json; bake folders are written relative to `report_dir`.
std::string report_json(const ReportData& data, const std::filesystem::path& report_dir);

}  // namespace sb
