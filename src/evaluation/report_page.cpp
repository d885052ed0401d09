// The report page, drawn from a report's data; every name that came from outside (a scene, a
// method, an error message) is HTML-escaped. docs/reports.md explains every number on it.
#include "evaluation/report_page.h"

#include <fmt/core.h>

#include <cmath>
#include <string>
#include <vector>

#include "evaluation/error_time_plot.h"

namespace sb {

namespace {

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

// Sets data-images-ok on <body> once the page has loaded: "yes", or "no: " and the images that
// did not decode (tests/tools/check_report_page.sh reads it).
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

std::string scene_section(const ReportData& data) {
  const Scene& scene = data.scene;
  std::string html = "<h2>Scene</h2>\n<table>\n";
  auto setting_row = [&](const std::string& name, const std::string& value) {
    html += fmt::format("<tr><th class=\"name\">{}</th><td class=\"name\">{}</td></tr>\n",
                        html_escape(name), html_escape(value));
  };
  setting_row("scene file", scene.file.string());
  setting_row("resolution", fmt::format("{0} × {0} texels per receiver", scene.bake.resolution));
  setting_row("quantity", to_string(scene.bake.quantity));
  setting_row("samples", fmt::format("{} per texel (sampling methods)", scene.bake.samples));
  setting_row("reference samples", data.reference_samples > 0
                                       ? fmt::format("{} per texel", data.reference_samples)
                                       : "—");
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
  return html;
}

// Median bake time, number of bakes and peak memory, as three cells.
std::string time_cells(const MethodRun& run) {
  return fmt::format(
      "<td>{}</td><td>{}</td><td>{}</td>",
      run.bake_seconds.empty() ? "—" : seconds_text(median_seconds(run)), run.bake_seconds.size(),
      run.peak_memory_mib > 0 ? fmt::format("{:.0f} MiB", run.peak_memory_mib) : "—");
}

std::string methods_section(const ReportData& data) {
  std::string html =
      "<h2>Methods</h2>\n<table>\n<tr><th class=\"name\">method</th><th>median bake time</th>"
      "<th>runs</th><th>peak memory</th><th>RMSE</th><th>MAE</th><th>max</th><th>PSNR</th>"
      "<th>SSIM</th><th>penumbra RMSE</th></tr>\n";
  html += fmt::format("<tr><td class=\"name\">reference ({} samples)</td>{}",
                      data.reference_samples > 0 ? std::to_string(data.reference_samples) : "?",
                      time_cells(data.reference));
  html += data.reference.error.empty()
              ? "<td colspan=\"6\" class=\"name\">the reference every method is compared with</td>"
              : fmt::format("<td colspan=\"6\" class=\"error\">failed: {}</td>",
                            html_escape(data.reference.error));
  html += "</tr>\n";
  for (const auto& method : data.methods) {
    const MethodSummary& s = method.overall;
    html += fmt::format("<tr><td class=\"name\">{}</td>{}", html_escape(method.run.method),
                        time_cells(method.run));
    if (!method.run.error.empty()) {
      html += fmt::format("<td colspan=\"6\" class=\"error\">failed: {}</td>",
                          html_escape(method.run.error));
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
      data.irradiance ? "irradiance (W/m²)" : "visibility",
      data.irradiance ? "the reference's largest covered value" : "1");
  return html;
}

std::string plot_section(const ReportData& data) {
  std::string html = "<h2>Error versus time</h2>\n";
  std::vector<PlotPoint> points;
  for (const auto& method : data.methods)
    if (method.overall.has_metrics && !method.run.bake_seconds.empty())
      points.push_back({method.run.method, median_seconds(method.run), method.overall.rmse});
  if (points.empty()) return html + "<p class=\"note\">No method has metrics to plot.</p>\n";
  return html + error_time_plot(points, data.irradiance ? "covered RMSE (W/m²)" : "covered RMSE");
}

// The convolution's own estimate of its penumbra error, beside the measured one; "" when no
// method made one.
std::string predicted_section(const ReportData& data) {
  std::string rows;
  for (const auto& receiver : data.receivers) {
    for (std::size_t m = 0; m < data.methods.size(); ++m) {
      const ReportCell& cell = receiver.cells[m];
      if (!cell.predicted_metres) continue;
      rows += fmt::format(
          "<tr><td class=\"name\">{}</td><td class=\"name\">{}</td><td>{}</td><td>{}</td>"
          "<td>{}</td><td>{}</td></tr>\n",
          html_escape(data.methods[m].run.method), html_escape(receiver.name),
          number(*cell.predicted_metres), number(*cell.predicted_texels),
          cell.comparison ? number(cell.comparison->penumbra.overall.rmse) : "—",
          cell.comparison ? std::to_string(cell.comparison->penumbra.texels) : "—");
    }
  }
  if (rows.empty()) return "";
  return "<h2>Predicted and measured penumbra error</h2>\n<table>\n<tr><th class=\"name\">method"
         "</th><th class=\"name\">receiver</th><th>predicted (metres)</th><th>predicted (texels)"
         "</th><th>measured penumbra RMSE</th><th>penumbra texels</th></tr>\n" +
         rows +
         "</table>\n<p class=\"note\">The prediction is the convolution's bound on how far a "
         "penumbra moves on the receiver (its manifest's penumbra_error, the worst over the "
         "lights); the measurement is the RMSE of the shadow over the reference's penumbra "
         "texels. They are in different units: a larger prediction should go with a larger "
         "measured error.</p>\n";
}

std::string receiver_section(const ReportData& data, const ReceiverReport& receiver) {
  std::string html = fmt::format("<h3>{}</h3>\n", html_escape(receiver.name));
  if (!receiver.error.empty())
    return html + fmt::format("<p class=\"error\">{}</p>\n", html_escape(receiver.error));
  html += fmt::format(
      "<p class=\"note\">{} covered texels, {} in the penumbra. Difference maps show method − "
      "reference: red above, blue below, white equal, grey uncovered; saturating at ±{}.</p>\n"
      "<div class=\"row\">\n<figure><img src=\"{}\" alt=\"reference\"><figcaption>reference ({} "
      "samples)"
      "</figcaption></figure>\n",
      receiver.covered_texels, receiver.penumbra_texels, number(receiver.heat_scale),
      html_escape(receiver.reference_texture), data.reference_samples);
  for (std::size_t m = 0; m < data.methods.size(); ++m) {
    const ReportCell& cell = receiver.cells[m];
    const std::string method = html_escape(data.methods[m].run.method);
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
        number(c.ssim), html_escape(cell.difference), method, method, number(receiver.heat_scale));
  }
  return html + "</div>\n";
}

}  // namespace

std::string report_page(const ReportData& data) {
  const std::string scene_name = data.scene.file.filename().string();
  std::string html = fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<title>shadowbake report: {0}</title>\n<style>{1}</style>\n<script>{2}</script>\n"
      "</head>\n<body>\n<h1>shadowbake report: {0}</h1>\n"
      "<p class=\"note\">Made by shadowbake {3}. Every method's lightmaps compared with a "
      "reference bake, texel by texel, over the texels the receivers' triangles cover "
      "(docs/reports.md explains each number).</p>\n",
      html_escape(scene_name), kStyle, kImageCheck, SHADOWBAKE_VERSION);
  html += scene_section(data);
  html += methods_section(data);
  html += plot_section(data);
  html += predicted_section(data);
  html += "<h2>Receivers</h2>\n";
  if (!data.reference.error.empty())
    html += fmt::format("<p class=\"error\">No comparisons: the reference failed: {}</p>\n",
                        html_escape(data.reference.error));
  for (const auto& receiver : data.receivers) html += receiver_section(data, receiver);
  html += "</body>\n</html>\n";
  return html;
}

}  // namespace sb
