// End to end: runs `shadowbake compare` on images the test writes, and checks the table,
// compare.json, the heat map, the gates and their exit codes, the errors, and the coverage mask
// picked up beside the reference.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/image_io.h"

namespace fs = std::filesystem;

namespace {

struct CompareRun {
  int code = -1;
  std::string out, err;
};

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class CompareCli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("shadowbake_compare_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // A 32 × 32 reference with a soft edge (a penumbra) across x, and a bake 0.01 brighter.
    sb::Image reference(32, 32, 3), bake(32, 32, 3);
    for (int y = 0; y < 32; ++y) {
      for (int x = 0; x < 32; ++x) {
        const float v = std::clamp((x - 8) / 16.0f, 0.0f, 1.0f);
        for (int c = 0; c < 3; ++c) {
          reference.at(x, y)[c] = v;
          bake.at(x, y)[c] = v + 0.01f;
        }
      }
    }
    write("a.exr", bake);
    write("b.exr", reference);
  }
  void TearDown() override { fs::remove_all(dir_); }

  void write(const std::string& name, const sb::Image& image) {
    const auto format =
        fs::path(name).extension() == ".exr" ? sb::PixelFormat::float32 : sb::PixelFormat::uint8;
    ASSERT_TRUE(sb::write_image(dir_ / name, image, format));
  }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  CompareRun run(const std::string& args) {
    CompareRun r;
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string cmd = std::string(SB_CLI) + " compare " + args + " >" + out.string() + " 2>" +
                            err.string() + " </dev/null";
    const int status = std::system(cmd.c_str());
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = read_text(out);
    r.err = read_text(err);
    return r;
  }

  fs::path dir_;
};

int lines(const std::string& text) { return int(std::count(text.begin(), text.end(), '\n')); }

}  // namespace

TEST_F(CompareCli, PrintsTable) {
  const CompareRun r = run(path("a.exr") + " " + path("b.exr"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("RMSE"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("SSIM"), std::string::npos);
  EXPECT_NE(r.out.find("covered"), std::string::npos);
  EXPECT_NE(r.out.find("penumbra"), std::string::npos);
  EXPECT_NE(r.out.find("channel 2"), std::string::npos);
  EXPECT_EQ(r.err, "");
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

TEST_F(CompareCli, WritesJsonAndHeatMap) {
  const CompareRun r = run(path("a.exr") + " " + path("b.exr") + " -o " + path("out"));
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(read_text(dir_ / "out" / "compare.json"));
  EXPECT_EQ(j["a"]["path"], path("a.exr"));
  EXPECT_EQ(j["reference"]["path"], path("b.exr"));
  EXPECT_EQ(j["a"]["width"], 32);
  EXPECT_EQ(j["reference"]["channels"], 3);
  EXPECT_EQ(j["mask"]["source"], "none");
  EXPECT_EQ(j["non_finite"]["a"], 0);
  EXPECT_EQ(j["covered"]["texels"], 32 * 32);
  EXPECT_NEAR(j["covered"]["overall"]["rmse"].get<double>(), 0.01, 1e-5);
  EXPECT_NEAR(j["covered"]["overall"]["mae"].get<double>(), 0.01, 1e-5);
  EXPECT_EQ(j["covered"]["channels"].size(), 3u);
  EXPECT_TRUE(j["covered"]["overall"]["max_at"].contains("x"));
  EXPECT_NEAR(j["covered"]["overall"]["psnr"].get<double>(), 40.0, 1e-2);
  EXPECT_GT(j["covered"]["overall"]["ssim"].get<double>(), 0.8);  // 0.5 where flat and black
  // The soft edge: x = 9 ... 23 hold 1/16 ... 15/16.
  EXPECT_EQ(j["penumbra"]["texels"], 15 * 32);
  EXPECT_NEAR(j["heat_map"]["scale"].get<double>(), 0.01, 1e-9);

  auto heat = sb::read_image(dir_ / "out" / "difference.png");
  ASSERT_TRUE(heat);
  EXPECT_EQ(heat->width, 32);
  EXPECT_GT(heat->height, 32 + 20);    // the colour bar
  EXPECT_GT(heat->at(5, 5)[0], 0.9f);  // a brighter everywhere: red
  EXPECT_LT(heat->at(5, 5)[2], 0.1f);
  EXPECT_GT(heat->at(1, 40)[2], 0.9f);  // the bar's blue end
  EXPECT_LT(heat->at(1, 40)[0], 0.2f);
  // Nothing else, no temporary files.
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir_ / "out")) names.push_back(e.path().filename());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"compare.json", "difference.png"}));
}

TEST_F(CompareCli, GateFailsAboveThreshold) {
  CompareRun r = run(path("a.exr") + " " + path("b.exr") + " --fail-above rmse=0.005");
  EXPECT_EQ(r.code, 5) << r.err;
  EXPECT_NE(r.err.find("shadowbake: gate failed: rmse = "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("> 0.005"), std::string::npos) << r.err;
  r = run(path("a.exr") + " " + path("b.exr") +
          " --fail-above rmse=0.02 --fail-above "
          "penumbra_max=0.02 --fail-above ssim=0.5");
  EXPECT_EQ(r.code, 0) << r.err;
  // ssim and psnr fail below their value.
  r = run(path("a.exr") + " " + path("b.exr") + " --fail-above psnr=45 --fail-above mae=1");
  EXPECT_EQ(r.code, 5);
  EXPECT_NE(r.err.find("gate failed: psnr"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("gate failed: mae"), std::string::npos) << r.err;
  // Outputs are written even when a gate fails, with the gates' results.
  r = run(path("a.exr") + " " + path("b.exr") + " -o " + path("out") + " --fail-above max=0.001");
  EXPECT_EQ(r.code, 5);
  const auto j = nlohmann::json::parse(read_text(dir_ / "out" / "compare.json"));
  EXPECT_EQ(j["gates"][0]["metric"], "max");
  EXPECT_EQ(j["gates"][0]["passed"], false);
}

TEST_F(CompareCli, RejectsUnknownOrMalformedGate) {
  for (const std::string gate : {"rmsx=0.1", "rmse", "rmse=", "rmse=abc", "=0.1"}) {
    const CompareRun r = run(path("a.exr") + " " + path("b.exr") + " --fail-above " + gate);
    EXPECT_EQ(r.code, 2) << gate;
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("--fail-above"), std::string::npos) << r.err;
  }
}

TEST_F(CompareCli, RejectsSizeMismatchNamingBothFiles) {
  write("small.exr", sb::Image(16, 32, 3, 0.5f));
  const CompareRun r = run(path("small.exr") + " " + path("b.exr"));
  EXPECT_EQ(r.code, 3);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("small.exr"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("b.exr"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.rfind("shadowbake: error: ", 0), 0u) << r.err;
}

TEST_F(CompareCli, RejectsMissingFileAndWrongMask) {
  CompareRun r = run(path("missing.exr") + " " + path("b.exr"));
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("missing.exr"), std::string::npos) << r.err;
  write("mask.png", sb::Image(8, 8, 1, 1.0f));
  r = run(path("a.exr") + " " + path("b.exr") + " --mask " + path("mask.png"));
  EXPECT_EQ(r.code, 3);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("mask.png"), std::string::npos) << r.err;
}

TEST_F(CompareCli, UsesCoverageBesideReference) {
  // Cover the left half only; a huge error in the right half must not count.
  sb::Image coverage(32, 32, 1, 0.0f), a(32, 32, 3, 0.0f), reference(32, 32, 3, 0.0f);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 16; ++x) coverage.at(x, y)[0] = 1.0f;
  for (int y = 0; y < 32; ++y)
    for (int x = 16; x < 32; ++x) a.at(x, y)[0] = 100.0f;
  write("floor.exr", reference);
  write("floor.coverage.png", coverage);
  write("cheap.exr", a);
  CompareRun r = run(path("cheap.exr") + " " + path("floor.exr") + " -o " + path("out"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("floor.coverage.png"), std::string::npos) << r.out;
  auto j = nlohmann::json::parse(read_text(dir_ / "out" / "compare.json"));
  EXPECT_EQ(j["mask"]["source"], "beside reference");
  EXPECT_EQ(j["covered"]["texels"], 16 * 32);
  EXPECT_EQ(j["covered"]["overall"]["rmse"].get<double>(), 0.0);
  EXPECT_TRUE(j["covered"]["overall"]["psnr"].is_null());  // +inf: JSON has none
  // An explicit mask wins.
  write("all.png", sb::Image(32, 32, 1, 1.0f));
  r = run(path("cheap.exr") + " " + path("floor.exr") + " --mask " + path("all.png") + " -o " +
          path("out"));
  ASSERT_EQ(r.code, 0) << r.err;
  j = nlohmann::json::parse(read_text(dir_ / "out" / "compare.json"));
  EXPECT_EQ(j["mask"]["source"], "option");
  EXPECT_EQ(j["covered"]["texels"], 32 * 32);
}

TEST_F(CompareCli, WarnsAboutNonFiniteTexels) {
  sb::Image a(32, 32, 3, 0.5f), reference(32, 32, 3, 0.5f);
  a.at(3, 4)[1] = std::numeric_limits<float>::quiet_NaN();
  a.at(5, 4)[0] = std::numeric_limits<float>::infinity();
  a.at(7, 7)[1] = 0.6f;
  write("nan.exr", a);
  write("flat.exr", reference);
  const CompareRun r = run(path("nan.exr") + " " + path("flat.exr") + " -o " + path("out"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("shadowbake: warning: " + path("nan.exr") +
                       ": 2 texels hold NaN or infinity; left out of the metrics"),
            std::string::npos)
      << r.err;
  const auto j = nlohmann::json::parse(read_text(dir_ / "out" / "compare.json"));
  EXPECT_EQ(j["non_finite"]["a"], 2);
  EXPECT_EQ(j["covered"]["texels"], 32 * 32 - 2);
  EXPECT_NEAR(j["covered"]["overall"]["max"].get<double>(), 0.1, 1e-6);
}
