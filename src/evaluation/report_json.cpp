// report.json: the scene's settings, per method its times and summary over receivers, and per
// receiver and method its metrics (metrics_json.h) and the convolution's predicted penumbra error.
#include "evaluation/report_json.h"

#include <nlohmann/json.hpp>

#include "evaluation/metrics_json.h"

namespace sb {

namespace {

using json = nlohmann::ordered_json;

json optional_text(const std::string& text) { return text.empty() ? json(nullptr) : json(text); }

json scene_json(const Scene& scene) {
  json settings = {{"file", scene.file.string()},
                   {"resolution", scene.bake.resolution},
                   {"quantity", to_string(scene.bake.quantity)},
                   {"samples", scene.bake.samples},
                   {"margin", scene.bake.margin},
                   {"seed", scene.bake.seed},
                   {"lights", json::array()},
                   {"objects", json::array()}};
  for (const auto& l : scene.lights)
    settings["lights"].push_back(
        {{"name", l.name}, {"shape", to_string(l.shape)}, {"power", l.power}});
  for (const auto& o : scene.objects)
    settings["objects"].push_back(
        {{"name", o.name}, {"receiver", o.receiver}, {"blocker", o.blocker}});
  return settings;
}

json run_json(const MethodRun& run, const std::filesystem::path& report_dir) {
  return {{"method", run.method},
          {"folder", run.folder.empty() ? json(nullptr)
                                        : json(run.folder.lexically_relative(report_dir).string())},
          {"median_seconds", run.bake_seconds.empty() ? json(nullptr) : json(median_seconds(run))},
          {"bake_seconds", run.bake_seconds},
          {"peak_memory_mib", run.peak_memory_mib},
          {"error", optional_text(run.error)}};
}

json summary_json(const MethodSummary& s) {
  if (!s.has_metrics) return nullptr;
  return {{"covered",
           {{"texels", s.texels},
            {"rmse", s.rmse},
            {"mae", s.mae},
            {"max", s.max_abs},
            {"psnr", json_number(s.psnr)},
            {"ssim", s.ssim}}},
          {"penumbra",
           {{"texels", s.penumbra_texels},
            {"rmse", s.penumbra_texels > 0 ? json(s.penumbra_rmse) : json(nullptr)}}}};
}

json cell_json(const ReportCell& cell, const std::string& method) {
  json c = {{"method", method}};
  if (cell.comparison) {
    c["covered"] = to_json(cell.comparison->covered);
    c["penumbra"] = to_json(cell.comparison->penumbra);
    c["non_finite_texels"] = cell.comparison->non_finite_a;
    c["image"] = cell.texture;
    c["difference_image"] = cell.difference;
  }
  if (cell.predicted_metres) {
    c["predicted_penumbra_error"] = {{"metres", *cell.predicted_metres},
                                     {"texels", *cell.predicted_texels}};
    if (cell.comparison) c["measured_penumbra_rmse"] = cell.comparison->penumbra.overall.rmse;
  }
  c["error"] = optional_text(cell.error);
  return c;
}

}  // namespace

std::string report_json(const ReportData& data, const std::filesystem::path& report_dir) {
  json report;
  report["shadowbake"] = SHADOWBAKE_VERSION;
  report["scene"] = scene_json(data.scene);
  report["reference"] = run_json(data.reference, report_dir);
  report["reference"]["samples"] =
      data.reference_samples > 0 ? json(data.reference_samples) : json(nullptr);
  report["weighting"] =
      "overall covered metrics: receivers weighted by covered texels (RMSE: root of the weighted "
      "mean square; max: largest); penumbra RMSE: pooled over penumbra texels";
  report["methods"] = json::array();
  for (const auto& method : data.methods) {
    json j = run_json(method.run, report_dir);
    j["overall"] = summary_json(method.overall);
    report["methods"].push_back(j);
  }
  report["receivers"] = json::array();
  for (const auto& receiver : data.receivers) {
    json r = {{"name", receiver.name},
              {"covered_texels", receiver.covered_texels},
              {"penumbra_texels", receiver.penumbra_texels},
              {"error", optional_text(receiver.error)},
              {"reference_image", optional_text(receiver.reference_texture)},
              {"difference_scale", receiver.heat_scale},
              {"methods", json::array()}};
    for (std::size_t m = 0; m < data.methods.size(); ++m)
      r["methods"].push_back(cell_json(receiver.cells[m], data.methods[m].run.method));
    report["receivers"].push_back(r);
  }
  return report.dump(2) + "\n";
}

}  // namespace sb
