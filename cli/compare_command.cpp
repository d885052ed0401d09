// `shadowbake compare`: error metrics of a texture against a reference, a table, compare.json and
// a difference heat map, and gates for pipelines (docs/reports.md).
#include <fmt/core.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "commands.h"
#include "core/image_io.h"
#include "evaluation/image_metrics.h"
#include "evaluation/metrics_json.h"
#include "formats/output_folder.h"

namespace sbcli {

namespace {

namespace fs = std::filesystem;

struct CompareArgs {
  std::string a, reference, mask, out_dir, penumbra;
  std::vector<std::string> gates;
  double peak = 1.0;
};

// A --fail-above METRIC=VALUE: fails when the metric is above VALUE, or below it for the
// "higher is better" metrics ssim and psnr.
struct Gate {
  std::string metric;
  double threshold = 0;
  bool fail_below = false;
};

const char* const kGateMetrics =
    "rmse, mae, max, penumbra_rmse, penumbra_mae, penumbra_max (fail above), ssim, psnr (fail "
    "below)";

std::optional<Gate> parse_gate(const std::string& text) {
  const auto equals = text.find('=');
  if (equals == std::string::npos) return std::nullopt;
  Gate gate;
  gate.metric = text.substr(0, equals);
  const std::string value = text.substr(equals + 1);
  const bool known = gate.metric == "rmse" || gate.metric == "mae" || gate.metric == "max" ||
                     gate.metric == "penumbra_rmse" || gate.metric == "penumbra_mae" ||
                     gate.metric == "penumbra_max" || gate.metric == "ssim" ||
                     gate.metric == "psnr";
  if (!known || value.empty()) return std::nullopt;
  std::size_t used = 0;
  try {
    gate.threshold = std::stod(value, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != value.size() || !std::isfinite(gate.threshold)) return std::nullopt;
  gate.fail_below = gate.metric == "ssim" || gate.metric == "psnr";
  return gate;
}

double gate_value(const Gate& gate, const sb::Comparison& c) {
  if (gate.metric == "rmse") return c.covered.overall.rmse;
  if (gate.metric == "mae") return c.covered.overall.mae;
  if (gate.metric == "max") return c.covered.overall.max_abs;
  if (gate.metric == "penumbra_rmse") return c.penumbra.overall.rmse;
  if (gate.metric == "penumbra_mae") return c.penumbra.overall.mae;
  if (gate.metric == "penumbra_max") return c.penumbra.overall.max_abs;
  if (gate.metric == "ssim") return c.covered.overall.ssim;
  return c.covered.overall.psnr;
}

int usage_error(const std::string& message) {
  std::fprintf(stderr, "shadowbake: error: %s\n", message.c_str());
  return usage;
}

// The mask image's first channel above one half: counts.
std::vector<std::uint8_t> mask_of(const sb::Image& image) {
  std::vector<std::uint8_t> mask(std::size_t(image.width) * image.height);
  for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = image.pixels[i * image.channels] > 0.5f;
  return mask;
}

std::string number(double v) {
  if (std::isnan(v)) return "-";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return fmt::format("{:.6g}", v);
}

void print_row(const std::string& label, std::int64_t texels, const sb::ChannelErrors& e) {
  const std::string where =
      e.max_x < 0 ? "" : fmt::format("({},{},{})", e.max_x, e.max_y, e.max_channel);
  fmt::print("{:<12} {:>9} {:>11} {:>11} {:>11} {:<16} {:>9} {:>9}\n", label, texels,
             number(e.rmse), number(e.mae), number(e.max_abs), where,
             std::isfinite(e.psnr) ? fmt::format("{:.2f}", e.psnr) : number(e.psnr),
             std::isnan(e.ssim) ? "-" : fmt::format("{:.5f}", e.ssim));
}

void print_table(const sb::Comparison& c) {
  fmt::print("{:<12} {:>9} {:>11} {:>11} {:>11} {:<16} {:>9} {:>9}\n", "region", "texels", "RMSE",
             "MAE", "max", "at (x,y,ch)", "PSNR dB", "SSIM");
  for (int region = 0; region < 2; ++region) {
    const sb::RegionErrors& r = region == 0 ? c.covered : c.penumbra;
    print_row(region == 0 ? "covered" : "penumbra", r.texels, r.overall);
    if (c.channels > 1) {
      for (int ch = 0; ch < c.channels; ++ch)
        print_row(fmt::format("  channel {}", ch), r.texels, r.channels[ch]);
    }
  }
}

void warn_non_finite(const std::string& file, std::int64_t texels) {
  if (texels == 0) return;
  std::fprintf(
      stderr, "shadowbake: warning: %s: %lld %s NaN or infinity; left out of the metrics\n",
      file.c_str(), static_cast<long long>(texels), texels == 1 ? "texel holds" : "texels hold");
}

// Reads the --fail-above gates, --peak and --penumbra into `gates` and `options`; `ok`, or the
// usage error's exit code.
int read_gates_and_options(const CompareArgs& args, std::vector<Gate>& gates,
                           sb::CompareOptions& options) {
  for (const auto& text : args.gates) {
    auto gate = parse_gate(text);
    if (!gate) {
      return usage_error("--fail-above " + text + ": expected METRIC=VALUE with METRIC one of " +
                         kGateMetrics);
    }
    gates.push_back(*gate);
  }
  if (!(args.peak >= 0) || !std::isfinite(args.peak)) {
    return usage_error(
        fmt::format("--peak {}: expected a value ≥ 0 (0: the reference's largest)", args.peak));
  }
  options.peak = args.peak;
  if (!args.penumbra.empty()) {
    double lo = 0, hi = 0;
    char extra = 0;
    if (std::sscanf(args.penumbra.c_str(), "%lf,%lf%c", &lo, &hi, &extra) != 2 || !(lo < hi)) {
      return usage_error("--penumbra " + args.penumbra + ": expected LO,HI with LO < HI");
    }
    options.penumbra_lo = lo;
    options.penumbra_hi = hi;
  }
  return ok;
}

// Which mask counts texels, and where it came from ("option", "beside reference" or "none").
struct MaskChoice {
  fs::path path;
  std::string source;
};

// The mask: given, or the bake's coverage beside the reference, or none (every texel).
MaskChoice choose_mask(const CompareArgs& args) {
  fs::path mask_path = args.mask;
  std::string mask_source = "option";
  if (mask_path.empty()) {
    const fs::path beside = fs::path(args.reference).parent_path() /
                            (fs::path(args.reference).stem().string() + ".coverage.png");
    std::error_code ec;
    if (fs::exists(beside, ec)) {
      mask_path = beside;
      mask_source = "beside reference";
      fmt::print("mask: {} (found beside the reference; --mask chooses another)\n",
                 beside.string());
    } else {
      mask_source = "none";
    }
  }
  return {mask_path, mask_source};
}

// Judges each gate on the comparison, appending its result to `gate_results`; the failures, one
// line each.
std::vector<std::string> check_gates(const std::vector<Gate>& gates, const sb::Comparison& c,
                                     const std::string& a_file,
                                     nlohmann::ordered_json& gate_results) {
  std::vector<std::string> failures;
  for (const auto& gate : gates) {
    const double value = gate_value(gate, c);
    // A gate that has nothing to judge, or an image with texels that are not numbers, fails:
    // a pipeline must not pass a bake it could not measure.
    const bool unmeasured = std::isnan(value);
    const bool broken = c.non_finite_a > 0;
    const bool failed =
        unmeasured || broken || (gate.fail_below ? value < gate.threshold : value > gate.threshold);
    if (unmeasured) {
      failures.push_back(
          fmt::format("{}: no texels to judge (none covered, or none finite)", gate.metric));
    } else if (broken) {
      failures.push_back(fmt::format("{}: {} has {} non-finite texel value(s)", gate.metric, a_file,
                                     c.non_finite_a));
    } else if (failed) {
      failures.push_back(fmt::format("{} = {} {} {}", gate.metric, number(value),
                                     gate.fail_below ? "<" : ">", number(gate.threshold)));
    }
    gate_results.push_back({{"metric", gate.metric},
                            {"threshold", gate.threshold},
                            {"fails", gate.fail_below ? "below" : "above"},
                            {"value", sb::json_number(value)},
                            {"passed", !failed}});
  }
  return failures;
}

// Writes difference.png and compare.json into --output; `ok`, or the error's exit code.
int write_compare_outputs(const CompareArgs& args, const sb::Image& a, const sb::Image& reference,
                          const sb::CompareOptions& options, const MaskChoice& mask,
                          const sb::Comparison& c, const nlohmann::ordered_json& gate_results) {
  const fs::path& mask_path = mask.path;
  auto folder = sb::OutputFolder::open(args.out_dir);
  if (!folder) return fail(folder.error());
  const double scale = sb::heat_map_scale(a, reference, options.mask);
  const sb::Image heat = sb::difference_heat_map(a, reference, options.mask, scale, true);

  nlohmann::ordered_json j;
  j["a"] = {{"path", args.a}, {"width", a.width}, {"height", a.height}, {"channels", a.channels}};
  j["reference"] = {{"path", args.reference},
                    {"width", reference.width},
                    {"height", reference.height},
                    {"channels", reference.channels}};
  j["mask"] = {{"source", mask.source},
               {"path", mask_path.empty() ? nlohmann::ordered_json(nullptr)
                                          : nlohmann::ordered_json(mask_path.string())}};
  j["peak"] = c.peak;
  j["penumbra_range"] = {options.penumbra_lo, options.penumbra_hi};
  j["non_finite"] = {{"a", c.non_finite_a}, {"reference", c.non_finite_reference}};
  j["covered"] = sb::to_json(c.covered);
  j["penumbra"] = sb::to_json(c.penumbra);
  j["heat_map"] = {{"file", "difference.png"}, {"scale", scale}};
  j["gates"] = gate_results;

  if (auto s = sb::write_image(folder->staged("difference.png"), heat, sb::PixelFormat::uint8); !s)
    return fail(s.error());
  if (auto s = sb::write_text_file(folder->staged("compare.json"), j.dump(2) + "\n"); !s)
    return fail(s.error());
  auto published = folder->publish({"difference.png", "compare.json"});
  reraise_pending_interrupt();
  if (!published) return fail(published.error());
  return ok;
}

int run_compare(const CompareArgs& args) {
  std::vector<Gate> gates;
  sb::CompareOptions options;
  if (int code = read_gates_and_options(args, gates, options); code != ok) return code;

  auto a = sb::read_image(args.a);
  if (!a) return fail(a.error());
  auto reference = sb::read_image(args.reference);
  if (!reference) return fail(reference.error());

  const MaskChoice mask = choose_mask(args);
  const fs::path& mask_path = mask.path;
  if (!mask_path.empty()) {
    auto mask_image = sb::read_image(mask_path);
    if (!mask_image) return fail(mask_image.error());
    if (mask_image->width != reference->width || mask_image->height != reference->height) {
      return fail(sb::input_error(fmt::format(
          "{}: the mask is {}×{}, but {} and {} are {}×{}", mask_path.string(), mask_image->width,
          mask_image->height, args.a, args.reference, reference->width, reference->height)));
    }
    options.mask = mask_of(*mask_image);
  }

  auto comparison = sb::compare_images(*a, *reference, options, args.a, args.reference);
  if (!comparison) return fail(comparison.error());
  const sb::Comparison& c = *comparison;
  warn_non_finite(args.a, c.non_finite_a);
  warn_non_finite(args.reference, c.non_finite_reference);

  fmt::print("{} against {} (reference): {}×{}, {} channel(s), PSNR peak {}\n", args.a,
             args.reference, c.width, c.height, c.channels, number(c.peak));
  print_table(c);

  // Gates, checked after the outputs are written so that a failing run can be inspected.
  nlohmann::ordered_json gate_results = nlohmann::ordered_json::array();
  const std::vector<std::string> failures = check_gates(gates, c, args.a, gate_results);

  if (!args.out_dir.empty()) {
    const int written = write_compare_outputs(args, *a, *reference, options, mask, c, gate_results);
    if (written != ok) return written;
  }

  for (const auto& f : failures) std::fprintf(stderr, "shadowbake: gate failed: %s\n", f.c_str());
  return failures.empty() ? ok : gate_failed;
}

}  // namespace

Runner add_compare_command(CLI::App& app) {
  auto args = std::make_shared<CompareArgs>();
  auto* compare = app.add_subcommand(
      "compare", "error metrics of image A against the reference B, and a difference heat map");
  compare->add_option("a", args->a, "the image to measure (any OIIO-readable image)")->required();
  compare->add_option("reference", args->reference, "the reference image, same size and channels")
      ->required();
  compare->add_option("--mask", args->mask,
                      "texels to count: the image's first channel > 0.5 (default: "
                      "<reference stem>.coverage.png beside the reference if present, else all)");
  compare->add_option("-o,--output", args->out_dir,
                      "write compare.json and difference.png here (created if missing)");
  compare
      ->add_option("--fail-above", args->gates,
                   "METRIC=VALUE, repeatable: exit 5 when rmse, mae, max, penumbra_rmse, "
                   "penumbra_mae or penumbra_max is above VALUE, or ssim or psnr below it")
      ->allow_extra_args(false);
  compare->add_option("--penumbra", args->penumbra,
                      "LO,HI: the penumbra is where any channel of the reference is strictly "
                      "between them (default 0.02,0.98)");
  compare->add_option("--peak", args->peak,
                      "PSNR peak and SSIM dynamic range (default 1; 0: the reference's largest "
                      "covered value)");
  return [args]() { return run_compare(*args); };
}

}  // namespace sbcli
