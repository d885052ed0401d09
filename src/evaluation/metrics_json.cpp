// One shape for a set's metrics wherever they are written, so that a script reading compare.json
// reads report.json's comparisons the same way.
#include "evaluation/metrics_json.h"

#include <nlohmann/json.hpp>

#include <cmath>

namespace sb {

using json = nlohmann::ordered_json;

json json_number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json to_json(const ChannelErrors& errors) {
  json j;
  j["count"] = errors.count;
  j["rmse"] = json_number(errors.rmse);
  j["mae"] = json_number(errors.mae);
  j["max"] = json_number(errors.max_abs);
  j["max_at"] =
      errors.max_x < 0
          ? json(nullptr)
          : json{{"x", errors.max_x}, {"y", errors.max_y}, {"channel", errors.max_channel}};
  j["psnr"] = json_number(errors.psnr);
  j["ssim"] = json_number(errors.ssim);
  return j;
}

json to_json(const RegionErrors& region) {
  json j;
  j["texels"] = region.texels;
  j["overall"] = to_json(region.overall);
  j["channels"] = json::array();
  for (const auto& channel : region.channels) j["channels"].push_back(to_json(channel));
  return j;
}

}  // namespace sb
