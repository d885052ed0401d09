// The corpus benchmark (issue "Exact penumbrae without noise"): for every scene of the corpus and
// every receiver, the default `backprojection` bake against the reference at 16, 64, 256 and
// 1024 samples, in one program, side by side: each variant's in-process time (median of
// --repeat runs, interleaved; the reference at 1024 samples once), its RMSE against a truth (the
// reference at --truth-samples, 4096 by default, with its own seed) over covered texels, the
// default's route shares (method_stats), the peak memory of a whole `shadowbake bake` process
// (its VmHWM) for the default and the reference at 64, and the equal-error speed ratios: the
// time the reference needs to reach RMSE --target (0.005) and the default's own RMSE,
// interpolated on its error curve (log RMSE against log time, between the two samples counts
// around the target; never extrapolated: where the default is more accurate than the reference
// at 1024 samples, the ratio is given as at least that reference's time over the default's).
//
// A receiver's time is its own texel space, method and dilation, plus a share of the scene's
// load (meshes, rays, shaft hierarchy) in proportion to its texels. A scene's time is its whole
// bake (load and every receiver); its RMSE pools every receiver's covered texels.
//
// Levels made by others (--levels, paths from the repository's root, each PATH or
// PATH@TEXELS_PER_METRE) are baked at their own sizes (or that density) and margins, not at
// --resolution; `--levels` alone leaves out the corpus. Per scene it also counts wrong texels:
// those off the truth by more than 0.25 where the reference at 64 samples is within 0.1 of it.
//
// Run: build/shadowbake_corpus_bench [--scenes room/scene.toml,...] [--repeat 5]
//      [--truth-samples 4096] [--resolution 512] [--target 0.005] [--json out/corpus.json]
//      [--truth-only 1] [--levels ../shared/assets/godot/zdm2.toml@5,...]
//      [--variants backprojection,reference-64,reference-256]
// The truths are cached under out/corpus-truth/ (keyed by the scene file's bytes, its size,
// samples and the library's sources), so later runs of the same build only bake the variants.
#include <fmt/core.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "core/image_io.h"
#include "pipeline/bake.h"
#include "scene/level_file.h"
#include "scene/scene.h"
#include "source_hash.h"  // generated at build time (CMakeLists.txt, script mode)
#include "support/image_errors.h"

namespace {

namespace fs = std::filesystem;

struct Variant {
  std::string label;
  std::string method;
  int samples = 0;      // the reference's; 0 for the default
  bool repeat = true;   // timed --repeat times (else once)
  bool memory = false;  // its peak memory measured
};

std::vector<Variant> variants() {
  return {{"backprojection", "backprojection", 0, true, true},
          {"reference-16", "reference", 16, true, false},
          {"reference-64", "reference", 64, true, true},
          {"reference-256", "reference", 256, true, false},
          {"reference-1024", "reference", 1024, false, false}};
}

const std::vector<std::string> kDefaultScenes = {
    "room/scene.toml",          "room/scene_disk.toml",   "atrium/scene.toml",
    "atrium/scene_sconce.toml", "atrium/scene_bulb.toml", "shelf/scene.toml",
    "dense/scene.toml",         "hall/scene.toml",        "suzanne/scene.toml",
    "showcase/scene.toml"};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty()      ? NAN
         : v.size() % 2 ? v[v.size() / 2]
                        : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// Peak resident memory of a whole `shadowbake bake` process, MiB.
double process_peak_mib(const std::string& scene, const Variant& v,
                        const std::vector<std::string>& sizing) {
  const fs::path out =
      fs::temp_directory_path() / ("shadowbake_corpus_mem_" + std::to_string(::getpid()));
  std::vector<std::string> args = {SB_CLI,       "bake", scene,      "-o",
                                   out.string(), "-q",   "--method", v.method};
  args.insert(args.end(), sizing.begin(), sizing.end());
  if (v.samples > 0) {
    args.push_back("--samples");
    args.push_back(std::to_string(v.samples));
  }
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::freopen("/dev/null", "w", stderr);
    ::execv(SB_CLI, argv.data());
    ::_exit(127);
  }
  // The child's own high-water mark (VmHWM, of its address space after exec), read every 5 ms
  // until it ends. Not wait4's ru_maxrss: Linux folds into it the resident size of the forked
  // copy of this process before exec, so it would report this benchmark's own memory.
  int status = 0;
  double peak_kib = 0;
  const std::string proc = "/proc/" + std::to_string(pid) + "/status";
  while (::waitpid(pid, &status, WNOHANG) == 0) {
    std::ifstream in(proc);
    bool execed = false;  // before exec the child is a copy of this benchmark
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("Name:", 0) == 0) execed = line == "Name:\tshadowbake";
      if (execed && line.rfind("VmHWM:", 0) == 0)
        peak_kib = std::max(peak_kib, std::stod(line.substr(6)));
    }
    ::usleep(5000);
  }
  fs::remove_all(out);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return NAN;
  return peak_kib / 1024.0;
}

// The reference's time at RMSE `target` on its curve of (time, rmse) points, interpolated in
// log-log between the two points around it; nullopt where the target lies outside them (above
// the fewest samples' error, or below the most's).
std::optional<double> time_at(std::vector<std::pair<double, double>> curve, double target) {
  std::sort(curve.begin(), curve.end());
  for (std::size_t i = 1; i < curve.size(); ++i) {
    const auto& [t0, e0] = curve[i - 1];
    const auto& [t1, e1] = curve[i];
    if (!(t0 > 0 && t1 > 0 && e0 > 0 && e1 > 0)) continue;
    if (!(e0 >= target && target >= e1)) continue;
    if (e0 == e1) return t0;
    const double s = (std::log(target) - std::log(e0)) / (std::log(e1) - std::log(e0));
    return std::exp(std::log(t0) + s * (std::log(t1) - std::log(t0)));
  }
  return std::nullopt;
}

struct Measured {
  std::map<std::string, std::vector<double>> seconds;
  std::map<std::string, double> rmse;
  std::map<std::string, std::int64_t> texels;
  std::map<std::string, sb::MethodStats> stats;
  std::vector<double> scene_runs;
  std::vector<double> scene_bakes;  // bake_seconds alone (the scene loaded)
  double scene_rmse = 0;
  double peak_mib = NAN;
};

// Where `target` lies below every point of the curve (more accurate than the reference at its
// most samples): the time of that point, which the reference needs at least to reach it.
std::optional<double> time_beyond(const std::vector<std::pair<double, double>>& curve,
                                  double target) {
  std::optional<double> best;
  double best_error = INFINITY;
  for (const auto& [t, e] : curve)
    if (t > 0 && e > 0 && e < best_error) best_error = e, best = t;
  if (best && target > 0 && target < best_error) return best;
  return std::nullopt;
}

std::string ratio_text(const std::optional<double>& reference, double ours,
                       const std::optional<double>& at_least = std::nullopt) {
  if (reference) return fmt::format("{:.1f}", *reference / ours);
  if (at_least) return fmt::format("> {:.1f}", *at_least / ours);
  return "-";
}

}  // namespace

// A scene to bake: its file, and how it is sized.
struct SceneSpec {
  fs::path file;
  std::string name;                        // as printed
  std::optional<double> texels_per_metre;  // a level's density, where given
  bool level = false;                      // its own sizes and margin, not --resolution
};

int main(int argc, char** argv) {
  std::vector<std::string> scenes = kDefaultScenes;
  std::vector<std::string> levels;
  std::vector<std::string> only_variants;
  int repeat = 5, truth_samples = 4096, resolution = 512;
  double target = 0.005;
  bool truth_only = false;
  std::string json_path;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--scenes") {
      scenes.clear();
      std::stringstream list(value);
      for (std::string s; std::getline(list, s, ',');) scenes.push_back(s);
    } else if (key == "--repeat") {
      repeat = std::stoi(value);
    } else if (key == "--truth-samples") {
      truth_samples = std::stoi(value);
    } else if (key == "--resolution") {
      resolution = std::stoi(value);
    } else if (key == "--target") {
      target = std::stod(value);
    } else if (key == "--json") {
      json_path = value;
    } else if (key == "--truth-only") {
      truth_only = value == "1";
    } else if (key == "--levels" || key == "--variants") {
      std::vector<std::string>& list = key == "--levels" ? levels : only_variants;
      if (key == "--levels" && scenes == kDefaultScenes) scenes.clear();
      std::stringstream items(value);
      for (std::string item; std::getline(items, item, ',');) list.push_back(item);
    } else {
      fmt::print(stderr, "unknown option {}\n", key);
      return 2;
    }
  }
  std::vector<Variant> vs;
  for (const Variant& v : variants())
    if (only_variants.empty() || v.label == "backprojection" ||
        std::find(only_variants.begin(), only_variants.end(), v.label) != only_variants.end())
      vs.push_back(v);
  // The reference at 64 samples: the speed goal's yardstick and the wrong texels' witness.
  std::size_t ref64 = 0;
  for (std::size_t k = 0; k < vs.size(); ++k)
    if (vs[k].label == "reference-64") ref64 = k;
  if (ref64 == 0) {
    fmt::print(stderr, "the variants must include reference-64\n");
    return 2;
  }
  std::vector<SceneSpec> specs;
  for (const std::string& name : scenes)
    specs.push_back({fs::path(SB_SOURCE_DIR) / "scenes" / name, name, std::nullopt, false});
  for (const std::string& item : levels) {
    SceneSpec spec;
    spec.level = true;
    spec.name = item;
    const std::size_t at = item.rfind('@');
    spec.file = fs::path(SB_SOURCE_DIR) / item.substr(0, at);
    if (at != std::string::npos) spec.texels_per_metre = std::stod(item.substr(at + 1));
    specs.push_back(spec);
  }
  nlohmann::ordered_json report = nlohmann::ordered_json::array();
  const fs::path cache = fs::path(SB_SOURCE_DIR) / "out" / "corpus-truth";

  for (const SceneSpec& spec : specs) {
    const fs::path& file = spec.file;
    const std::string& name = spec.name;
    auto loaded =
        spec.file.extension() == ".toml" ? sb::load_scene(file) : sb::load_level_scene(file);
    if (!loaded) {
      fmt::print(stderr, "{}\n", loaded.error().message);
      return 3;
    }
    sb::Scene scene = *loaded;
    if (!spec.level) {
      scene.bake.resolution = resolution;
      scene.bake.margin = 0;
    } else if (spec.texels_per_metre) {
      scene.bake.texels_per_metre = *spec.texels_per_metre;
    }
    const std::string size_key = spec.level
                                     ? fmt::format("level/{}", spec.texels_per_metre.value_or(0))
                                     : std::to_string(resolution);

    // The truth, cached by the scene file's bytes and the build's sources (a change to the
    // reference, or to what every method shares, changes the truth).
    const std::size_t key =
        std::hash<std::string>{}(slurp(file) + size_key + "/" + std::to_string(truth_samples) +
                                 "/" + SHADOWBAKE_SOURCE_HASH);
    const fs::path truth_dir = cache / fmt::format("{:016x}", key);
    std::map<std::string, sb::Image> truth;
    for (const auto& obj : scene.objects) {
      if (!obj.receiver) continue;
      if (auto img = sb::read_image(truth_dir / (obj.name + ".exr"))) truth[obj.name] = *img;
    }
    if (truth.size() != std::size_t(std::count_if(scene.objects.begin(), scene.objects.end(),
                                                  [](const auto& o) { return o.receiver; }))) {
      sb::Scene truth_scene = scene;
      truth_scene.bake.method = "reference";
      truth_scene.bake.samples = truth_samples;
      truth_scene.bake.seed = 12345;  // independent of the variants' seed
      fmt::print(stderr, "{}: baking the reference at {} samples ...\n", name, truth_samples);
      auto result = sb::bake(truth_scene);
      if (!result) {
        fmt::print(stderr, "{}\n", result.error().message);
        return 3;
      }
      fs::create_directories(truth_dir);
      for (const auto& r : result->receivers) {
        truth[r.name] = r.image;
        (void)sb::write_image(truth_dir / (r.name + ".exr"), r.image, sb::PixelFormat::float32);
      }
    }
    if (truth_only) continue;

    // The variants, interleaved repeat by repeat so that load on the machine hits all alike.
    std::vector<Measured> measured(vs.size());
    std::vector<std::string> receivers;
    // The default's and the reference at 64's images of the first repeat, for the wrong texels.
    std::map<std::size_t, std::map<std::string, sb::Image>> first_images;
    std::map<std::string, std::vector<std::uint8_t>> covered_of;
    for (int rep = 0; rep < repeat; ++rep) {
      for (std::size_t k = 0; k < vs.size(); ++k) {
        if (rep > 0 && !vs[k].repeat) continue;
        sb::Scene s = scene;
        s.bake.method = vs[k].method;
        if (vs[k].samples > 0) s.bake.samples = vs[k].samples;
        auto result = sb::bake(s);
        if (!result) {
          fmt::print(stderr, "{} {}: {}\n", name, vs[k].label, result.error().message);
          return 3;
        }
        double total_texels = 0;
        for (const auto& r : result->receivers) total_texels += double(r.covered_texels);
        receivers.clear();
        std::vector<image_errors::Errors> parts;
        for (const auto& r : result->receivers) {
          receivers.push_back(r.name);
          const double share = total_texels > 0 ? double(r.covered_texels) / total_texels : 0;
          measured[k].seconds[r.name].push_back(r.seconds + share * result->load_seconds);
          if (rep == 0) {
            if (k == 0 || k == ref64) first_images[k][r.name] = r.image;
            // Covered texels of this bake (margin 0: every texel with a value is covered).
            const image_errors::Errors e = image_errors::errors(r.image, truth[r.name], r.covered);
            if (k == 0) covered_of[r.name] = r.covered;
            measured[k].rmse[r.name] = e.rmse;
            measured[k].texels[r.name] = e.count;
            measured[k].stats[r.name] = r.report.stats;
            parts.push_back(e);
          }
        }
        if (rep == 0) measured[k].scene_rmse = image_errors::pooled(parts).rmse;
        measured[k].scene_runs.push_back(result->load_seconds + result->bake_seconds);
        measured[k].scene_bakes.push_back(result->bake_seconds);
      }
    }
    std::vector<std::string> sizing;
    if (!spec.level) sizing = {"--resolution", std::to_string(resolution)};
    if (spec.texels_per_metre)
      sizing = {"--texels-per-metre", fmt::format("{}", *spec.texels_per_metre)};
    for (std::size_t k = 0; k < vs.size(); ++k)
      if (vs[k].memory) measured[k].peak_mib = process_peak_mib(file.string(), vs[k], sizing);

    // Per receiver: the default's time, RMSE and routes; the references'; the ratios.
    const Measured& ours = measured[0];
    const auto seconds = [&](std::size_t k, const std::string& r) {
      return median(measured[k].seconds.at(r));
    };
    const auto curve = [&](const std::function<double(std::size_t)>& time,
                           const std::function<double(std::size_t)>& error) {
      std::vector<std::pair<double, double>> points;
      for (std::size_t k = 1; k < vs.size(); ++k) points.emplace_back(time(k), error(k));
      return points;
    };
    fmt::print("\n## {} ({}, truth: reference-{})\n\n", name,
               spec.level ? (spec.texels_per_metre
                                 ? fmt::format("{} texels per metre", *spec.texels_per_metre)
                                 : std::string("its own sizes"))
                          : fmt::format("{}²", resolution),
               truth_samples);
    std::string columns, rule;
    for (std::size_t k = 1; k < vs.size(); ++k) {
      columns += " " + vs[k].label + " s, RMSE |";
      rule += "---|";
    }
    fmt::print(
        "| receiver | backprojection s | RMSE | clear / exact / interpolated / traced |{} "
        "ref-64 / ours | at RMSE {} | at our RMSE |\n|---|---|---|---|{}---|---|---|\n",
        columns, target, rule);
    nlohmann::ordered_json entry;
    entry["scene"] = name;
    entry["resolution"] = resolution;
    entry["truth_samples"] = truth_samples;
    entry["target"] = target;
    for (const std::string& r : receivers) {
      const auto ref_curve = curve([&](std::size_t k) { return seconds(k, r); },
                                   [&](std::size_t k) { return measured[k].rmse.at(r); });
      const double t = seconds(0, r), e = ours.rmse.at(r);
      const auto at_target = time_at(ref_curve, target);
      const auto at_ours = time_at(ref_curve, e);
      const auto beyond = time_beyond(ref_curve, e);
      const auto route = [&](const char* key) {
        for (const auto& [k, v] : ours.stats.at(r))
          if (k == key) return v;
        return 0.0;
      };
      fmt::print("| {} | {:.3f} | {:.4f} | {:.2f} / {:.2f} / {:.2f} / {:.2f} |", r, t, e,
                 route("clear_fraction"), route("exact_fraction"), route("interpolated_fraction"),
                 route("traced_fraction"));
      for (std::size_t k = 1; k < vs.size(); ++k)
        fmt::print(" {:.3f}, {:.4f} |", seconds(k, r), measured[k].rmse.at(r));
      fmt::print(" {:.2f} | {} | {} |\n", seconds(ref64, r) / t, ratio_text(at_target, t),
                 ratio_text(at_ours, t, beyond));
      auto& j = entry["receivers"][r];
      j["texels"] = ours.texels.at(r);
      for (std::size_t k = 0; k < vs.size(); ++k)
        j[vs[k].label] = {{"seconds", seconds(k, r)}, {"rmse", measured[k].rmse.at(r)}};
      for (const auto& [k, v] : ours.stats.at(r)) j["routes"][k] = v;
      j["reference_seconds_at_target"] =
          at_target ? nlohmann::ordered_json(*at_target) : nlohmann::ordered_json();
      j["reference_seconds_at_our_rmse"] =
          at_ours ? nlohmann::ordered_json(*at_ours) : nlohmann::ordered_json();
      j["reference_seconds_at_our_rmse_at_least"] =
          beyond ? nlohmann::ordered_json(*beyond) : nlohmann::ordered_json();
    }
    // Wrong texels: off the truth by more than 0.25 where the reference at 64 is within 0.1.
    std::int64_t wrong = 0;
    for (const std::string& r : receivers) {
      const sb::Image& ours = first_images[0][r];
      const sb::Image& witness = first_images[ref64][r];
      const sb::Image& t = truth[r];
      const std::vector<std::uint8_t>& covered = covered_of[r];
      for (std::size_t i = 0; i < covered.size(); ++i) {
        if (!covered[i]) continue;
        bool off = false;
        for (int c = 0; c < t.channels; ++c) {
          const std::size_t at = i * std::size_t(t.channels) + std::size_t(c);
          off = off || (std::abs(double(ours.pixels[at]) - double(t.pixels[at])) > 0.25 &&
                        std::abs(double(witness.pixels[at]) - double(t.pixels[at])) <= 0.1);
        }
        if (off) {
          if (wrong < 10)
            fmt::print(stderr, "{}: wrong texel {} ({}, {})\n", name, r, i % std::size_t(t.width),
                       i / std::size_t(t.width));
          ++wrong;
        }
      }
    }
    // The scene as a whole.
    const auto scene_curve = curve([&](std::size_t k) { return median(measured[k].scene_runs); },
                                   [&](std::size_t k) { return measured[k].scene_rmse; });
    const double scene_t = median(ours.scene_runs);
    const auto scene_at_target = time_at(scene_curve, target);
    const auto scene_at_ours = time_at(scene_curve, ours.scene_rmse);
    const auto scene_beyond = time_beyond(scene_curve, ours.scene_rmse);
    fmt::print("| **scene** | {:.3f} | {:.4f} | peak {:.0f} MiB (reference-64: {:.0f}) |", scene_t,
               ours.scene_rmse, ours.peak_mib, measured[ref64].peak_mib);
    for (std::size_t k = 1; k < vs.size(); ++k)
      fmt::print(" {:.3f}, {:.4f} |", median(measured[k].scene_runs), measured[k].scene_rmse);
    fmt::print(" {:.2f} | {} | {} |\n", median(measured[ref64].scene_runs) / scene_t,
               ratio_text(scene_at_target, scene_t),
               ratio_text(scene_at_ours, scene_t, scene_beyond));
    const double bake_t = median(ours.scene_bakes),
                 ref64_bake = median(measured[ref64].scene_bakes);
    fmt::print(
        "\nIn-process bake (scene loaded): {:.3f} s against the reference at 64's {:.3f} s "
        "({:.2f}x); wrong texels: {}\n",
        bake_t, ref64_bake, ref64_bake / bake_t, wrong);
    auto& j = entry["scene_totals"];
    j["wrong_texels"] = wrong;
    for (std::size_t k = 0; k < vs.size(); ++k)
      j[vs[k].label] = {{"seconds", median(measured[k].scene_runs)},
                        {"bake_seconds", median(measured[k].scene_bakes)},
                        {"rmse", measured[k].scene_rmse},
                        {"peak_mib", std::isnan(measured[k].peak_mib)
                                         ? nlohmann::ordered_json()
                                         : nlohmann::ordered_json(measured[k].peak_mib)}};
    j["reference_seconds_at_target"] =
        scene_at_target ? nlohmann::ordered_json(*scene_at_target) : nlohmann::ordered_json();
    j["reference_seconds_at_our_rmse"] =
        scene_at_ours ? nlohmann::ordered_json(*scene_at_ours) : nlohmann::ordered_json();
    j["reference_seconds_at_our_rmse_at_least"] =
        scene_beyond ? nlohmann::ordered_json(*scene_beyond) : nlohmann::ordered_json();
    report.push_back(entry);
    std::fflush(stdout);
  }
  if (!json_path.empty()) std::ofstream(json_path) << report.dump(1) << "\n";
  return 0;
}
