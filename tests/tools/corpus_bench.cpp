// The corpus benchmark (issue "The convolution method on the scenes artists bring"): for every
// scene of the corpus and every receiver, each variant's in-process bake time (median of
// --repeat runs, side by side in one program), its RMSE against the reference at
// --truth-samples (covered texels), the peak memory of a whole `shadowbake bake` process (its
// VmHWM), and the equal-error speed ratio: the time each family (the reference at 16/64/256
// samples; the convolution at its settings) needs to reach RMSE --target, interpolated on its
// error curve (log RMSE against log time, between the two points around the target; beyond
// them, from the last two, marked '~').
//
// A receiver's time is its own texel space, method and dilation, plus a share of the scene's
// load (meshes, rays, clusters) in proportion to its texels.
//
// Run: build/shadowbake_corpus_bench [--scenes room/scene.toml,...] [--repeat 5]
//      [--truth-samples 1024] [--resolution 512] [--json out/corpus.json]
// The references at --truth-samples are cached under out/corpus-truth/ (keyed by the scene
// file's bytes, resolution and samples), so later runs only bake the variants.
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
#include "scene/scene.h"
#include "support/image_errors.h"

namespace {

namespace fs = std::filesystem;

struct Variant {
  std::string label, family;  // "reference", "convolution" (the curves), "alone", "shaft"
  std::string method;
  std::vector<std::pair<std::string, std::string>> cli;  // overrides, as the CLI takes them
  std::function<void(sb::BakeSettings&)> apply;
};

std::vector<Variant> variants() {
  std::vector<Variant> v;
  for (int n : {16, 64, 256}) {
    v.push_back({"reference-" + std::to_string(n),
                 "reference",
                 "reference",
                 {{"--samples", std::to_string(n)}},
                 [n](sb::BakeSettings& b) { b.samples = n; }});
  }
  // The convolution alone (no rays: shaft test and convolution), then with rays at 16, 64 and
  // 256 samples where it cannot vouch for its values: the family on the equal-error curve.
  v.push_back(
      {"convolution-alone", "alone", "convolution", {{"--no-trace", ""}}, [](sb::BakeSettings& b) {
         b.trace = false;
       }});
  for (int n : {16, 64, 256}) {
    v.push_back({"convolution-" + std::to_string(n),
                 "convolution",
                 "convolution",
                 {{"--samples", std::to_string(n)}},
                 [n](sb::BakeSettings& b) {
                   b.samples = n;
                   b.trace = true;
                 }});
  }
  // What the convolution contributes to the whole method: the same method with the convolution
  // skipped (the shaft test, then rays at every pair it keeps; the reference's values).
  v.push_back({"shaft-rays-64",
               "shaft",
               "convolution",
               {{"--samples", "64"}, {"--no-convolve", ""}},
               [](sb::BakeSettings& b) {
                 b.samples = 64;
                 b.trace = true;
                 b.convolve = false;
               }});
  return v;
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
double process_peak_mib(const std::string& scene, const Variant& v, int resolution) {
  const fs::path out =
      fs::temp_directory_path() / ("shadowbake_corpus_mem_" + std::to_string(::getpid()));
  std::vector<std::string> args = {
      SB_CLI, "bake",     scene,    "-o",           out.string(),
      "-q",   "--method", v.method, "--resolution", std::to_string(resolution)};
  for (const auto& [k, value] : v.cli) {
    args.push_back(k);
    if (!value.empty()) args.push_back(value);
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

// Time at RMSE `target` on a family's curve of (time, rmse) points; `extrapolated` when the
// target lies outside them.
std::optional<double> time_at(std::vector<std::pair<double, double>> curve, double target,
                              bool* extrapolated) {
  curve.erase(std::remove_if(curve.begin(), curve.end(),
                             [](const auto& p) { return !(p.first > 0 && p.second > 0); }),
              curve.end());
  if (curve.empty()) return std::nullopt;
  std::sort(curve.begin(), curve.end());
  if (curve.size() == 1) {
    *extrapolated = curve[0].second > target;
    if (curve[0].second <= target) return curve[0].first;
    return std::nullopt;
  }
  // First point at or below the target, and the one before it.
  for (std::size_t i = 0; i < curve.size(); ++i) {
    if (curve[i].second > target) continue;
    if (i == 0) {
      *extrapolated = false;
      return curve[0].first;
    }
    const auto& [t0, e0] = curve[i - 1];
    const auto& [t1, e1] = curve[i];
    *extrapolated = false;
    const double s = (std::log(target) - std::log(e0)) / (std::log(e1) - std::log(e0));
    return std::exp(std::log(t0) + s * (std::log(t1) - std::log(t0)));
  }
  // Beyond the last point: the last two points' slope, if the error falls with time.
  const auto& [t0, e0] = curve[curve.size() - 2];
  const auto& [t1, e1] = curve.back();
  if (!(e1 < e0)) return std::nullopt;
  *extrapolated = true;
  const double s = (std::log(target) - std::log(e0)) / (std::log(e1) - std::log(e0));
  return std::exp(std::log(t0) + s * (std::log(t1) - std::log(t0)));
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> scenes = kDefaultScenes;
  int repeat = 5, truth_samples = 1024, resolution = 512;
  bool truth_only = false;
  double target = 0.005;
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
    } else {
      fmt::print(stderr, "unknown option {}\n", key);
      return 2;
    }
  }
  const std::vector<Variant> vs = variants();
  nlohmann::ordered_json report = nlohmann::ordered_json::array();
  const fs::path cache = fs::path(SB_SOURCE_DIR) / "out" / "corpus-truth";

  for (const std::string& name : scenes) {
    const fs::path file = fs::path(SB_SOURCE_DIR) / "scenes" / name;
    auto loaded = sb::load_scene(file);
    if (!loaded) {
      fmt::print(stderr, "{}\n", loaded.error().message);
      return 3;
    }
    sb::Scene scene = *loaded;
    scene.bake.resolution = resolution;
    scene.bake.margin = 0;

    // The truth, cached by the scene file's bytes (and the reference's own version: its samples
    // cover the part of a light above the horizon since version 2).
    const std::size_t key =
        std::hash<std::string>{}(slurp(file) + std::to_string(resolution) + "/" +
                                 std::to_string(truth_samples) + "/reference-2");
    const fs::path truth_dir = cache / fmt::format("{:016x}", key);
    std::map<std::string, sb::Image> truth;
    std::map<std::string, std::vector<std::uint8_t>> covered;
    for (const auto& obj : scene.objects) {
      if (!obj.receiver) continue;
      if (auto img = sb::read_image(truth_dir / (obj.name + ".exr"))) truth[obj.name] = *img;
    }
    sb::Scene truth_scene = scene;
    truth_scene.bake.method = "reference";
    truth_scene.bake.samples = truth_samples;
    truth_scene.bake.seed = 12345;  // independent of the variants' seed
    if (truth.size() != std::size_t(std::count_if(scene.objects.begin(), scene.objects.end(),
                                                  [](const auto& o) { return o.receiver; }))) {
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
    // Variants, interleaved repeat by repeat so that load on the machine hits all alike.
    struct Measured {
      std::map<std::string, std::vector<double>> seconds;
      std::map<std::string, double> error;
      double scene_seconds = 0;
      std::vector<double> scene_runs;
      double peak_mib = NAN;
      int64_t rays = 0;
    };
    std::vector<Measured> measured(vs.size());
    std::vector<std::string> receivers;
    for (int rep = 0; rep < repeat; ++rep) {
      for (std::size_t k = 0; k < vs.size(); ++k) {
        sb::Scene s = scene;
        s.bake.method = vs[k].method;
        vs[k].apply(s.bake);
        auto result = sb::bake(s);
        if (!result) {
          fmt::print(stderr, "{} {}: {}\n", name, vs[k].label, result.error().message);
          return 3;
        }
        double total_texels = 0;
        for (const auto& r : result->receivers) total_texels += double(r.covered_texels);
        receivers.clear();
        for (const auto& r : result->receivers) {
          receivers.push_back(r.name);
          const double share = total_texels > 0 ? double(r.covered_texels) / total_texels : 0;
          measured[k].seconds[r.name].push_back(r.seconds + share * result->load_seconds);
          if (rep == 0) {
            // Covered texels of this bake (margin 0: every texel with a value is covered).
            measured[k].error[r.name] =
                image_errors::errors(r.image, truth[r.name], r.covered).rmse;
          }
        }
        measured[k].scene_runs.push_back(result->load_seconds + result->bake_seconds);
        measured[k].rays = result->shadow_rays;
      }
    }
    for (std::size_t k = 0; k < vs.size(); ++k) {
      measured[k].scene_seconds = median(measured[k].scene_runs);
      measured[k].peak_mib = process_peak_mib(file.string(), vs[k], resolution);
    }

    fmt::print("\n## {} ({}², truth: reference-{})\n\n", name, resolution, truth_samples);
    fmt::print("| variant | scene s | peak MiB |");
    for (const auto& r : receivers) fmt::print(" {} s | {} RMSE |", r, r);
    fmt::print("\n|---|---|---|");
    for (std::size_t i = 0; i < receivers.size(); ++i) fmt::print("---|---|");
    fmt::print("\n");
    nlohmann::ordered_json entry;
    entry["scene"] = name;
    entry["resolution"] = resolution;
    entry["truth_samples"] = truth_samples;
    for (std::size_t k = 0; k < vs.size(); ++k) {
      fmt::print("| {} | {:.3f} | {:.0f} |", vs[k].label, measured[k].scene_seconds,
                 measured[k].peak_mib);
      auto& j = entry["variants"][vs[k].label];
      j["scene_seconds"] = measured[k].scene_seconds;
      j["peak_mib"] = measured[k].peak_mib;
      for (const auto& r : receivers) {
        const double t = median(measured[k].seconds[r]);
        fmt::print(" {:.3f} | {:.4f} |", t, measured[k].error[r]);
        j["receivers"][r] = {{"seconds", t}, {"rmse", measured[k].error[r]}};
      }
      fmt::print("\n");
    }
    // Equal error, per receiver.
    fmt::print("\nTime to RMSE {} (s) and the ratio reference / convolution:\n\n", target);
    fmt::print("| receiver | reference | convolution | ratio |\n|---|---|---|---|\n");
    for (const auto& r : receivers) {
      std::map<std::string, std::vector<std::pair<double, double>>> curves;
      for (std::size_t k = 0; k < vs.size(); ++k)
        curves[vs[k].family].emplace_back(median(measured[k].seconds[r]), measured[k].error[r]);
      bool ex_ref = false, ex_conv = false;
      const auto t_ref = time_at(curves["reference"], target, &ex_ref);
      const auto t_conv = time_at(curves["convolution"], target, &ex_conv);
      const auto show = [](const std::optional<double>& t, bool ex) {
        return t ? fmt::format("{}{:.3f}", ex ? "~" : "", *t) : std::string("-");
      };
      const std::string ratio =
          t_ref && t_conv ? fmt::format("{}{:.2f}", ex_ref || ex_conv ? "~" : "", *t_ref / *t_conv)
                          : std::string("-");
      fmt::print("| {} | {} | {} | {} |\n", r, show(t_ref, ex_ref), show(t_conv, ex_conv), ratio);
      entry["equal_error"][r] = {
          {"reference_seconds", t_ref ? nlohmann::ordered_json(*t_ref) : nlohmann::ordered_json()},
          {"convolution_seconds",
           t_conv ? nlohmann::ordered_json(*t_conv) : nlohmann::ordered_json()},
          {"extrapolated", ex_ref || ex_conv}};
    }
    report.push_back(entry);
    std::fflush(stdout);
  }
  if (!json_path.empty()) std::ofstream(json_path) << report.dump(1) << "\n";
  return 0;
}
