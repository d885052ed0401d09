// The JSON encoding of metrics that compare.json and report.json share: the worst texel with its
// channel, null for what JSON cannot hold, a region's overall errors beside each channel's.
#include "evaluation/metrics_json.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <limits>

namespace {

sb::ChannelErrors errors(double rmse, int max_x, int max_y, int max_channel) {
  sb::ChannelErrors e;
  e.count = 12;
  e.rmse = rmse;
  e.mae = 0.5 * rmse;
  e.max_abs = 2 * rmse;
  e.max_x = max_x;
  e.max_y = max_y;
  e.max_channel = max_channel;
  e.psnr = 40;
  e.ssim = 0.9;
  return e;
}

}  // namespace

TEST(MetricsJson, WorstTexelNamesItsChannel) {
  const auto j = sb::to_json(errors(0.25, 3, 7, 2));
  EXPECT_EQ(j["count"], 12);
  EXPECT_DOUBLE_EQ(j["rmse"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(j["mae"].get<double>(), 0.125);
  EXPECT_DOUBLE_EQ(j["max"].get<double>(), 0.5);
  EXPECT_EQ(j["max_at"], (nlohmann::ordered_json{{"x", 3}, {"y", 7}, {"channel", 2}}));
  EXPECT_DOUBLE_EQ(j["psnr"].get<double>(), 40.0);
  EXPECT_DOUBLE_EQ(j["ssim"].get<double>(), 0.9);
}

TEST(MetricsJson, WritesNaNAndInfinityAsNull) {
  // An empty set: nothing compared, every metric NaN, no worst texel.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  sb::ChannelErrors empty = errors(nan, -1, -1, -1);
  empty.count = 0;
  empty.ssim = nan;
  const auto j = sb::to_json(empty);
  for (const char* key : {"rmse", "mae", "max", "max_at", "ssim"})
    EXPECT_TRUE(j[key].is_null()) << key;
  // Identical images: PSNR +inf.
  sb::ChannelErrors identical = errors(0, 0, 0, 0);
  identical.psnr = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(sb::to_json(identical)["psnr"].is_null());
  EXPECT_DOUBLE_EQ(sb::to_json(identical)["rmse"].get<double>(), 0.0);
}

TEST(MetricsJson, RegionHoldsOverallAndEachChannel) {
  sb::RegionErrors region;
  region.texels = 4;
  region.overall = errors(0.3, 1, 2, 1);
  region.channels = {errors(0.1, 0, 0, 0), errors(0.5, 1, 2, 1), errors(0.2, 3, 3, 2)};
  const auto j = sb::to_json(region);
  EXPECT_EQ(j["texels"], 4);
  EXPECT_EQ(j["overall"], sb::to_json(region.overall));
  ASSERT_EQ(j["channels"].size(), 3u);
  for (std::size_t c = 0; c < 3; ++c) EXPECT_EQ(j["channels"][c], sb::to_json(region.channels[c]));
}
