// `shadowbake report`: bakes a scene with each method, and once with a high-sample reference,
// every bake a child process of this executable (so its peak memory is its own), then writes the
// comparison with sb::write_report (docs/reports.md, docs/cli.md).
#include <fcntl.h>
#include <fmt/core.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "commands.h"
#include "evaluation/report.h"
#include "formats/manifest.h"
#include "scene/scene.h"

extern char** environ;

namespace sbcli {

namespace {

namespace fs = std::filesystem;

struct ReportArgs {
  std::string scene;
  std::string out_dir;
  std::vector<std::string> methods;
  int reference_samples = 1024;
  int repeat = 3;
  std::optional<int> resolution;
  std::optional<int> threads;
  bool quiet = false;
};

// What one bake child left behind.
struct ChildResult {
  double bake_seconds = 0;
  double peak_memory_mib = 0;
  std::string error;  // empty: it succeeded
};

std::string last_line_of(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::string line, last;
  while (std::getline(in, line)) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (!line.empty()) last = line;
  }
  return last;
}

// Runs `/proc/self/exe bake ...` with stdout discarded and stderr captured to `log`, waits for it
// (wait4, for its peak resident set), and reads bake_seconds from the manifest it wrote.
ChildResult run_bake_child(const std::vector<std::string>& args, const fs::path& folder,
                           const fs::path& log) {
  ChildResult result;
  std::vector<char*> argv;
  std::string program = "shadowbake";
  argv.push_back(program.data());
  std::vector<std::string> owned = args;
  for (auto& a : owned) argv.push_back(a.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, "/proc/self/exe", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) {
    result.error = std::string("cannot start a bake process: ") + std::strerror(spawned);
    return result;
  }
  int status = 0;
  struct rusage usage {};
  if (::wait4(pid, &status, 0, &usage) < 0) {
    result.error = std::string("cannot wait for the bake process: ") + std::strerror(errno);
    return result;
  }
  result.peak_memory_mib = double(usage.ru_maxrss) / 1024.0;  // Linux: ru_maxrss in KiB
  if (WIFSIGNALED(status)) {
    result.error = fmt::format("the bake was killed by signal {} ({})", WTERMSIG(status),
                               strsignal(WTERMSIG(status)));
    return result;
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::string why = last_line_of(log);
    // The child's "shadowbake: error: " prefix would be said twice in the report's own line.
    constexpr std::string_view kPrefix = "shadowbake: error: ";
    if (why.starts_with(kPrefix)) why.erase(0, kPrefix.size());
    if (why.empty()) why = "the bake failed with no message";
    result.error = fmt::format("{} (exit code {})", why, WEXITSTATUS(status));
    return result;
  }
  const auto manifest = sb::read_manifest(folder);
  if (!manifest) {
    result.error = manifest.error().message;
    return result;
  }
  result.bake_seconds = manifest->bake_seconds;
  return result;
}

// Bakes `method` `repeat` times into out_dir/runs/<folder_name>, printing one line per bake.
sb::MethodRun bake_method(const ReportArgs& args, const std::string& method,
                          const std::string& folder_name, const std::string& label,
                          std::optional<int> samples, int repeat) {
  sb::MethodRun run;
  run.method = method;
  const fs::path runs = fs::path(args.out_dir) / "runs";
  run.folder = runs / folder_name;
  const auto& known = sb::known_methods();
  if (std::find(known.begin(), known.end(), method) == known.end()) {
    std::string list;
    for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
    run.error = fmt::format("unknown method '{}' (this build knows: {})", method, list);
    run.folder.clear();
    if (!args.quiet)
      std::fprintf(stderr, "report: %s ... failed: %s\n", label.c_str(), run.error.c_str());
    return run;
  }
  // A previous report's files in this folder must not be mistaken for this bake's.
  std::error_code ec;
  fs::remove_all(run.folder, ec);
  fs::create_directories(runs, ec);

  // Each receiver's own lightmap as float EXR, whatever the scene's [output] says: the report
  // compares receivers texel by texel.
  std::vector<std::string> child_args = {"bake",       args.scene,  "-o",      run.folder.string(),
                                         "--method",   method,      "--quiet", "--no-atlas",
                                         "--encoding", "linear-exr"};
  if (args.resolution) {
    child_args.push_back("--resolution");
    child_args.push_back(std::to_string(*args.resolution));
  }
  if (samples) {
    child_args.push_back("--samples");
    child_args.push_back(std::to_string(*samples));
  }
  if (args.threads) {
    child_args.push_back("--threads");
    child_args.push_back(std::to_string(*args.threads));
  }
  const fs::path log = runs / (folder_name + ".stderr.txt");
  for (int i = 1; i <= repeat; ++i) {
    const ChildResult child = run_bake_child(child_args, run.folder, log);
    run.peak_memory_mib = std::max(run.peak_memory_mib, child.peak_memory_mib);
    if (!child.error.empty()) {
      run.error = child.error;
      if (!args.quiet)
        std::fprintf(stderr, "report: %s %d/%d ... failed: %s\n", label.c_str(), i, repeat,
                     run.error.c_str());
      return run;
    }
    run.bake_seconds.push_back(child.bake_seconds);
    if (!args.quiet)
      std::fprintf(stderr, "report: %s %d/%d ... %.2f s\n", label.c_str(), i, repeat,
                   child.bake_seconds);
  }
  return run;
}

int run_report(ReportArgs args) {
  auto scene = sb::load_scene(args.scene);
  if (!scene) return fail(scene.error());
  if (args.resolution) scene->bake.resolution = *args.resolution;

  auto folder = sb::OutputFolder::open(args.out_dir);
  if (!folder) return fail(folder.error());
  std::error_code ec;
  fs::create_directories(fs::path(args.out_dir) / "runs", ec);
  if (ec) {
    return fail(
        sb::output_error(args.out_dir + ": cannot create the report folder: " + ec.message()));
  }

  bool any_failed = false;
  // Ambient occlusion's ground truth is its own rays at many samples; every other quantity's is
  // the reference method's.
  const std::string truth =
      scene->bake.quantity == sb::Quantity::ambient_occlusion ? "ambient-occlusion" : "reference";
  const sb::MethodRun reference = bake_method(
      args, truth, fmt::format("reference-{}spp", args.reference_samples),
      fmt::format("reference ({} samples)", args.reference_samples), args.reference_samples, 1);
  if (!reference.error.empty()) any_failed = true;

  std::vector<sb::MethodRun> runs;
  std::vector<std::string> seen;
  for (const auto& method : args.methods) {
    // Twice the same method would bake into one folder; once is enough.
    if (std::find(seen.begin(), seen.end(), method) != seen.end()) continue;
    seen.push_back(method);
    runs.push_back(bake_method(args, method, method, method, std::nullopt, args.repeat));
    if (!runs.back().error.empty()) any_failed = true;
  }

  auto written = sb::write_report(*scene, runs, reference, *folder);
  reraise_pending_interrupt();
  if (!written) return fail(written.error());
  if (!args.quiet) {
    fmt::print(stderr, "report: {}/index.html and report.json written{}\n", args.out_dir,
               any_failed ? "; some bakes failed (see above)" : "");
  }
  return any_failed ? bad_input : ok;
}

}  // namespace

Runner add_report_command(CLI::App& app) {
  struct Options {
    ReportArgs args;
    int resolution = 0, threads = 0;
  };
  auto o = std::make_shared<Options>();
  auto* report = app.add_subcommand(
      "report", "bake a scene with several methods and a reference; write a comparison to OUTDIR");
  report->add_option("scene", o->args.scene, "scene file (TOML, docs/scene-format.md)")->required();
  report->add_option("-o,--output", o->args.out_dir, "report folder (created if missing)")
      ->required();
  report
      ->add_option("--methods", o->args.methods,
                   "methods to compare with the reference, comma-separated")
      ->delimiter(',')
      ->required();
  report
      ->add_option("--reference-samples", o->args.reference_samples,
                   "light samples per texel of the reference bake")
      ->check(CLI::Range(1, 1 << 20));
  report->add_option("--repeat", o->args.repeat, "bakes per method; the median time is reported")
      ->check(CLI::Range(1, 1000));
  auto* resolution_opt =
      report->add_option("--resolution", o->resolution, "texels per side (overrides the scene)")
          ->check(CLI::Range(1, 16384));
  auto* threads_opt =
      report->add_option("--threads", o->threads, "worker threads of each bake (0: all cores)")
          ->check(CLI::Range(0, 1024));
  report->add_flag("-q,--quiet", o->args.quiet, "no progress lines");
  return [=]() {
    ReportArgs args = o->args;
    if (*resolution_opt) args.resolution = o->resolution;
    if (*threads_opt) args.threads = o->threads;
    return run_report(std::move(args));
  };
}

}  // namespace sbcli
