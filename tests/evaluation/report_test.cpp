// The report: write_report on hand-made bake folders (a failed run keeps its error, names are
// escaped in the page), and `shadowbake report` end to end on scenes/parallel, with the page
// opened in headless Chromium by tests/tools/check_report_page.sh when chromium is installed.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "core/image_io.h"
#include "evaluation/report.h"
#include "formats/manifest.h"

namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct CommandResult {
  int code = -1;
  std::string out, err;
};

// Runs a shell command with output captured in `dir`.
CommandResult run_command(const std::string& command, const fs::path& dir) {
  CommandResult r;
  const fs::path out = dir / "cmd_stdout.txt", err = dir / "cmd_stderr.txt";
  const std::string cmd = command + " >" + out.string() + " 2>" + err.string() + " </dev/null";
  const int status = std::system(cmd.c_str());
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

fs::path test_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir =
      fs::temp_directory_path() /
      ("shadowbake_report_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Every src="..." of the page, as written.
std::vector<std::string> image_sources(const std::string& html) {
  std::vector<std::string> sources;
  const std::regex src("src=\"([^\"]*)\"");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), src); it != std::sregex_iterator();
       ++it)
    sources.push_back((*it)[1]);
  return sources;
}

// A bake folder as `shadowbake bake` leaves it, for one 8 × 8 receiver "floor" whose visibility
// is `value` everywhere but a dark 2 × 2 square; the left column is not covered.
void write_bake(const fs::path& folder, const std::string& method, float value) {
  fs::create_directories(folder);
  sb::Image image(8, 8, 3, value), coverage(8, 8, 1, 1.0f);
  for (int y = 3; y < 5; ++y)
    for (int x = 3; x < 5; ++x)
      for (int c = 0; c < 3; ++c) image.at(x, y)[c] = 0.0f;
  for (int y = 0; y < 8; ++y) coverage.at(0, y)[0] = 0.0f;
  ASSERT_TRUE(sb::write_image(folder / "floor.exr", image, sb::PixelFormat::float32));
  ASSERT_TRUE(sb::write_image(folder / "floor.png", image, sb::PixelFormat::uint8));
  ASSERT_TRUE(sb::write_image(folder / "floor.coverage.png", coverage, sb::PixelFormat::uint8));
  sb::Manifest manifest;
  manifest.method = method;
  manifest.samples = 64;
  manifest.bake_seconds = 0.5;
  sb::ManifestReceiver& floor = manifest.receivers.emplace_back();
  floor.name = "floor";
  floor.files.emplace();
  floor.files->lightmap = {"floor.exr", sb::Encoding::linear_exr};
  floor.files->preview = sb::ManifestFile{"floor.png", sb::Encoding::png};
  floor.files->coverage = {"floor.coverage.png", sb::Encoding::png};
  floor.width = floor.height = 8;
  floor.method = method;
  floor.samples = 64;
  floor.covered_texels = 56;
  if (method == "convolution")
    floor.method_entries["penumbra_error"] = {{"metres", 0.01}, {"texels", 2.5}};
  std::ofstream(folder / sb::kManifestFile) << sb::manifest_to_json(manifest).dump(2);
}

sb::Scene tiny_scene() {
  sb::Scene scene;
  scene.file = "tiny.toml";
  scene.bake.resolution = 8;
  scene.objects.push_back({});
  scene.objects.back().name = "floor";
  return scene;
}

}  // namespace

TEST(Report, FailedRunKeepsItsErrorAndNamesAreEscaped) {
  const fs::path dir = test_dir();
  write_bake(dir / "runs" / "reference-64spp", "reference", 1.0f);
  write_bake(dir / "runs" / "convolution", "convolution", 0.9f);
  sb::MethodRun reference{"reference", {0.5}, 100, dir / "runs" / "reference-64spp", ""};
  std::vector<sb::MethodRun> runs = {
      {"convolution", {0.2, 0.1, 0.3}, 50, dir / "runs" / "convolution", ""},
      {"<script>alert(1)</script>", {}, 0, {}, "unknown method '<script>' & more"},
  };
  const fs::path out = dir / "report";
  auto folder = sb::OutputFolder::open(out);
  ASSERT_TRUE(folder);
  ASSERT_TRUE(sb::write_report(tiny_scene(), runs, reference, *folder));

  const auto report = nlohmann::json::parse(slurp(out / "report.json"));
  ASSERT_EQ(report["methods"].size(), 2u);
  const auto& convolution = report["methods"][0];
  EXPECT_DOUBLE_EQ(convolution["median_seconds"].get<double>(), 0.2);
  EXPECT_EQ(convolution["bake_seconds"].size(), 3u);
  EXPECT_TRUE(convolution["error"].is_null());
  // 0.1 off on the 52 covered lit texels, exact on the 4 shadowed ones; the uncovered column
  // does not count.
  const auto& covered = convolution["overall"]["covered"];
  EXPECT_EQ(covered["texels"], 56);
  EXPECT_NEAR(covered["rmse"].get<double>(), 0.1 * std::sqrt(52.0 / 56.0), 1e-5);
  EXPECT_NEAR(covered["max"].get<double>(), 0.1, 1e-5);
  // The reference is 0 or 1: no penumbra, and no number for its RMSE.
  EXPECT_EQ(convolution["overall"]["penumbra"]["texels"], 0);
  EXPECT_TRUE(convolution["overall"]["penumbra"]["rmse"].is_null());
  const auto& failed = report["methods"][1];
  EXPECT_EQ(failed["error"], "unknown method '<script>' & more");
  EXPECT_TRUE(failed["overall"].is_null());
  const auto& floor = report["receivers"][0]["methods"];
  EXPECT_DOUBLE_EQ(floor[0]["predicted_penumbra_error"]["texels"].get<double>(), 2.5);
  EXPECT_TRUE(floor[0].contains("measured_penumbra_rmse"));
  // A receiver's metrics are encoded as in compare.json: overall and per channel, the worst
  // texel with its channel.
  const auto& floor_covered = floor[0]["covered"];
  EXPECT_EQ(floor_covered["texels"], 56);
  EXPECT_NEAR(floor_covered["overall"]["rmse"].get<double>(), 0.1 * std::sqrt(52.0 / 56.0), 1e-5);
  EXPECT_EQ(floor_covered["channels"].size(), 3u);
  const auto& worst = floor_covered["overall"]["max_at"];
  EXPECT_GE(worst["x"].get<int>(), 1);  // column 0 is not covered
  EXPECT_GE(worst["y"].get<int>(), 0);
  EXPECT_GE(worst["channel"].get<int>(), 0);
  EXPECT_LT(worst["channel"].get<int>(), 3);
  EXPECT_TRUE(floor[0]["penumbra"]["overall"]["max_at"].is_null());  // no penumbra texels
  EXPECT_FALSE(floor[1]["error"].is_null());

  const std::string html = slurp(out / "index.html");
  EXPECT_EQ(html.find("<script>alert"), std::string::npos);
  EXPECT_NE(html.find("&lt;script&gt;alert(1)&lt;/script&gt;"), std::string::npos);
  EXPECT_NE(html.find("unknown method &#39;&lt;script&gt;&#39; &amp; more"), std::string::npos);
  EXPECT_NE(html.find("<svg"), std::string::npos);
  EXPECT_NE(html.find("weighted by their covered texels"), std::string::npos);
  const auto sources = image_sources(html);
  EXPECT_EQ(sources.size(), 3u);  // reference, convolution and its difference map
  for (const auto& src : sources) EXPECT_TRUE(fs::is_regular_file(out / src)) << src;
  fs::remove_all(dir);
}

TEST(Report, FailedReferenceStillWritesThePage) {
  const fs::path dir = test_dir();
  write_bake(dir / "runs" / "convolution", "convolution", 0.9f);
  sb::MethodRun reference{
      "reference", {}, 0, dir / "runs" / "reference-64spp", "scene.toml: out of memory"};
  std::vector<sb::MethodRun> runs = {{"convolution", {0.2}, 50, dir / "runs" / "convolution", ""}};
  auto folder = sb::OutputFolder::open(dir / "report");
  ASSERT_TRUE(folder);
  ASSERT_TRUE(sb::write_report(tiny_scene(), runs, reference, *folder));
  const auto report = nlohmann::json::parse(slurp(dir / "report" / "report.json"));
  EXPECT_EQ(report["reference"]["error"], "scene.toml: out of memory");
  EXPECT_TRUE(report["methods"][0]["overall"].is_null());
  EXPECT_DOUBLE_EQ(report["methods"][0]["median_seconds"].get<double>(), 0.2);
  const std::string html = slurp(dir / "report" / "index.html");
  EXPECT_NE(html.find("the reference failed: scene.toml: out of memory"), std::string::npos);
  fs::remove_all(dir);
}

TEST(Report, CommandComparesMethodsAndPageLoadsInChromium) {
  const fs::path dir = test_dir();
  const fs::path out = dir / "report";
  const CommandResult r = run_command(std::string(SB_CLI) + " report " + SB_SOURCE_DIR +
                                          "/scenes/parallel/scene.toml --resolution 64 "
                                          "--reference-samples 64 --repeat 2 --threads 2 "
                                          "--methods convolution,reference,nonsense -o " +
                                          out.string(),
                                      dir);
  // `nonsense` is no method: it fails, the report is still written, the exit code says so.
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_NE(r.err.find("report: convolution 2/2 ... "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("report: nonsense ... failed: unknown method 'nonsense'"), std::string::npos)
      << r.err;
  ASSERT_TRUE(fs::is_regular_file(out / "report.json"));
  ASSERT_TRUE(fs::is_regular_file(out / "index.html"));

  const auto report = nlohmann::json::parse(slurp(out / "report.json"));
  EXPECT_EQ(report["reference"]["samples"], 64);
  EXPECT_EQ(report["reference"]["bake_seconds"].size(), 1u);
  ASSERT_EQ(report["methods"].size(), 3u);
  for (int m = 0; m < 2; ++m) {
    const auto& method = report["methods"][m];
    EXPECT_EQ(method["method"], m == 0 ? "convolution" : "reference");
    EXPECT_TRUE(method["error"].is_null()) << method["error"];
    EXPECT_EQ(method["bake_seconds"].size(), 2u);
    EXPECT_GT(method["peak_memory_mib"].get<double>(), 1.0);
    ASSERT_TRUE(method["overall"].is_object());
    EXPECT_EQ(method["overall"]["covered"]["texels"], 64 * 64);
  }
  // The convolution is exact for parallel planes, up to the 64-sample reference's noise.
  EXPECT_LT(report["methods"][0]["overall"]["covered"]["rmse"].get<double>(), 0.05);
  EXPECT_GT(report["methods"][0]["overall"]["penumbra"]["texels"].get<int>(), 0);
  EXPECT_EQ(report["methods"][2]["method"], "nonsense");
  EXPECT_NE(report["methods"][2]["error"].get<std::string>().find("unknown method"),
            std::string::npos);
  const auto& floor = report["receivers"][0];
  EXPECT_EQ(floor["name"], "floor");
  EXPECT_TRUE(floor["methods"][0].contains("predicted_penumbra_error"));

  const std::string html = slurp(out / "index.html");
  const auto sources = image_sources(html);
  EXPECT_EQ(sources.size(), 5u);  // the reference, then each method's texture and heat map
  for (const auto& src : sources) EXPECT_TRUE(fs::is_regular_file(out / src)) << src;

  if (!fs::exists("/usr/bin/chromium")) {
    GTEST_SKIP() << "/usr/bin/chromium is not installed: the page was not opened in a browser";
  }
  const CommandResult page = run_command(
      std::string(SB_SOURCE_DIR) + "/tests/tools/check_report_page.sh " + out.string(), dir);
  EXPECT_EQ(page.code, 0) << page.out << page.err;
  EXPECT_TRUE(fs::is_regular_file(out / "screenshot.png"));
  fs::remove_all(dir);
}
