// The bad-input corpus (tests/bad_inputs/, written by make_corpus.py) run through the shadowbake
// executable: every case must end with its documented exit code and one line on stderr naming
// the problem, leave no crash, no hang and no output file, and leave the previous good bake in
// the output folder byte for byte. Warning cases publish their bake and say what is doubtful.
// Cases git cannot hold (a FIFO, a symbolic-link loop, devices, signals, a second writer) are made
// here.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "formats/manifest.h"

namespace {

namespace fs = std::filesystem;

const fs::path kCorpus = fs::path(SB_SOURCE_DIR) / "tests" / "bad_inputs";

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Every file under `dir` (hidden ones too) with its bytes.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  if (!fs::exists(dir)) return files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string name = fs::relative(e.path(), dir).string();
    files[name] = e.is_regular_file() ? slurp(e.path()) : std::string("<folder>");
  }
  return files;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

struct CliResult {
  int code = -1;
  std::string err;
};

// Runs the CLI with a time limit (a hang is a failure, not a stuck suite).
CliResult run_cli(const std::string& args, const fs::path& scratch, int seconds = 60) {
  const fs::path err = scratch / "stderr.txt";
  const std::string cmd = "timeout -s KILL " + std::to_string(seconds) + " " + SB_CLI + " " + args +
                          " >/dev/null 2>" + err.string() + " </dev/null";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.err = slurp(err);
  return r;
}

class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->name());
    std::replace(name.begin(), name.end(), '/', '_');
    dir_ =
        fs::temp_directory_path() / ("shadowbake_bad_" + std::to_string(::getpid()) + "_" + name);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // out/ holding a good bake, as a pipeline's folder does before a broken input arrives.
  fs::path good_bake() {
    const fs::path out = dir_ / "out";
    const CliResult r = run_cli(
        "bake " + (kCorpus / "good" / "scene.toml").string() + " -o " + out.string() + " -q", dir_);
    EXPECT_EQ(r.code, 0) << r.err;
    return out;
  }

  // The run failed as documented: the exit code, one line "shadowbake: error: ..." holding
  // `text`, and out/ as it was.
  void expect_refused(const CliResult& r, int code, const std::string& text, const fs::path& out,
                      const std::map<std::string, std::string>& before) {
    EXPECT_EQ(r.code, code) << r.err;
    const auto lines = lines_of(r.err);
    ASSERT_EQ(lines.size(), 1u) << r.err;
    EXPECT_EQ(lines[0].rfind("shadowbake: error: ", 0), 0u) << lines[0];
    EXPECT_NE(lines[0].find(text), std::string::npos) << lines[0];
    EXPECT_EQ(snapshot(out), before) << "the previous bake changed";
  }

  fs::path dir_;
};

struct Case {
  std::string name, command, text, kind;
  int code = 0;
};

// gtest prints a parameter in test lists and failures: its name, not its bytes.
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

std::vector<Case> corpus_cases() {
  std::vector<Case> cases;
  std::ifstream in(kCorpus / "cases.json");
  const auto json = nlohmann::json::parse(in, nullptr, false);
  if (json.is_discarded()) return cases;
  for (const auto& c : json)
    cases.push_back({c["name"], c["command"], c["text"], c["kind"], c["code"]});
  return cases;
}

class Corpus : public BadInput, public ::testing::WithParamInterface<Case> {};

TEST_P(Corpus, EndsAsDocumented) {
  const Case& c = GetParam();
  const fs::path out = good_bake();
  const auto before = snapshot(out);
  ASSERT_FALSE(before.empty());
  const CliResult r = run_cli(
      c.command + " " + (kCorpus / c.name / "scene.toml").string() + " -o " + out.string(), dir_);
  if (c.kind == "error") {
    expect_refused(r, c.code, c.text, out, before);
    return;
  }
  // A warning: published, and said on stderr and in the manifest.
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("shadowbake: warning: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(c.text), std::string::npos) << r.err;
  const auto manifest = sb::read_manifest(out);
  ASSERT_TRUE(manifest) << manifest.error().message;
  bool in_manifest = false;
  for (const std::string& w : manifest->warnings)
    in_manifest = in_manifest || w.find(c.text) != std::string::npos;
  EXPECT_TRUE(in_manifest);
  for (const auto& [name, bytes] : snapshot(out))
    EXPECT_EQ(name.find(".shadowbake-staging"), std::string::npos) << name;
}

INSTANTIATE_TEST_SUITE_P(BadInputs, Corpus, ::testing::ValuesIn(corpus_cases()),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           return info.param.name;
                         });

TEST(BadInputsCorpus, HasItsCases) { EXPECT_GE(corpus_cases().size(), 25u); }

TEST_F(BadInput, SceneThatIsAFifoIsRefusedWithoutHanging) {
  const fs::path out = good_bake();
  const auto before = snapshot(out);
  const fs::path fifo = dir_ / "scene.toml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  expect_refused(run_cli("bake " + fifo.string() + " -o " + out.string(), dir_, 20), 3,
                 "not a regular file", out, before);
}

TEST_F(BadInput, DevicesAreRefusedWithoutReadingThem) {
  const fs::path out = good_bake();
  const auto before = snapshot(out);
  expect_refused(run_cli("bake /dev/zero -o " + out.string(), dir_, 20), 3, "not a regular file",
                 out, before);
  // A mesh named by an absolute path to a device.
  std::ofstream(dir_ / "scene.toml")
      << slurp(kCorpus / "good" / "scene.toml")
             .replace(slurp(kCorpus / "good" / "scene.toml").find("\"quad.obj\""), 10,
                      "\"/dev/zero\"");
  expect_refused(
      run_cli("bake " + (dir_ / "scene.toml").string() + " -o " + out.string(), dir_, 20), 3,
      "not a regular file", out, before);
  // compare reading /dev/zero.
  const CliResult r = run_cli("compare /dev/zero /dev/zero", dir_, 20);
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_EQ(lines_of(r.err).size(), 1u) << r.err;
}

TEST_F(BadInput, SymbolicLinkLoopIsNamed) {
  const fs::path out = good_bake();
  const auto before = snapshot(out);
  fs::create_symlink(dir_ / "b.obj", dir_ / "a.obj");
  fs::create_symlink(dir_ / "a.obj", dir_ / "b.obj");
  std::string text = slurp(kCorpus / "good" / "scene.toml");
  text.replace(text.find("\"quad.obj\""), 10, "\"a.obj\"");
  std::ofstream(dir_ / "scene.toml") << text;
  expect_refused(run_cli("bake " + (dir_ / "scene.toml").string() + " -o " + out.string(), dir_), 3,
                 "Too many levels of symbolic links", out, before);
}

TEST_F(BadInput, OutputFolderThatIsAFileOrHoldsAFolderOfAnOutputName) {
  const fs::path file = dir_ / "file";
  std::ofstream(file) << "not a folder";
  const std::string scene = (kCorpus / "good" / "scene.toml").string();
  CliResult r = run_cli("bake " + scene + " -o " + file.string(), dir_);
  EXPECT_EQ(r.code, 4) << r.err;
  EXPECT_EQ(lines_of(r.err).size(), 1u) << r.err;
  EXPECT_EQ(slurp(file), "not a folder");

  const fs::path out = good_bake();
  fs::remove(out / "manifest.json");
  fs::create_directories(out / "manifest.json");
  const auto before = snapshot(out);
  expect_refused(run_cli("bake " + scene + " -o " + out.string(), dir_), 4,
                 "a folder of that name is in the way", out, before);
}

// Runs a bake of the showcase at 1024² with the reference (several seconds) in the background.
pid_t start_slow_bake(const fs::path& out, const fs::path& err) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const std::string scene = std::string(SB_SOURCE_DIR) + "/scenes/showcase/scene.toml";
    const std::string out_arg = out.string(), err_arg = err.string();
    std::freopen(err_arg.c_str(), "w", stderr);
    std::freopen("/dev/null", "w", stdout);
    ::execl(SB_CLI, SB_CLI, "bake", scene.c_str(), "-o", out_arg.c_str(), "--resolution", "1024",
            "--samples", "256", "--method", "reference", "-q", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

// Waits until `out` holds the bake's staging folder (the bake is under way), at most 20 s.
bool wait_for_staging(const fs::path& out) {
  for (int i = 0; i < 400; ++i) {
    for (const auto& [name, bytes] : snapshot(out))
      if (name.rfind(".shadowbake-staging", 0) == 0) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

TEST_F(BadInput, InterruptedBakeLeavesThePreviousOneAndNoTemporaryFiles) {
  for (const int signal : {SIGINT, SIGTERM}) {
    const fs::path out = good_bake();
    const auto before = snapshot(out);
    const pid_t pid = start_slow_bake(out, dir_ / "slow.txt");
    ASSERT_TRUE(wait_for_staging(out));
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    ::kill(pid, signal);
    int status = 0;
    ::waitpid(pid, &status, 0);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal) << status;
    EXPECT_EQ(snapshot(out), before) << "signal " << signal;
    fs::remove_all(out);
  }
}

TEST_F(BadInput, SecondBakeIntoTheSameFolderIsRefusedWhileTheFirstRuns) {
  const fs::path out = good_bake();
  const pid_t pid = start_slow_bake(out, dir_ / "slow.txt");
  ASSERT_TRUE(wait_for_staging(out));
  const CliResult second =
      run_cli("bake " + (kCorpus / "good" / "scene.toml").string() + " -o " + out.string(), dir_);
  ::kill(pid, SIGTERM);
  ::waitpid(pid, nullptr, 0);
  EXPECT_EQ(second.code, 4) << second.err;
  EXPECT_NE(second.err.find("another shadowbake process (pid " + std::to_string(pid) + ")"),
            std::string::npos)
      << second.err;
  EXPECT_EQ(lines_of(second.err).size(), 1u) << second.err;
}

TEST_F(BadInput, UsageErrorsAreOneLine) {
  for (const std::string args :
       {"", "bake", "bake x.toml", "bake x.toml -o out --seed -1",
        "bake x.toml -o out --frobnicate", "nonsense", "bake x.toml -o out --max-memory lots"}) {
    const CliResult r = run_cli(args, dir_);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    const auto lines = lines_of(r.err);
    ASSERT_EQ(lines.size(), 1u) << args << ": " << r.err;
    EXPECT_EQ(lines[0].rfind("shadowbake: error: ", 0), 0u) << lines[0];
  }
}

TEST_F(BadInput, CompareGatesFailWithNothingToJudge) {
  // A bake, and a copy of its lightmap whose every texel is NaN.
  const fs::path out = good_bake();
  const std::string a = (out / "floor.exr").string();
  const fs::path nan = dir_ / "nan.exr";
  const CliResult make = run_cli("compare " + a + " " + a, dir_);
  ASSERT_EQ(make.code, 0) << make.err;
  const std::string oiiotool = "oiiotool " + a + " --mulc 0 --divc 0 -o " + nan.string();
  if (std::system((oiiotool + " >/dev/null 2>&1").c_str()) != 0) GTEST_SKIP() << "no oiiotool";
  const CliResult r = run_cli("compare " + nan.string() + " " + a + " --mask " +
                                  (out / "floor.coverage.png").string() + " --fail-above rmse=0.1",
                              dir_);
  EXPECT_EQ(r.code, 5) << r.err;
  EXPECT_NE(r.err.find("gate failed"), std::string::npos) << r.err;
}

}  // namespace
