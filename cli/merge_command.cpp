// `shadowbake merge`: the shards of a bake into the files one bake of the whole scene writes
// (docs/distributed.md).
#include <fmt/core.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "formats/outputs.h"
#include "pipeline/shards.h"

namespace sbcli {

namespace {

struct MergeArgs {
  std::vector<std::string> shards;
  std::string out_dir;
  std::string scene;  // where the scene lies, when not where the shards read it
  bool quiet = false;
};

int run_merge(const MergeArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::filesystem::path> folders(args.shards.begin(), args.shards.end());
  auto merged = sb::merge_shards(folders, args.scene);
  if (!merged) return fail(merged.error());
  const sb::Scene& scene = merged->scene;
  if (sb::Status names = sb::check_output_names(scene); !names) return fail(names.error());
  auto folder = sb::OutputFolder::open(args.out_dir);
  if (!folder) return fail(folder.error());
  for (const auto& w : merged->result.warnings)
    std::fprintf(stderr, "shadowbake: warning: %s\n", w.c_str());
  auto written = sb::write_outputs(*folder, scene, scene.bake, merged->result);
  reraise_pending_interrupt();
  if (!written) return fail(written.error());
  if (!args.quiet) {
    fmt::print("merged {} shard(s), {} receiver(s) of {} into {}/ (manifest.json) in {:.2f} s\n",
               folders.size(), merged->result.receivers.size(), scene.file.string(), args.out_dir,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return ok;
}

}  // namespace

Runner add_merge_command(CLI::App& app) {
  auto args = std::make_shared<MergeArgs>();
  auto* merge = app.add_subcommand(
      "merge", "merge the shards of a bake (bake --shard K/N) into what one bake writes");
  merge->add_option("shards", args->shards, "the shards' output folders, every shard once")
      ->required();
  merge->add_option("-o,--output", args->out_dir, "output folder (created if missing)")->required();
  merge->add_option("--scene", args->scene,
                    "the scene file, when it is not where the shards read it (its content must "
                    "be the same)");
  merge->add_flag("-q,--quiet", args->quiet, "no summary; errors and warnings still go to stderr");
  return [args]() { return run_merge(*args); };
}

}  // namespace sbcli
