// The `convolution` method's entry in the registry (traced_convolution.h): its settings, what it
// needs built, and what it reports per receiver — the shares of clear, convolved and traced
// pairs, its penumbra error per light and frustum (the manifest's `penumbra_error` and
// `lights`), and the plan and choices --explain prints.
#include <fmt/format.h>

#include <algorithm>

#include "methods/convolution/fft_convolution.h"
#include "methods/convolution/traced_convolution.h"

namespace sb {

namespace {

// The convolution's arrays per receiver texel: the planner's frames (add_frames: tangents,
// depths, groups and indices of a light part's whole and halves at once; heaptrack measured 755 MB
// at peak for the 4.2 M texels of a floor at 2048², 180 B per texel), and while a frame is
// convolved its occlusion, largest, Euler's counts and weight gradient (about 90 B, of frames'
// texels that are the receiver's); and per light part the texel's V (12) and whether it is
// reached (1).
constexpr double kConvolutionBytesPerTexel = 180 + 90;
constexpr double kConvolutionBytesPerTexelAndLightPart = 12 + 1;

nlohmann::ordered_json pair_json(const PairReport& p) {
  return {
      {"light", p.light},
      {"frustum", p.part.empty() ? "central" : p.part},
      {"direction", {p.axis[0], p.axis[1], p.axis[2]}},
      {"blocker_plane", p.blocker_plane},
      {"receiver_plane", p.receiver_plane},
      {"blocker_depths", {p.blocker_depth_lo, p.blocker_depth_hi}},
      {"receiver_depths", {p.receiver_depth_lo, p.receiver_depth_hi}},
      {"rho", {p.rho_lo, p.rho, p.rho_hi}},
      {"penumbra_error", {{"metres", p.penumbra_error}, {"texels", p.penumbra_error_texels}}},
      {"blocker_image", {p.image_width, p.image_height}},
      {"kernel", {p.kernel_width, p.kernel_height}},
      {"fft", {p.fft_width, p.fft_height}},
      {"lit_texels", p.lit_texels},
      {"unprojected_texels", p.outside_texels},
      {"seconds",
       {{"configure", p.seconds_configure},
        {"source", p.seconds_source},
        {"blocker", p.seconds_blocker},
        {"fft", p.seconds_fft},
        {"lookup", p.seconds_lookup}}},
  };
}

std::string pair_text(const PairReport& p) {
  std::string s = fmt::format("{} <- {}{}{}: D = ({:.3f}, {:.3f}, {:.3f}), {} lit texels",
                              p.receiver, p.light, p.part.empty() ? "" : " face ", p.part,
                              p.axis[0], p.axis[1], p.axis[2], p.lit_texels);
  if (p.outside_texels > 0)
    s += fmt::format(" ({} beside the light, left unshadowed)", p.outside_texels);
  s += "\n";
  if (p.image_width == 0) return s + "    no blocker between the light and the receiver\n";
  s += fmt::format(
      "    planes along D: source 0, blocker {:.3f} m (blockers {:.3f}..{:.3f}), receiver "
      "{:.3f} m (receiver {:.3f}..{:.3f})\n",
      p.blocker_plane, p.blocker_depth_lo, p.blocker_depth_hi, p.receiver_plane,
      p.receiver_depth_lo, p.receiver_depth_hi);
  s += fmt::format(
      "    penumbra error: rho {:.3f} in [{:.3f}, {:.3f}], L = {:.3f} m -> {:.4f} m = {:.1f} "
      "texels\n",
      p.rho, p.rho_lo, p.rho_hi, p.light_extent, p.penumbra_error, p.penumbra_error_texels);
  s += fmt::format("    images: blocker {}x{}, kernel {}x{}, FFT {}x{}, {} convolution(s)\n",
                   p.image_width, p.image_height, p.kernel_width, p.kernel_height, p.fft_width,
                   p.fft_height, p.convolutions);
  s += fmt::format(
      "    time: configure {:.1f} ms; summed over threads: source {:.1f} ms, blocker {:.1f} ms, "
      "FFT {:.1f} ms, lookup {:.1f} ms\n",
      1e3 * p.seconds_configure, 1e3 * p.seconds_source, 1e3 * p.seconds_blocker,
      1e3 * p.seconds_fft, 1e3 * p.seconds_lookup);
  return s;
}

}  // namespace

ConvolutionSettings convolution_settings(const BakeSettings& bake) {
  ConvolutionSettings s;
  s.quantity = bake.quantity;
  s.error_texels = setting_number(bake, "error_texels");
  s.max_image = int(setting_whole(bake, "max_image"));
  s.max_triples = int(setting_whole(bake, "max_triples"));
  s.light_parts = int(setting_whole(bake, "light_parts"));
  s.combine = setting_word(bake, "blocker_combine") == "sum" ? BlockerCombine::sum
                                                             : BlockerCombine::product;
  s.weighted = setting_word(bake, "weighting") == "irradiance";
  s.convolve = setting_flag(bake, "convolve");
  s.trace_error_texels = setting_number(bake, "trace_error_texels");
  s.samples = bake.samples;
  s.seed = bake.seed;
  return s;
}

PlanInputs plan_inputs(const BakeContext& context, const ConvolutionSettings& settings,
                       const Mesh* receiver, const ConvolutionBackend* backend) {
  PlanInputs in;
  in.lights = context.lights;
  in.receiver = receiver;
  in.blockers = context.blockers;
  in.clusters = context.clusters;
  in.error_texels = settings.error_texels;
  in.max_image = settings.max_image;
  in.max_triples = settings.max_triples;
  in.light_parts = settings.light_parts;
  in.backend = backend;
  return in;
}

namespace {

class ConvolutionMethod final : public Method {
 public:
  explicit ConvolutionMethod(const BakeContext& context)
      : context_(context), settings_(convolution_settings(context.scene->bake)) {
    fft_.set_threads(std::max(1, context.threads));
  }

  Expected<MethodResult> bake(const ReceiverInput& receiver) override {
    const ConvolutionSettings& settings = settings_;
    ConvolutionInputs in;
    in.plan = plan_inputs(context_, settings, receiver.mesh, &fft_);
    in.quantity = settings.quantity;
    in.combine = settings.combine;
    in.weighted = settings.weighted;
    in.memory_for_images = context_.memory_for_images;
    in.fft = &fft_;
    TracedConvolutionInputs traced;
    traced.convolution = in;
    traced.culler = context_.shafts;
    traced.rays = context_.rays;
    traced.convolve = settings.convolve;
    traced.samples = settings.samples;
    traced.trace_error_texels = settings.trace_error_texels;
    traced.seed = settings.seed;
    traced.stream = receiver.stream;
    traced.keep_per_light = context_.keep_per_light;
    ConvolutionPlan plan;
    TracedConvolutionStats stats;
    std::vector<PairReport> pairs;
    auto images = bake_traced_convolution(*receiver.space, traced, &pairs, &plan, &stats);
    if (!images) {
      return scene_error(context_.scene->file.string() + ":" +
                         std::to_string(receiver.object->line) + ": " + images.error().message);
    }
    MethodResult result;
    result.images = std::move(*images);
    result.rays = stats.rays;
    MethodReport& report = result.report;
    const double all = std::max<double>(1.0, double(stats.pairs));
    report.stats.emplace_back("clear_fraction", double(stats.clear) / all);
    report.stats.emplace_back("convolved_fraction", double(stats.convolved) / all);
    report.stats.emplace_back("traced_fraction", double(stats.traced) / all);
    report.stats.emplace_back(
        "rays_per_texel",
        double(stats.rays) / std::max<double>(1.0, double(receiver.space->texels.size())));
    report.explain = describe_plan(plan);
    for (const auto& w : plan.warnings)
      report.warnings.push_back(context_.scene->file.string() + ": " + w);
    if (!pairs.empty()) {
      double worst = 0, worst_texels = 0;
      for (const auto& p : pairs) {
        worst = std::max(worst, p.penumbra_error);
        worst_texels = std::max(worst_texels, p.penumbra_error_texels);
      }
      report.manifest["penumbra_error"] = {{"metres", worst}, {"texels", worst_texels}};
      report.manifest["lights"] = nlohmann::ordered_json::array();
      for (const auto& p : pairs) {
        report.manifest["lights"].push_back(pair_json(p));
        report.explain += pair_text(p);
      }
    }
    report.details = std::move(pairs);
    return result;
  }

 private:
  BakeContext context_;
  ConvolutionSettings settings_;
  FftConvolver fft_;  // this bake's transforms: plans made once per size, kernel spectra cached
};

}  // namespace

MethodEntry convolution_method() {
  const PlanInputs plan;
  const TracedConvolutionInputs traced;
  MethodEntry e;
  e.name = "convolution";
  e.settings = {"samples", "seed"};
  e.own_settings = {number_setting("error_texels", plan.error_texels, "a number > 0",
                                   [](double x) { return x > 0; }),
                    whole_setting("max_image", plan.max_image, 64, 16384),
                    whole_setting("max_triples", plan.max_triples, 1, 1 << 20),
                    whole_setting("light_parts", plan.light_parts, 1, 4, "1, 2 or 4",
                                  [](std::int64_t parts) { return parts != 3; }),
                    flag_setting("trace", true),
                    flag_setting("convolve", traced.convolve),
                    number_setting("trace_error_texels", traced.trace_error_texels, "a number >= 0",
                                   [](double x) { return x >= 0; }),
                    word_setting("blocker_combine", "sum", {"product", "sum"}),
                    word_setting("weighting", "irradiance", {"irradiance", "emission"})};
  // The switches the manifest records, for a reader to tell a convolution without rays.
  e.manifest_settings = {"trace", "convolve"};
  e.needs = [](const BakeSettings& s) {
    // The planner's clusters serve the convolution (and the buried-texel test); with
    // convolve = false and rays, no leaf is planned.
    const bool trace = setting_flag(s, "trace"), convolve = setting_flag(s, "convolve");
    return MethodNeeds{.rays = trace, .clusters = convolve || !trace, .shafts = true};
  };
  e.memory = [](const Scene& scene, double texels) {
    // Parts of a light: at least light_parts; a sphere light's receiver may be seen through up
    // to six cube faces, each a frame of its own.
    const double parts = double(scene.lights.size()) *
                         std::max<double>(double(setting_whole(scene.bake, "light_parts")), 1);
    return std::vector<MemoryItem>{
        {"convolution texel arrays",
         texels * (kConvolutionBytesPerTexel + kConvolutionBytesPerTexelAndLightPart * parts)}};
  };
  e.make = [](const BakeContext& context) -> Expected<std::unique_ptr<Method>> {
    const BakeSettings& s = context.scene->bake;
    if (!setting_flag(s, "convolve") && !setting_flag(s, "trace"))
      return scene_error(context.scene->file.string() +
                         ": [bake]: convolve = false needs trace = true (with neither, nothing "
                         "would compute the shadows)");
    return std::unique_ptr<Method>(std::make_unique<ConvolutionMethod>(context));
  };
  e.tile_halo = -1;  // its images span the receiver
  e.local = false;   // its clusters span the scene's blockers
  e.plan = [](const BakeContext& context, const ReceiverInput& receiver) -> Expected<std::string> {
    const FftConvolver fft;
    return describe_plan(plan_convolution(
        *receiver.space,
        plan_inputs(context, convolution_settings(context.scene->bake), receiver.mesh, &fft)));
  };
  return e;
}

}  // namespace sb
