// The report of `shadowbake report`: each method's textures compared with the reference's
// (image_metrics.h), written as report.json and a self-contained index.html whose error-versus-
// time plot is inline SVG drawn here (docs/reports.md explains every number).
#include "evaluation/report.h"

#include <fmt/core.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>

#include "evaluation/error_time_plot.h"
#include "core/image_io.h"
#include "evaluation/image_metrics.h"
#include "pipeline/outputs.h"

namespace sb {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

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

double median(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

Expected<json> read_manifest(const fs::path& folder) {
  const fs::path path = folder / "manifest.json";
  std::ifstream in(path, std::ios::binary);
  if (!in) return input_error(path.string() + ": cannot read the bake's manifest");
  json manifest = json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (manifest.is_discarded() || !manifest.contains("receivers") ||
      !manifest["receivers"].is_array()) {
    return input_error(path.string() + ": not a bake manifest (no receivers array)");
  }
  return manifest;
}

const json* find_receiver(const json& manifest, const std::string& name) {
  for (const auto& r : manifest["receivers"])
    if (r.value("name", "") == name) return &r;
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

// NaN (an empty region) and +inf (a PSNR of identical images) have no JSON number: null.
json finite_or_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json metrics_json(const RegionErrors& region) {
  const ChannelErrors& e = region.overall;
  return {{"texels", region.texels},       {"rmse", finite_or_null(e.rmse)},
          {"mae", finite_or_null(e.mae)},  {"max", finite_or_null(e.max_abs)},
          {"max_at", {e.max_x, e.max_y}},  {"psnr", finite_or_null(e.psnr)},
          {"ssim", finite_or_null(e.ssim)}};
}

// One method on one receiver.
struct Cell {
  std::string error;  // why there are no metrics
  std::optional<Comparison> comparison;
  std::string texture, difference;  // image paths relative to out_dir ("" if none)
  std::optional<double> predicted_metres, predicted_texels;
};

struct ReceiverRow {
  std::string name;
  std::string error;  // the reference's images could not be read
  std::int64_t covered_texels = 0, penumbra_texels = 0;
  std::string reference_texture;
  double heat_scale = 0;    // the difference maps saturate at ±heat_scale
  std::vector<Cell> cells;  // one per run
};

// A method's metrics over all receivers. Covered metrics weight each receiver by its covered
// texels (RMSE as the root of the weighted mean square); the penumbra RMSE pools penumbra texels.
struct Summary {
  bool has_metrics = false;
  std::int64_t texels = 0, penumbra_texels = 0;
  double rmse = 0, mae = 0, max_abs = 0, psnr = 0, ssim = 0, penumbra_rmse = 0;
};

Summary summarise(const std::vector<ReceiverRow>& rows, std::size_t run) {
  Summary s;
  double square_sum = 0, abs_sum = 0, ssim_sum = 0, penumbra_square_sum = 0, peak = 0;
  for (const auto& row : rows) {
    const Cell& cell = row.cells[run];
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

constexpr const char* kStyle = R"(
body { font-family: system-ui, -apple-system, "Segoe UI", Helvetica, Arial, sans-serif;
       margin: 24px auto; max-width: 1360px; padding: 0 16px; color: #222; background: #fafafa; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; }
h2 { margin-top: 1.6em; border-bottom: 1px solid #ccc; padding-bottom: 0.2em; }
table { border-collapse: collapse; margin: 0.6em 0; background: #fff; }
th, td { border: 1px solid #ccc; padding: 4px 10px; text-align: right; }
th { background: #eee; }
td.name, th.name { text-align: left; }
.error { color: #a00; }
td.error { text-align: left; }
p.note { color: #555; font-size: 0.9em; max-width: 70em; }
.row, .pair { display: flex; flex-wrap: wrap; gap: 12px; align-items: flex-start; }
.pair { flex-wrap: nowrap; gap: 6px; }
figure { margin: 0; background: #fff; border: 1px solid #ddd; padding: 6px; }
figure img { display: block; width: 224px; height: auto; image-rendering: pixelated; }
figcaption { font-size: 0.85em; margin-top: 4px; max-width: 224px; }
.failed { width: 224px; height: 224px; display: flex; align-items: center; justify-content: center;
          text-align: center; color: #a00; background: #fee; font-size: 0.9em; }
svg.plot text { font-family: inherit; }
svg.plot .tick { font-size: 12px; fill: #333; }
svg.plot .axis { font-size: 13px; fill: #111; }
svg.plot .label { font-size: 13px; fill: #111; }
)";

constexpr const char* kImageCheck = R"(
window.addEventListener("load", function () {
  var bad = [];
  for (var i = 0; i < document.images.length; i++) {
    var img = document.images[i];
    if (!img.complete || img.naturalWidth === 0) bad.push(img.getAttribute("src"));
  }
  document.body.dataset.imagesOk = bad.length === 0 ? "yes" : "no: " + bad.join(", ");
});
)";

}  // namespace

Status write_report(const Scene& scene, const std::vector<MethodRun>& runs_in,
                    const MethodRun& reference, OutputFolder& folder) {
  const fs::path& out_dir = folder.dir();
  std::vector<std::string> written;  // files to publish, relative to out_dir
  const bool irradiance = scene.bake.quantity == Quantity::irradiance;
  std::vector<MethodRun> runs = runs_in;
  std::vector<json> manifests(runs.size());
  for (std::size_t m = 0; m < runs.size(); ++m) {
    if (!runs[m].error.empty()) continue;
    auto manifest = read_manifest(runs[m].folder);
    if (manifest) {
      manifests[m] = std::move(*manifest);
    } else {
      runs[m].error = manifest.error().message;
    }
  }
  std::string reference_error = reference.error;
  json reference_manifest;
  if (reference_error.empty()) {
    auto manifest = read_manifest(reference.folder);
    if (manifest) {
      reference_manifest = std::move(*manifest);
    } else {
      reference_error = manifest.error().message;
    }
  }
  const double white =
      reference_manifest.is_object() ? reference_manifest.value("png_white_point", 1.0) : 1.0;

  // Image names, unique even where two names map to one safe stem.
  std::set<std::string> used_names;
  auto image_name = [&](const std::string& stem) {
    std::string name = "images/" + url_safe(stem);
    std::string candidate = name + ".png";
    for (int i = 2; used_names.count(candidate); ++i) candidate = fmt::format("{}_{}.png", name, i);
    used_names.insert(candidate);
    return candidate;
  };
  // The texture shown for a bake: its preview, or for irradiance the EXR tone-mapped with the
  // reference's white point, so every method is shown at one exposure.
  auto write_texture = [&](const fs::path& bake_folder, const json& entry, const Image* exr,
                           const std::string& relative) -> Status {
    if (irradiance && exr) {
      written.push_back(relative);
      return write_image(folder.staged(relative), tone_map_irradiance(*exr, white),
                         PixelFormat::uint8);
    }
    const std::string png = entry.contains("files") ? entry["files"].value("png", "") : "";
    written.push_back(relative);
    return copy_into_staging(bake_folder / png, folder.staged(relative));
  };

  std::vector<ReceiverRow> rows;
  if (reference_error.empty()) {
    for (const auto& entry : reference_manifest["receivers"]) {
      ReceiverRow row;
      row.name = entry.value("name", "");
      row.cells.resize(runs.size());
      const json files = entry.value("files", json::object());
      auto ref_image = read_image(reference.folder / files.value("exr", row.name + ".exr"));
      auto coverage =
          read_image(reference.folder / files.value("coverage", row.name + ".coverage.png"));
      if (!ref_image || !coverage) {
        row.error = !ref_image ? ref_image.error().message : coverage.error().message;
        for (auto& cell : row.cells) cell.error = "no reference: " + row.error;
        rows.push_back(std::move(row));
        continue;
      }
      CompareOptions options;
      options.peak = irradiance ? 0.0 : 1.0;
      options.mask.resize(std::size_t(coverage->width) * coverage->height);
      for (std::size_t i = 0; i < options.mask.size(); ++i)
        options.mask[i] = coverage->pixels[i * coverage->channels] > 0.5f ? 1 : 0;

      // Named after its folder (reference-<N>spp): a `reference` method may be compared too.
      row.reference_texture = image_name(reference.folder.filename().string() + "_" + row.name);
      if (auto s = write_texture(reference.folder, entry, &*ref_image, row.reference_texture); !s)
        return s.error();

      std::vector<std::optional<Image>> images(runs.size());
      for (std::size_t m = 0; m < runs.size(); ++m) {
        Cell& cell = row.cells[m];
        if (!runs[m].error.empty()) {
          cell.error = runs[m].error;
          continue;
        }
        const json* run_entry = find_receiver(manifests[m], row.name);
        if (!run_entry) {
          cell.error =
              (runs[m].folder / "manifest.json").string() + ": no receiver '" + row.name + "'";
          continue;
        }
        if (run_entry->contains("penumbra_error")) {
          cell.predicted_metres = (*run_entry)["penumbra_error"].value("metres", 0.0);
          cell.predicted_texels = (*run_entry)["penumbra_error"].value("texels", 0.0);
        }
        const json run_files = run_entry->value("files", json::object());
        const fs::path exr = runs[m].folder / run_files.value("exr", row.name + ".exr");
        auto image = read_image(exr);
        if (!image) {
          cell.error = image.error().message;
          continue;
        }
        auto comparison = compare_images(*image, *ref_image, options, exr.string(),
                                         (reference.folder / row.name).string() + ".exr");
        if (!comparison) {
          cell.error = comparison.error().message;
          continue;
        }
        row.heat_scale = std::max(row.heat_scale, comparison->covered.overall.max_abs);
        row.covered_texels = comparison->covered.texels;
        row.penumbra_texels = comparison->penumbra.texels;
        cell.comparison = std::move(*comparison);
        cell.texture = image_name(runs[m].method + "_" + row.name);
        if (auto s = write_texture(runs[m].folder, *run_entry, &*image, cell.texture); !s)
          return s.error();
        images[m] = std::move(*image);
      }
      // One scale for every method's map of this receiver, so the maps compare at a glance.
      if (row.heat_scale <= 0) row.heat_scale = irradiance ? 1.0 : 0.01;
      for (std::size_t m = 0; m < runs.size(); ++m) {
        if (!images[m]) continue;
        Cell& cell = row.cells[m];
        cell.difference = image_name(runs[m].method + "_" + row.name + "_diff");
        const Image map =
            difference_heat_map(*images[m], *ref_image, options.mask, row.heat_scale, true);
        written.push_back(cell.difference);
        if (auto s = write_image(folder.staged(cell.difference), map, PixelFormat::uint8); !s)
          return s.error();
      }
      if (row.covered_texels == 0)
        row.covered_texels = entry.value("covered_texels", std::int64_t(0));
      rows.push_back(std::move(row));
    }
  }
  std::vector<Summary> summaries;
  for (std::size_t m = 0; m < runs.size(); ++m) summaries.push_back(summarise(rows, m));

  // report.json
  const int reference_samples =
      reference_manifest.is_object() ? reference_manifest.value("samples", 0) : 0;
  json report;
  report["shadowbake"] = SHADOWBAKE_VERSION;
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
  report["scene"] = settings;
  auto run_json = [&](const MethodRun& run, const std::string& error) {
    json j = {
        {"method", run.method},
        {"folder", run.folder.empty() ? json(nullptr)
                                      : json(run.folder.lexically_relative(out_dir).string())},
        {"median_seconds",
         run.bake_seconds.empty() ? json(nullptr) : json(median(run.bake_seconds))},
        {"bake_seconds", run.bake_seconds},
        {"peak_memory_mib", run.peak_memory_mib},
        {"error", error.empty() ? json(nullptr) : json(error)}};
    return j;
  };
  report["reference"] = run_json(reference, reference_error);
  report["reference"]["samples"] = reference_samples > 0 ? json(reference_samples) : json(nullptr);
  report["weighting"] =
      "overall covered metrics: receivers weighted by covered texels (RMSE: root of the weighted "
      "mean square; max: largest); penumbra RMSE: pooled over penumbra texels";
  report["methods"] = json::array();
  for (std::size_t m = 0; m < runs.size(); ++m) {
    json j = run_json(runs[m], runs[m].error);
    const Summary& s = summaries[m];
    if (s.has_metrics) {
      j["overall"] = {{"covered",
                       {{"texels", s.texels},
                        {"rmse", s.rmse},
                        {"mae", s.mae},
                        {"max", s.max_abs},
                        {"psnr", finite_or_null(s.psnr)},
                        {"ssim", s.ssim}}},
                      {"penumbra",
                       {{"texels", s.penumbra_texels},
                        {"rmse", s.penumbra_texels > 0 ? json(s.penumbra_rmse) : json(nullptr)}}}};
    } else {
      j["overall"] = nullptr;
    }
    report["methods"].push_back(j);
  }
  report["receivers"] = json::array();
  for (const auto& row : rows) {
    json r = {{"name", row.name},
              {"covered_texels", row.covered_texels},
              {"penumbra_texels", row.penumbra_texels},
              {"error", row.error.empty() ? json(nullptr) : json(row.error)},
              {"reference_image",
               row.reference_texture.empty() ? json(nullptr) : json(row.reference_texture)},
              {"difference_scale", row.heat_scale},
              {"methods", json::array()}};
    for (std::size_t m = 0; m < runs.size(); ++m) {
      const Cell& cell = row.cells[m];
      json c = {{"method", runs[m].method}};
      if (cell.comparison) {
        c["covered"] = metrics_json(cell.comparison->covered);
        c["penumbra"] = metrics_json(cell.comparison->penumbra);
        c["non_finite_texels"] = cell.comparison->non_finite_a;
        c["image"] = cell.texture;
        c["difference_image"] = cell.difference;
      }
      if (cell.predicted_metres) {
        c["predicted_penumbra_error"] = {{"metres", *cell.predicted_metres},
                                         {"texels", *cell.predicted_texels}};
        if (cell.comparison) c["measured_penumbra_rmse"] = cell.comparison->penumbra.overall.rmse;
      }
      c["error"] = cell.error.empty() ? json(nullptr) : json(cell.error);
      r["methods"].push_back(c);
    }
    report["receivers"].push_back(r);
  }

  // index.html
  const std::string scene_name = scene.file.filename().string();
  std::string html = fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<title>shadowbake report: {0}</title>\n<style>{1}</style>\n<script>{2}</script>\n"
      "</head>\n<body>\n<h1>shadowbake report: {0}</h1>\n"
      "<p class=\"note\">Made by shadowbake {3}. Every method's lightmaps compared with a "
      "reference bake, texel by texel, over the texels the receivers' triangles cover "
      "(docs/reports.md explains each number).</p>\n",
      html_escape(scene_name), kStyle, kImageCheck, SHADOWBAKE_VERSION);

  html += "<h2>Scene</h2>\n<table>\n";
  auto setting_row = [&](const std::string& name, const std::string& value) {
    html += fmt::format("<tr><th class=\"name\">{}</th><td class=\"name\">{}</td></tr>\n",
                        html_escape(name), html_escape(value));
  };
  setting_row("scene file", scene.file.string());
  setting_row("resolution", fmt::format("{0} × {0} texels per receiver", scene.bake.resolution));
  setting_row("quantity", to_string(scene.bake.quantity));
  setting_row("samples", fmt::format("{} per texel (sampling methods)", scene.bake.samples));
  setting_row("reference samples",
              reference_samples > 0 ? fmt::format("{} per texel", reference_samples) : "—");
  setting_row("margin", fmt::format("{} texels", scene.bake.margin));
  std::string lights;
  for (const auto& l : scene.lights)
    lights += fmt::format("{}{} ({}, {:g} W)", lights.empty() ? "" : "; ", l.name,
                          to_string(l.shape), l.power);
  setting_row(fmt::format("lights ({})", scene.lights.size()), lights);
  std::string objects;
  for (const auto& o : scene.objects) {
    const char* role = o.receiver && o.blocker ? "receiver, blocker"
                       : o.receiver            ? "receiver"
                       : o.blocker             ? "blocker"
                                               : "neither";
    objects += fmt::format("{}{} ({})", objects.empty() ? "" : "; ", o.name, role);
  }
  setting_row(fmt::format("objects ({})", scene.objects.size()), objects);
  html += "</table>\n";

  html += fmt::format(
      "<h2>Methods</h2>\n<table>\n<tr><th class=\"name\">method</th><th>median bake time</th>"
      "<th>runs</th><th>peak memory</th><th>RMSE</th><th>MAE</th><th>max</th><th>PSNR</th>"
      "<th>SSIM</th><th>penumbra RMSE</th></tr>\n");
  auto time_cells = [&](const MethodRun& run) {
    return fmt::format(
        "<td>{}</td><td>{}</td><td>{}</td>",
        run.bake_seconds.empty() ? "—" : seconds_text(median(run.bake_seconds)),
        run.bake_seconds.size(),
        run.peak_memory_mib > 0 ? fmt::format("{:.0f} MiB", run.peak_memory_mib) : "—");
  };
  html += fmt::format("<tr><td class=\"name\">reference ({} samples)</td>{}",
                      reference_samples > 0 ? std::to_string(reference_samples) : "?",
                      time_cells(reference));
  html += reference_error.empty()
              ? "<td colspan=\"6\" class=\"name\">the reference every method is compared with</td>"
              : fmt::format("<td colspan=\"6\" class=\"error\">failed: {}</td>",
                            html_escape(reference_error));
  html += "</tr>\n";
  for (std::size_t m = 0; m < runs.size(); ++m) {
    const Summary& s = summaries[m];
    html += fmt::format("<tr><td class=\"name\">{}</td>{}", html_escape(runs[m].method),
                        time_cells(runs[m]));
    if (!runs[m].error.empty()) {
      html += fmt::format("<td colspan=\"6\" class=\"error\">failed: {}</td>",
                          html_escape(runs[m].error));
    } else if (!s.has_metrics) {
      html += "<td colspan=\"6\" class=\"error\">no metrics: see the receivers below</td>";
    } else {
      html += fmt::format("<td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>",
                          number(s.rmse), number(s.mae), number(s.max_abs),
                          std::isfinite(s.psnr) ? fmt::format("{:.1f} dB", s.psnr) : "∞",
                          number(s.ssim), s.penumbra_texels > 0 ? number(s.penumbra_rmse) : "—");
    }
    html += "</tr>\n";
  }
  html += fmt::format(
      "</table>\n<p class=\"note\">Times are the median of each method's bakes (bake_seconds of "
      "its manifest: texel space, method and dilation, without loading and writing); peak memory "
      "is the largest resident set of a bake process. Errors are {} differences from the "
      "reference over covered texels, averaged over receivers weighted by their covered texels "
      "(RMSE as the root of the weighted mean square, max as the largest); PSNR uses a peak of "
      "{}. Penumbra RMSE pools the covered texels where the reference is strictly between 0.02 "
      "and 0.98.</p>\n",
      irradiance ? "irradiance (W/m²)" : "visibility",
      irradiance ? "the reference's largest covered value" : "1");

  html += "<h2>Error versus time</h2>\n";
  std::vector<PlotPoint> points;
  for (std::size_t m = 0; m < runs.size(); ++m)
    if (summaries[m].has_metrics && !runs[m].bake_seconds.empty())
      points.push_back({runs[m].method, median(runs[m].bake_seconds), summaries[m].rmse});
  if (points.empty()) {
    html += "<p class=\"note\">No method has metrics to plot.</p>\n";
  } else {
    html += error_time_plot(points, irradiance ? "covered RMSE (W/m²)" : "covered RMSE");
  }

  // The convolution's own estimate of its penumbra error, beside the measured one.
  std::string predicted;
  for (const auto& row : rows) {
    for (std::size_t m = 0; m < runs.size(); ++m) {
      const Cell& cell = row.cells[m];
      if (!cell.predicted_metres) continue;
      predicted += fmt::format(
          "<tr><td class=\"name\">{}</td><td class=\"name\">{}</td><td>{}</td><td>{}</td>"
          "<td>{}</td><td>{}</td></tr>\n",
          html_escape(runs[m].method), html_escape(row.name), number(*cell.predicted_metres),
          number(*cell.predicted_texels),
          cell.comparison ? number(cell.comparison->penumbra.overall.rmse) : "—",
          cell.comparison ? std::to_string(cell.comparison->penumbra.texels) : "—");
    }
  }
  if (!predicted.empty()) {
    html +=
        "<h2>Predicted and measured penumbra error</h2>\n<table>\n<tr><th class=\"name\">method"
        "</th><th class=\"name\">receiver</th><th>predicted (metres)</th><th>predicted (texels)"
        "</th><th>measured penumbra RMSE</th><th>penumbra texels</th></tr>\n" +
        predicted +
        "</table>\n<p class=\"note\">The prediction is the convolution's bound on how far a "
        "penumbra moves on the receiver (its manifest's penumbra_error, the worst over the "
        "lights); the measurement is the RMSE of the shadow over the reference's penumbra "
        "texels. They are in different units: a larger prediction should go with a larger "
        "measured error.</p>\n";
  }

  html += "<h2>Receivers</h2>\n";
  if (!reference_error.empty())
    html += fmt::format("<p class=\"error\">No comparisons: the reference failed: {}</p>\n",
                        html_escape(reference_error));
  for (const auto& row : rows) {
    html += fmt::format("<h3>{}</h3>\n", html_escape(row.name));
    if (!row.error.empty()) {
      html += fmt::format("<p class=\"error\">{}</p>\n", html_escape(row.error));
      continue;
    }
    html += fmt::format(
        "<p class=\"note\">{} covered texels, {} in the penumbra. Difference maps show method − "
        "reference: red above, blue below, white equal, grey uncovered; saturating at ±{}.</p>\n"
        "<div class=\"row\">\n<figure><img src=\"{}\" alt=\"reference\"><figcaption>reference ({} "
        "samples)"
        "</figcaption></figure>\n",
        row.covered_texels, row.penumbra_texels, number(row.heat_scale),
        html_escape(row.reference_texture), reference_samples);
    for (std::size_t m = 0; m < runs.size(); ++m) {
      const Cell& cell = row.cells[m];
      const std::string method = html_escape(runs[m].method);
      if (!cell.comparison) {
        html += fmt::format(
            "<figure><div class=\"failed\">{}: {}</div><figcaption>{}: no metrics</figcaption>"
            "</figure>\n",
            method, html_escape(cell.error), method);
        continue;
      }
      const auto& c = cell.comparison->covered.overall;
      html += fmt::format(
          "<div class=\"pair\"><figure><img src=\"{}\" alt=\"{}\"><figcaption>{}: RMSE {}, "
          "max {}, SSIM {}</figcaption></figure>\n"
          "<figure><img src=\"{}\" alt=\"{} difference\"><figcaption>{} − reference (±{})"
          "</figcaption></figure></div>\n",
          html_escape(cell.texture), method, method, number(c.rmse), number(c.max_abs),
          number(c.ssim), html_escape(cell.difference), method, method, number(row.heat_scale));
    }
    html += "</div>\n";
  }
  html += "</body>\n</html>\n";

  // Every file appears together, or none does.
  if (auto s = write_text_file(folder.staged("report.json"), report.dump(2) + "\n"); !s) return s;
  if (auto s = write_text_file(folder.staged("index.html"), html); !s) return s;
  written.push_back("report.json");
  written.push_back("index.html");
  return folder.publish(written);
}

}  // namespace sb
