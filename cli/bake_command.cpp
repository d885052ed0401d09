// `shadowbake bake`: bakes every receiver of a scene and writes the lightmaps (docs/cli.md).
#include <fmt/core.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "commands.h"
#include "formats/outputs.h"
#include "pipeline/bake.h"
#include "pipeline/memory_budget.h"
#include "pipeline/shards.h"
#include "scene/scene.h"

namespace sbcli {

namespace {

// Progress on stderr, at most ten updates a second; any thread may call. On a terminal a one-line
// bar, redrawn in place; with --progress-lines one line `progress F` per update (F the fraction
// done, 0 to 1, four decimals), whether stderr is a terminal or not, for a program that reads it
// (the Blender add-on, blender/). The last update is always 1.
class ProgressBar {
 public:
  ProgressBar(std::string label, bool lines) : label_(std::move(label)), lines_(lines) {}
  void update(double fraction) {
    const bool final_update = fraction >= 1.0;
    // The final update must not be lost to a busy lock; the others may be.
    std::unique_lock lock(mutex_, std::defer_lock);
    if (final_update) {
      lock.lock();
    } else if (!lock.try_lock()) {
      return;
    }
    if (finished_) return;
    const auto now = std::chrono::steady_clock::now();
    if (!final_update && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    finished_ = final_update;
    fraction = std::clamp(fraction, 0.0, 1.0);
    if (lines_) {
      std::fprintf(stderr, "progress %.4f\n", fraction);
    } else {
      constexpr int kWidth = 40;
      const int filled = int(fraction * kWidth + 0.5);
      std::fprintf(stderr, "\r%s [%s%s] %3d%%", label_.c_str(), std::string(filled, '#').c_str(),
                   std::string(kWidth - filled, ' ').c_str(), int(fraction * 100 + 0.5));
      if (fraction >= 1.0) std::fprintf(stderr, "\n");
    }
    std::fflush(stderr);
  }
  // Ends the updates with 1 if the bake never reported it (every receiver taken from the cache).
  void finish() { update(1.0); }

 private:
  std::string label_;
  bool lines_;
  std::mutex mutex_;
  std::chrono::steady_clock::time_point last_{};
  bool finished_ = false;
};

struct BakeArgs {
  std::vector<std::string> scenes;  // one, or a batch
  std::string list;                 // a file naming more scenes, one per line
  std::string out_dir;
  std::optional<std::string> shard;  // "K/N" or "auto/N"
  sb::ShardBalance balance = sb::ShardBalance::cost;
  bool shard_tiles = true;  // --shard-tiles auto (off: false)
  std::optional<std::string> method, quantity;
  std::optional<int> resolution, samples;
  std::optional<double> texels_per_metre;
  std::optional<double> ao_distance;
  std::optional<double> irradiance_floor;
  std::optional<std::string> encoding;
  std::optional<int> atlas_size, atlas_padding;
  bool per_light = false, shadowmask = false, gltf = false, no_atlas = false;
  std::optional<std::uint64_t> seed;
  std::optional<double> error_texels;
  std::optional<std::uint64_t> max_memory;
  int threads = 0;
  bool quiet = false;
  bool progress_lines = false;  // --progress-lines: `progress F` lines on stderr
  bool explain = false;
  bool no_trace = false;
  bool no_convolve = false;
  bool no_seams = false;
  std::optional<std::string> preset;  // "preview" or "final"
  // Incremental bakes (pipeline/bake_cache.h).
  bool force = false, no_cache = false;
  std::vector<std::string> only, lights;
  bool watch = false;
};

// --explain: per receiver its stage times, the method's figures and what the method says of its
// choices (the convolution: its plan, directions, planes, error metric, images and stage times).
void print_explanation(const sb::BakeResult& result) {
  for (const auto& r : result.receivers) {
    fmt::print("{}: texel space {:.1f} ms, method {:.1f} ms, dilation {:.1f} ms, seams {:.1f} ms\n",
               r.name, 1e3 * r.seconds_texels, 1e3 * r.seconds_method, 1e3 * r.seconds_dilate,
               1e3 * r.seconds_seams);
    for (const auto& [key, value] : r.report.stats) fmt::print("    {} = {:.4g}\n", key, value);
    fmt::print("{}", r.report.explain);
  }
}

// --preset: "final" bakes the scene as it says; "preview" a faithful look in seconds (docs/cli.md,
// "Presets"): a quarter of the texels per side (at least 16), the lightmaps alone (no per-light
// images or shadow masks), rays at 16 samples or fewer (at a sixteenth of the texels the
// reference's rays are faster than any estimator's per-light set-up: measured on the hall
// level), no seams pass. Options given beside it override it.
void apply_preset(const std::string& preset, sb::BakeSettings& settings,
                  sb::OutputSettings& output) {
  if (preset != "preview") return;
  if (settings.texels_per_metre > 0)
    settings.texels_per_metre /= 4;
  else
    settings.resolution = std::max(16, settings.resolution / 4);
  if (settings.quantity != sb::Quantity::ambient_occlusion) settings.method = "reference";
  settings.samples = std::min(settings.samples, 16);
  settings.seams = false;
  output.per_light = false;
  output.shadowmask = false;
}

// Applies the options given on the command line over the scene file's settings and outputs; the
// error is a --quantity and --method that do not pair.
sb::Status apply_options(const BakeArgs& args, sb::Scene& scene) {
  auto& settings = scene.bake;
  if (args.preset) apply_preset(*args.preset, settings, scene.output);
  if (args.method) settings.method = *args.method;
  if (args.quantity) {
    settings.quantity = *args.quantity == "irradiance"          ? sb::Quantity::irradiance
                        : *args.quantity == "ambient-occlusion" ? sb::Quantity::ambient_occlusion
                                                                : sb::Quantity::visibility;
  }
  if (args.quantity || args.method) {
    if (sb::Status paired = sb::pair_quantity_and_method(
            settings, sb::method_baking_only(sb::Quantity::ambient_occlusion),
            args.quantity.has_value(), args.method.has_value(), "--quantity/--method");
        !paired)
      return paired.error();
  }
  if (args.ao_distance) settings.ao_distance = *args.ao_distance;
  if (args.irradiance_floor) settings.irradiance_floor = *args.irradiance_floor;
  if (args.resolution) {
    settings.resolution = *args.resolution;
    settings.texels_per_metre = 0;
  }
  if (args.texels_per_metre) settings.texels_per_metre = *args.texels_per_metre;
  sb::OutputSettings& output = scene.output;
  if (args.encoding) output.encoding = *sb::parse_encoding(*args.encoding);
  output.per_light |= args.per_light;
  output.shadowmask |= args.shadowmask;
  output.gltf |= args.gltf;
  if (args.atlas_size || args.atlas_padding) {
    if (!output.atlas) output.atlas = sb::AtlasSettings{};
    if (args.atlas_size) output.atlas->size = *args.atlas_size;
    if (args.atlas_padding) output.atlas->padding = *args.atlas_padding;
  }
  if (args.no_atlas) output.atlas.reset();
  if (args.samples) settings.samples = *args.samples;
  if (args.seed) settings.seed = *args.seed;
  if (args.error_texels) set_setting(settings, "error_texels", *args.error_texels);
  if (args.max_memory) settings.max_memory = *args.max_memory;
  if (args.no_trace) set_setting(settings, "trace", false);
  if (args.no_convolve) set_setting(settings, "convolve", false);
  if (args.no_seams) settings.seams = false;
  return sb::Ok{};
}

// Prints each receiver baked, then the scene's (or the shard's) line with its steps' times.
void print_summary(const sb::BakeResult& result, const sb::BakeSettings& settings,
                   const std::optional<sb::ShardSpec>& shard, const std::string& out_dir,
                   double write_seconds, double total_seconds) {
  std::size_t reused = 0;
  const bool tiles = std::any_of(result.receivers.begin(), result.receivers.end(),
                                 [](const sb::ReceiverBake& r) { return bool(r.tile); });
  for (const auto& r : result.receivers) {
    reused += r.reuse == "reused";
    const std::string rows =
        r.tile ? fmt::format(", rows {} to {}", r.tile->begin, r.tile->end - 1) : "";
    fmt::print("  {:<16} {}²{} ({} texels covered, {})\n", r.name, r.image.width, rows,
               r.covered_texels,
               r.reuse == "reused" ? "reused" : fmt::format("{:.2f} s", r.seconds));
  }
  const std::string size = settings.texels_per_metre > 0
                               ? fmt::format("{:.4g} texels per metre", settings.texels_per_metre)
                               : fmt::format("{}²", settings.resolution);
  const std::string atlases =
      result.atlas ? fmt::format(", {} atlas(es)", result.atlas->sizes.size()) : "";
  const std::string what = shard ? fmt::format("shard {}/{}: ", shard->index, shard->count) : "";
  fmt::print(
      "{}baked {} {}{} with '{}' at {}{} into {}/ ({}): load {:.2f} s, bake "
      "{:.2f} s, write {:.2f} s, total {:.2f} s\n",
      what, result.receivers.size(), tiles ? "receiver(s) or tile(s)" : "receiver(s)",
      reused ? fmt::format(" ({} taken unchanged from the earlier bake)", reused) : "",
      settings.method, size, atlases, out_dir, shard ? sb::kShardFile : "manifest.json",
      result.load_seconds, result.bake_seconds, write_seconds, total_seconds);
}

// Bakes one scene into `out_dir` (a shard's part of it, with --shard); the exit code.
int bake_scene(const BakeArgs& args, const std::string& scene_file, const std::string& out_dir) {
  const auto start = std::chrono::steady_clock::now();
  std::optional<sb::ShardSpec> shard;
  if (args.shard) {
    auto spec = sb::parse_shard(*args.shard);
    if (!spec) return fail(spec.error());
    spec->balance = args.balance;
    spec->tiles = args.shard_tiles;
    shard = *spec;
  }
  // Ambient occlusion asked for here needs no light in the file.
  const bool ambient_occlusion =
      args.quantity == "ambient-occlusion" || args.method == "ambient-occlusion";
  auto scene = sb::load_scene(scene_file, !ambient_occlusion);
  if (!scene) return fail(scene.error());
  auto& settings = scene->bake;
  if (sb::Status applied = apply_options(args, *scene); !applied) return fail(applied.error());

  // The output folder is locked and its names checked before the bake, so a bake that could not
  // publish its files fails in a second, not after its work.
  if (sb::Status names = sb::check_output_names(*scene); !names) return fail(names.error());
  auto folder = sb::OutputFolder::open(out_dir);
  if (!folder) return fail(folder.error());
  // With an atlas, the first atlas's names (how many there are is known after the bake); a
  // shard's names once it knows its receivers.
  if (!shard)
    if (sb::Status targets = folder->check_targets(sb::output_names(*scene)); !targets)
      return fail(targets.error());

  const bool show_progress = args.progress_lines || (!args.quiet && ::isatty(STDERR_FILENO));
  ProgressBar bar("baking " + settings.method, args.progress_lines);
  sb::BakeOptions options;
  options.threads = args.threads;
  options.shard = shard;
  // A bake keeps each receiver's result for the next into this folder, and takes what it can
  // from the last; a shard's receivers go to its merge instead.
  options.keys = !args.no_cache && !shard;
  if (options.keys) options.reuse_from = out_dir;
  options.force = args.force;
  options.only = args.only;
  options.relight = args.lights;
  if (show_progress) options.progress = [&bar](double f) { bar.update(f); };

  auto result = sb::bake(*scene, options);
  if (!result) return fail(result.error());
  if (show_progress) bar.finish();
  for (const auto& w : result->warnings)
    std::fprintf(stderr, "shadowbake: warning: %s\n", w.c_str());

  const auto write_start = std::chrono::steady_clock::now();
  auto written = shard ? sb::write_shard(*folder, *scene, *shard, *result)
                       : sb::write_outputs(*folder, *scene, settings, *result);
  reraise_pending_interrupt();
  if (!written) return fail(written.error());
  const double write_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - write_start).count();
  const double total_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (args.explain) print_explanation(*result);

  if (!args.quiet) print_summary(*result, settings, shard, out_dir, write_seconds, total_seconds);
  return ok;
}

// The scenes a list file names: a scene file per line, relative to the list file's folder;
// blank lines and lines starting with '#' are skipped.
sb::Expected<std::vector<std::string>> read_scene_list(const std::string& list) {
  std::ifstream in(list);
  if (!in) return sb::input_error(list + ": cannot read the list of scenes");
  std::vector<std::string> scenes;
  std::string line;
  const std::filesystem::path folder = std::filesystem::path(list).parent_path();
  while (std::getline(in, line)) {
    while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
    std::size_t first = 0;
    while (first < line.size() && std::isspace(static_cast<unsigned char>(line[first]))) ++first;
    line.erase(0, first);
    if (line.empty() || line.front() == '#') continue;
    const std::filesystem::path scene(line);
    scenes.push_back(scene.is_absolute() ? line : (folder / scene).lexically_normal().string());
  }
  return scenes;
}

// In a batch, scene `file`'s output folder: OUT/<its path without the extension>, made
// relative (scenes/hall/scene.toml → OUT/scenes/hall/scene), so distinct scenes never share one.
std::string batch_folder(const std::string& out_dir, const std::string& file) {
  std::filesystem::path relative, stem = std::filesystem::path(file).lexically_normal();
  stem.replace_extension();
  for (const auto& part : stem)
    if (part != ".." && part != "." && !part.has_root_directory() && !part.has_root_name() &&
        !part.empty())
      relative /= part;
  return (std::filesystem::path(out_dir) / relative).string();
}

// One scene into its folder, or a batch, each scene into its own folder under OUT: the library
// is loaded once for all. A scene that fails does not stop the others; the exit code is the
// first failure's.
// --watch: the files a bake of `scene_file` reads — the scene file, its objects' meshes (a
// level's file for its objects) and its lights' images — with their times and sizes; a scene
// that does not load is watched by its own file alone.
using FileStamps =
    std::vector<std::pair<std::filesystem::path, std::pair<std::int64_t, std::int64_t>>>;
FileStamps watched_files(const std::string& scene_file) {
  std::vector<std::filesystem::path> files = {scene_file};
  if (auto scene = sb::load_scene(scene_file, false)) {
    for (const auto& o : scene->objects) files.push_back(o.mesh);
    for (const auto& l : scene->lights)
      if (!l.texture.empty()) files.push_back(l.texture);
  }
  std::sort(files.begin(), files.end());
  files.erase(std::unique(files.begin(), files.end()), files.end());
  FileStamps stamps;
  for (const auto& f : files) {
    std::error_code error;
    const auto time = std::filesystem::last_write_time(f, error);
    const auto size = std::filesystem::file_size(f, error);
    stamps.push_back({f,
                      {error ? -1 : std::int64_t(time.time_since_epoch().count()),
                       error ? -1 : std::int64_t(size)}});
  }
  return stamps;
}

// Bakes the scene, then again each time one of the files it reads changes (incrementally: the
// folder's cache keeps what did not change), until interrupted (SIGINT, SIGTERM). A failed bake
// prints its error and is retried at the next change.
[[noreturn]] void watch_scene(const BakeArgs& args, const std::string& scene_file) {
  constexpr auto kPoll = std::chrono::milliseconds(250);
  for (;;) {
    bake_scene(args, scene_file, args.out_dir);
    reraise_pending_interrupt();
    const FileStamps before = watched_files(scene_file);
    if (!args.quiet)
      fmt::print("watching {} file(s) of {}; Ctrl-C stops\n", before.size(), scene_file);
    std::fflush(stdout);
    FileStamps now = before;
    while (now == before) {
      std::this_thread::sleep_for(kPoll);
      now = watched_files(scene_file);
    }
    // Editors and exporters write in steps: wait until the files hold still for one poll.
    for (FileStamps next = watched_files(scene_file); next != now;
         next = watched_files(scene_file)) {
      now = std::move(next);
      std::this_thread::sleep_for(kPoll);
    }
  }
}

int run_bake(const BakeArgs& args) {
  std::vector<std::string> scenes = args.scenes;
  if (!args.list.empty()) {
    auto listed = read_scene_list(args.list);
    if (!listed) return fail(listed.error());
    scenes.insert(scenes.end(), listed->begin(), listed->end());
  }
  if (scenes.empty()) return fail(sb::scene_error("bake: no scene given (a file, or --list FILE)"));
  if (args.watch) {
    if (scenes.size() != 1 || !args.list.empty())
      return fail(sb::scene_error("bake --watch: one scene file, not a batch"));
    watch_scene(args, scenes[0]);
  }
  if (scenes.size() == 1 && args.list.empty()) return bake_scene(args, scenes[0], args.out_dir);
  int first_failure = ok, failed = 0;
  const auto start = std::chrono::steady_clock::now();
  for (const std::string& scene : scenes) {
    const int code = bake_scene(args, scene, batch_folder(args.out_dir, scene));
    reraise_pending_interrupt();
    if (code == ok) continue;
    ++failed;
    if (first_failure == ok) first_failure = code;
  }
  if (!args.quiet)
    fmt::print("batch: {} of {} scene(s) baked into {}/ in {:.2f} s{}\n", scenes.size() - failed,
               scenes.size(), args.out_dir,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
               failed ? fmt::format("; {} failed (above)", failed) : "");
  return first_failure;
}

// What `bake`'s options parse into. An option whose absence leaves the scene file's setting is
// copied into `args` only where given (read_given_options), so each keeps its CLI::Option.
struct Options {
  BakeArgs args;
  std::string method, quantity;
  int resolution = 0, samples = 0;
  std::int64_t seed = 0;
  double error_texels = 1;
  double ao_distance = 10;
  double irradiance_floor = 0;
  std::string max_memory;
  double texels_per_metre = 0;
  std::string encoding, shard, balance, preset, shard_tiles;
  int atlas_size = 0, atlas_padding = 0;
  CLI::Option *method_opt = nullptr, *quantity_opt = nullptr, *ao_distance_opt = nullptr,
              *floor_opt = nullptr, *resolution_opt = nullptr, *density_opt = nullptr,
              *encoding_opt = nullptr, *atlas_opt = nullptr, *padding_opt = nullptr,
              *samples_opt = nullptr, *seed_opt = nullptr, *memory_opt = nullptr,
              *error_opt = nullptr;
};

// The scenes, the output folder and the shard to bake.
void add_input_options(CLI::App* bake, Options* o) {
  bake->add_option("scene", o->args.scenes, "scene file(s) (TOML, docs/scene-format.md)");
  bake->add_option("--list", o->args.list,
                   "a file naming scene files, one per line (relative to it), baked as a batch");
  bake->add_option("-o,--output", o->args.out_dir, "output folder (created if missing)")
      ->required();
  bake->add_option("--shard", o->shard,
                   "bake shard K of N (K/N, 0 <= K < N; auto/N takes K from "
                   "SLURM_ARRAY_TASK_ID or JOB_COMPLETION_INDEX) for `shadowbake merge`");
  bake->add_option("--shard-balance", o->balance,
                   "how receivers are dealt to shards: cost (default) or count (round robin)")
      ->check(CLI::IsMember({"cost", "count"}));
  bake->add_option("--shard-tiles", o->shard_tiles,
                   "auto (default): a receiver dearer than a shard's share is split into tiles "
                   "of rows, for methods that allow it; off: receivers stay whole")
      ->check(CLI::IsMember({"auto", "off"}));
}

// What is baked and written: the method, the quantity and its reach, the lightmaps' size, their
// encoding, what else is written beside them, the atlases.
void add_setting_options(CLI::App* bake, Options* o) {
  o->method_opt = bake->add_option("--method", o->method, "bake method (overrides [bake] method)")
                      ->check(CLI::IsMember(sb::known_methods()));
  o->quantity_opt =
      bake->add_option("--quantity", o->quantity,
                       "visibility, irradiance or ambient-occlusion (overrides [bake] quantity)")
          ->check(CLI::IsMember({"visibility", "irradiance", "ambient-occlusion"}));
  o->ao_distance_opt =
      bake->add_option("--ao-distance", o->ao_distance,
                       "ambient occlusion: metres within which a blocker occludes (overrides "
                       "[bake] ao_distance)")
          ->check(CLI::Range(1e-6, 1e6));
  o->floor_opt =
      bake->add_option("--irradiance-floor", o->irradiance_floor,
                       "W/m²: a light without a range reaches as far as its irradiance stays "
                       "above this (overrides [bake] irradiance_floor; 0: everywhere)")
          ->check(CLI::Range(0.0, 1e9));
  o->resolution_opt = bake->add_option("--resolution", o->resolution, "texels per side")
                          ->check(CLI::Range(1, 16384));
  o->density_opt =
      bake->add_option("--texels-per-metre", o->texels_per_metre,
                       "size each lightmap by its surface: texels per metre (overrides [bake])")
          ->check(CLI::Range(1e-6, 1e6));
  o->resolution_opt->excludes(o->density_opt);
  o->encoding_opt = bake->add_option("--encoding", o->encoding,
                                     "lightmap files: linear-exr, half-exr, png, rgbm-png")
                        ->check(CLI::IsMember({"linear-exr", "half-exr", "png", "rgbm-png"}));
  bake->add_flag("--per-light", o->args.per_light, "also write each light's own image");
  bake->add_flag("--shadowmask", o->args.shadowmask,
                 "also write shadow masks: up to four lights in R, G, B, A");
  bake->add_flag("--gltf", o->args.gltf, "also write scene.glb with the lightmaps bound");
  o->atlas_opt =
      bake->add_option("--atlas", o->atlas_size, "pack the lightmaps into atlases of this size")
          ->check(CLI::Range(64, 16384));
  o->padding_opt =
      bake->add_option("--atlas-padding", o->atlas_padding, "texels around each atlas rectangle")
          ->check(CLI::Range(1, 256));
  auto* no_atlas_opt = bake->add_flag("--no-atlas", o->args.no_atlas,
                                      "one set of files per receiver, whatever [output] says");
  no_atlas_opt->excludes(o->atlas_opt)->excludes(o->padding_opt);
}

// How the bake samples and runs: its budgets, switches, threads, progress lines and preset.
void add_run_options(CLI::App* bake, Options* o) {
  o->samples_opt = bake->add_option("--samples", o->samples, "light samples per texel")
                       ->check(CLI::Range(1, 1 << 20));
  o->seed_opt = bake->add_option("--seed", o->seed, "sampling seed (0 or more)")
                    ->check(CLI::Range(std::int64_t(0), std::numeric_limits<std::int64_t>::max()));
  o->memory_opt =
      bake->add_option("--max-memory", o->max_memory,
                       "memory the bake may use, e.g. \"8 GiB\" (overrides [bake] max_memory)")
          ->check(CLI::Validator(
              [](std::string& text) {
                std::uint64_t bytes = 0;
                return sb::parse_memory_size(text, bytes)
                           ? std::string()
                           : "must be a size such as 8GiB or 512MiB, got '" + text + "'";
              },
              "SIZE"));
  o->error_opt =
      bake->add_option("--error-texels", o->error_texels,
                       "convolution: penumbra error allowed, receiver texels (overrides [bake])")
          ->check(CLI::PositiveNumber);
  bake->add_option("--threads", o->args.threads, "worker threads (0: all cores)")
      ->check(CLI::Range(0, 1024));
  bake->add_flag("-q,--quiet", o->args.quiet, "no progress bar and no summary");
  bake->add_flag("--progress-lines", o->args.progress_lines,
                 "print progress as lines 'progress F' (F from 0 to 1) on stderr, at most ten a "
                 "second and a last one of 1, even with --quiet or when stderr is no terminal");
  bake->add_flag("--no-trace", o->args.no_trace,
                 "convolution: trace no shadow rays, even where it cannot vouch for its values "
                 "(overrides [bake] trace)");
  bake->add_flag("--no-convolve", o->args.no_convolve,
                 "convolution: skip the convolution, trace every pair the shaft test keeps "
                 "(overrides [bake] convolve)");
  bake->add_flag("--no-seams", o->args.no_seams,
                 "leave the texels along UV seams as baked; only measure the seams (overrides "
                 "[bake] seams)");
  bake->add_option("--preset", o->preset,
                   "preview: a quarter of the texels per side, rays at 16 samples or fewer, the "
                   "lightmaps alone, no seams pass; final: the scene's settings (options given "
                   "beside it override it)")
      ->check(CLI::IsMember({"preview", "final"}));
}

// Incremental bakes (pipeline/bake_cache.h): what is baked again, what is taken from the folder's
// earlier bake, and --watch.
void add_incremental_options(CLI::App* bake, Options* o) {
  bake->add_flag("--force", o->args.force,
                 "bake every receiver, even those the folder's earlier bake holds unchanged")
      ->excludes("--shard");
  bake->add_option("--only", o->args.only,
                   "bake these receivers; the others are taken from the folder's earlier bake "
                   "where it has them, changed or not")
      ->excludes("--force")
      ->excludes("--shard");
  bake->add_option("--lights", o->args.lights,
                   "bake the receivers these lights may reach; the others are taken from the "
                   "folder's earlier bake where it has them, changed or not")
      ->excludes("--force")
      ->excludes("--shard");
  bake->add_flag("--watch", o->args.watch,
                 "bake, then bake again (incrementally) whenever the scene file, a mesh or a "
                 "light's image changes, until interrupted")
      ->excludes("--shard");
  bake->add_flag("--no-cache", o->args.no_cache,
                 "neither take receivers from the folder's earlier bake nor keep this bake's "
                 "for the next (.shadowbake-cache)")
      ->excludes("--force")
      ->excludes("--only")
      ->excludes("--lights");
}

// Copies the options into `args`: those that stand in for a scene file's setting only where
// given, so that the scene's own setting holds otherwise.
void read_given_options(Options* o) {
  if (*o->method_opt) o->args.method = o->method;
  if (*o->quantity_opt) o->args.quantity = o->quantity;
  if (*o->ao_distance_opt) o->args.ao_distance = o->ao_distance;
  if (*o->floor_opt) o->args.irradiance_floor = o->irradiance_floor;
  if (*o->resolution_opt) o->args.resolution = o->resolution;
  if (*o->density_opt) o->args.texels_per_metre = o->texels_per_metre;
  if (!o->shard.empty()) o->args.shard = o->shard;
  if (!o->preset.empty()) o->args.preset = o->preset;
  if (o->balance == "count") o->args.balance = sb::ShardBalance::count;
  o->args.shard_tiles = o->shard_tiles != "off";
  if (*o->encoding_opt) o->args.encoding = o->encoding;
  if (*o->atlas_opt) o->args.atlas_size = o->atlas_size;
  if (*o->padding_opt) o->args.atlas_padding = o->atlas_padding;
  if (*o->samples_opt) o->args.samples = o->samples;
  if (*o->seed_opt) o->args.seed = std::uint64_t(o->seed);
  if (*o->memory_opt) {
    std::uint64_t bytes = 0;
    sb::parse_memory_size(o->max_memory, bytes);
    o->args.max_memory = bytes;
  }
  if (*o->error_opt) o->args.error_texels = o->error_texels;
}

}  // namespace

Runner add_bake_command(CLI::App& app) {
  auto o = std::make_shared<Options>();
  auto* bake = app.add_subcommand(
      "bake", "bake every receiver of a scene into OUTDIR (several scenes: each into OUTDIR/...)");
  add_input_options(bake, o.get());
  add_setting_options(bake, o.get());
  add_run_options(bake, o.get());
  add_incremental_options(bake, o.get());
  bake->add_flag("--explain", o->args.explain,
                 "print, per light and receiver, the convolution's direction, planes, error "
                 "metric, image sizes and stage times");
  return [o]() {
    read_given_options(o.get());
    return run_bake(o->args);
  };
}

}  // namespace sbcli
