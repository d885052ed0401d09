// The report's error-versus-time plot: an SVG drawn by hand (a dozen points and two axes need no
// plotting library), and the HTML text helpers around it.
#include "evaluation/error_time_plot.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

namespace sb {

namespace {

// "1, 2, 5 × 10^k" at or above `v`.
double nice_step(double v) {
  const double decade = std::pow(10.0, std::floor(std::log10(v)));
  for (const double m : {1.0, 2.0, 5.0, 10.0})
    if (m * decade >= v) return m * decade;
  return 10 * decade;
}

}  // namespace

std::string html_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string number(double v) {
  if (std::isnan(v)) return "—";
  if (std::isinf(v)) return v > 0 ? "∞" : "−∞";
  return fmt::format("{:.4g}", v);
}

std::string seconds_text(double s) {
  if (std::isnan(s)) return "—";
  return s < 0.1 ? fmt::format("{:.1f} ms", 1e3 * s) : fmt::format("{:.2f} s", s);
}

// Covered RMSE against median bake time (log scale), one labelled point per method.
std::string error_time_plot(const std::vector<PlotPoint>& points, const std::string& y_label) {
  constexpr double kWidth = 680, kHeight = 380, kLeft = 80, kRight = 30, kTop = 20, kBottom = 60;
  const double plot_w = kWidth - kLeft - kRight, plot_h = kHeight - kTop - kBottom;
  double t_lo = std::numeric_limits<double>::infinity(), t_hi = 0, e_hi = 0;
  for (const auto& p : points) {
    const double t = std::max(p.seconds, 1e-6);
    t_lo = std::min(t_lo, t);
    t_hi = std::max(t_hi, t);
    e_hi = std::max(e_hi, p.rmse);
  }
  const int decade_lo = int(std::floor(std::log10(t_lo / 1.5)));
  const int decade_hi = std::max(decade_lo + 1, int(std::ceil(std::log10(t_hi * 1.5))));
  const double y_step = nice_step(std::max(e_hi, 1e-6) * 1.15 / 5);
  const double y_hi = y_step * std::max(1.0, std::ceil(std::max(e_hi, 1e-6) * 1.15 / y_step));
  auto x_of = [&](double t) {
    return kLeft + plot_w * (std::log10(std::max(t, 1e-6)) - decade_lo) / (decade_hi - decade_lo);
  };
  auto y_of = [&](double e) { return kTop + plot_h * (1 - e / y_hi); };

  std::string svg = fmt::format(
      "<svg class=\"plot\" xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" "
      "viewBox=\"0 0 {0} {1}\" role=\"img\" aria-label=\"error versus time\">\n"
      "<rect x=\"{2}\" y=\"{3}\" width=\"{4}\" height=\"{5}\" fill=\"#fff\" stroke=\"#333\"/>\n",
      kWidth, kHeight, kLeft, kTop, plot_w, plot_h);
  // x ticks: every decade labelled; 2× and 5× minor ticks, labelled when the span is short.
  const bool label_minor = decade_hi - decade_lo <= 2;
  for (int d = decade_lo; d <= decade_hi; ++d) {
    for (const double m : {1.0, 2.0, 5.0}) {
      const double t = m * std::pow(10.0, d);
      if (d == decade_hi && m > 1) break;
      const double x = x_of(t);
      const bool major = m == 1.0;
      svg += fmt::format(
          "<line x1=\"{0:.1f}\" y1=\"{1}\" x2=\"{0:.1f}\" y2=\"{2}\" stroke=\"{3}\"/>\n", x, kTop,
          kTop + plot_h, major ? "#ccc" : "#eee");
      svg += fmt::format(
          "<line x1=\"{0:.1f}\" y1=\"{1}\" x2=\"{0:.1f}\" y2=\"{2}\" stroke=\"#333\"/>\n", x,
          kTop + plot_h, kTop + plot_h + (major ? 6 : 3));
      if (major || label_minor) {
        svg += fmt::format(
            "<text x=\"{:.1f}\" y=\"{}\" text-anchor=\"middle\" class=\"tick\">{:g}</text>\n", x,
            kTop + plot_h + 20, t);
      }
    }
  }
  for (double e = 0; e <= y_hi * (1 + 1e-9); e += y_step) {
    const double y = y_of(e);
    svg += fmt::format(
        "<line x1=\"{0}\" y1=\"{1:.1f}\" x2=\"{2}\" y2=\"{1:.1f}\" stroke=\"#ccc\"/>\n"
        "<line x1=\"{3}\" y1=\"{1:.1f}\" x2=\"{0}\" y2=\"{1:.1f}\" stroke=\"#333\"/>\n"
        "<text x=\"{4}\" y=\"{5:.1f}\" text-anchor=\"end\" class=\"tick\">{6:.3g}</text>\n",
        kLeft, y, kLeft + plot_w, kLeft - 6, kLeft - 9, y + 4, e);
  }
  svg += fmt::format(
      "<text x=\"{:.1f}\" y=\"{}\" text-anchor=\"middle\" class=\"axis\">median bake time "
      "(seconds, log scale)</text>\n",
      kLeft + plot_w / 2, kHeight - 15);
  svg += fmt::format(
      "<text transform=\"translate(20 {:.1f}) rotate(-90)\" text-anchor=\"middle\" "
      "class=\"axis\">{}</text>\n",
      kTop + plot_h / 2, html_escape(y_label));
  for (const auto& p : points) {
    const double x = x_of(p.seconds), y = y_of(p.rmse);
    const bool right_half = x > kLeft + plot_w * 0.7;
    svg += fmt::format(
        "<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"5\" fill=\"#c0392b\" stroke=\"#222\"><title>{}: "
        "{}, RMSE {}</title></circle>\n",
        x, y, html_escape(p.label), seconds_text(p.seconds), number(p.rmse));
    svg += fmt::format(
        "<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"{}\" class=\"label\">{}</text>\n",
        right_half ? x - 9 : x + 9, y - 8, right_half ? "end" : "start", html_escape(p.label));
  }
  svg += "</svg>\n";
  return svg;
}

}  // namespace sb
