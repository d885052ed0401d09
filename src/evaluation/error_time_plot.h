// The error-versus-time plot of a report, drawn as inline SVG, and the HTML text helpers the
// report page shares with it (error_time_plot.cpp).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace sb {

// Text safe inside HTML: & < > " ' escaped.
std::string html_escape(std::string_view text);
// A number with four significant digits; "—" for NaN, "∞" for infinity.
std::string number(double v);
// A duration as "12.3 ms" below 0.1 s, else "1.23 s".
std::string seconds_text(double s);

struct PlotPoint {
  std::string label;
  double seconds, rmse;
};

// Covered RMSE (y, linear from 0) against median bake time (x, log scale), one labelled point
// per method, as an <svg class="plot"> element.
std::string error_time_plot(const std::vector<PlotPoint>& points, const std::string& y_label);

}  // namespace sb
