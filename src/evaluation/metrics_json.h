// The JSON encoding of a comparison's metrics (metrics_json.cpp): `covered` and `penumbra` in
// compare.json, and per receiver and method in report.json (docs/reports.md).
#pragma once

#include <nlohmann/json_fwd.hpp>

#include "evaluation/image_metrics.h"

namespace sb {

// `v` as a JSON number, or null where JSON has none: NaN (a metric of an empty set) and ±inf (the
// PSNR of identical images).
nlohmann::ordered_json json_number(double v);

// {count, rmse, mae, max, max_at: {x, y, channel} (null when no value was compared), psnr, ssim},
// undefined and infinite values as null.
nlohmann::ordered_json to_json(const ChannelErrors& errors);

// {texels, overall: to_json(overall), channels: [to_json(channel), ...]}.
nlohmann::ordered_json to_json(const RegionErrors& region);

}  // namespace sb
