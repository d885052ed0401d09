// index.html of a report (report_page.cpp): the scene's settings, a table of methods, the
// error-versus-time plot, the predicted and measured penumbra error, and per receiver the
// textures and difference maps. Self-contained: styles and script inline, images referred to
// relatively (ReportData's paths), the plot inline SVG.
#pragma once

#include <string>

#include "evaluation/report_data.h"

namespace sb {

std::string report_page(const ReportData& data);

}  // namespace sb
