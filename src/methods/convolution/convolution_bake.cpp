// Soft shadow textures by convolution (Soler & Sillion, "Fast Calculation of Soft Shadow Textures
// Using Convolution", SIGGRAPH 1998; docs/design.md [S1]; the mathematics in
// docs/design.md §2–4).
//
// For each receiver, plan_convolution (convolution_plan.cpp) chooses the hierarchy of (light part,
// blocker cluster, receiver part) triples. Each leaf triple renders its source kernel
// (source_image) and blocker image (blocker_image) on one grid of its frustum's tangent plane,
// convolves them by FFT (fft_convolution) to get the occluded fraction O, and gives each texel
// of its footprint O read bilinearly at the texel's central projection through the light part's
// centre. That projection makes hard-shadow positions exact for the light's centre whatever the
// geometry; only penumbra widths are approximate, by at most the penumbra error ε reported.
// A leaf whose blockers fall into islands far apart (a table's legs in one slab) is convolved on
// a window per island (leaf_windows): the same values, by linearity, for far fewer pixels.
//
// Combining leaves at a texel: a receiver split's two parts are blended by their cut weights (a
// partition of unity across the seam); a slab's shadow counts in proportion to the part of its
// geometry in front of the texel; blocker clusters combine by BlockerCombine, which becomes a
// weighted sum S = Σ w·f(O) with f(O) = O, V = 1 − min(S, 1) (sum) or f(O) = −ln(1 − O),
// V = exp(−S) (product). Light parts add weighted by their own unoccluded irradiance at the texel
// (by their share of the power with `weighting = "emission"`).
//
// With `sum`, each cluster's image is its share of the nearest layer (nearest_layer_coverage),
// so the shares partition the hard shadow seen from the light's centre. A cluster hidden behind
// another there still hides light from other points of the light: a bracket's base lies under
// the shadow of its own wall, yet the floor beneath the base is dark whatever the wall does. So
// the occluded fraction is at least each cluster's own, from its whole image:
// O = max(Σ O_share, max O_whole) (a union is at least as large as any of its sets). The
// second convolution is skipped for clusters that nothing hides.
//
// Neither holds the light that a thick solid hides from off-centre light points only: rays that
// enter a post through a side the light's centre does not see. For a convex closed solid
// (add_sections) the plan keeps its slabs together: each slab's whole image is capped by the
// solid's section at its near depth (the solid slab's projection, not the ring of its faces), and
// a section leaf sits at every depth between two slabs. A line from the texel to a light point
// meets a convex solid in one interval, which touches k consecutive slabs and crosses the k − 1
// sections between them inside the solid, so Σ whole slabs − Σ sections (Euler's count) is the
// fraction of the light the solid hides, E; O = max(Σ O_share, max O_whole, max E). Each term
// is convolved at its own plane: sections exactly, slabs within their penumbra error.
//
// V is the irradiance-weighted visibility of the reference to first order across the light
// (docs/design.md §6): the weight cos·cos/distance² of the light's points seen from a texel is
// expanded about the centre, and the kernel's two first moments, convolved with the same image,
// give the correction (two more convolutions per leaf; ConvolutionInputs::weighted). Without it
// V is the emission-weighted V_u of docs/design.md §1.
#include "methods/convolution/convolution_bake.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "core/memory_size.h"
#include "core/stopwatch.h"
#include "methods/convolution/buried_texels.h"
#include "methods/convolution/convolution_plan.h"
#include "methods/convolution/leaf_convolution.h"
#include "methods/convolution/texel_accumulation.h"

namespace sb {

namespace {

using Clock = std::chrono::steady_clock;

// Transform pixels of the leaves convolved together before their images are added in (about
// 5 images of 4 bytes each per pixel: 64 MiB).
constexpr std::size_t kBatchPixels = std::size_t(1) << 22;

// Bytes per transform pixel of a leaf being convolved: its blocker images (share and whole, 8),
// its results (3 colour channels and 2 moments, for the share and the whole: 40), FFTW's padded
// input and spectrum (12) and the cached kernel spectra (5 kernels of half a spectrum: 20),
// rounded up for the allocator.
constexpr double kBytesPerTransformPixel = 96;

// How far outside a solid's face plane a texel may lie and still count as buried in it, in
// receiver texels: a floor texel under a box's bottom face lies on that plane up to rounding.
constexpr double kBuriedTolerance = 1e-3;

}  // namespace

double convolution_images_bytes(const ConvolutionPlan& plan) {
  // The batches of bake_convolution: leaves together up to kBatchPixels, a larger one alone.
  double largest_leaf = 0, all = 0;
  for (const Triple& tr : plan.triples) {
    if (!tr.children.empty() || tr.empty || tr.traced) continue;
    const double pixels = double(tr.fft_width) * double(tr.fft_height);
    largest_leaf = std::max(largest_leaf, pixels);
    all += pixels;
  }
  return std::max(largest_leaf, std::min(all, double(kBatchPixels))) * kBytesPerTransformPixel;
}

namespace {

// Per light part (or per light) and texel: V, whether one of its frames reaches the texel, and
// the worst penumbra error there (the three tables of ConvolutionVisibility).
struct TexelTables {
  std::vector<std::vector<Vec3f>> visible;
  std::vector<std::vector<std::uint8_t>> reached;
  std::vector<std::vector<float>> error;

  explicit TexelTables(std::size_t count) : visible(count), reached(count), error(count) {}
};

// The error that refuses a plan whose images need `needed` bytes, more than the memory left
// them; it names the plan's largest transform.
Error image_memory_error(const ConvolutionPlan& plan, const ConvolutionInputs& in, double needed) {
  int widest = 0, tallest = 0;
  for (const Triple& tr : plan.triples) {
    if (!tr.children.empty() || tr.empty) continue;
    if (double(tr.fft_width) * tr.fft_height > double(widest) * tallest) {
      widest = tr.fft_width;
      tallest = tr.fft_height;
    }
  }
  return scene_error(
      fmt::format("receiver '{}': the convolution's images need about {} (its largest transform is "
                  "{}x{}), more than the {} max_memory leaves them; lower 'max_image' or raise "
                  "'error_texels' or max_memory",
                  in.plan.receiver->name, format_bytes(needed), widest, tallest,
                  format_bytes(in.memory_for_images)));
}

// A frame's report before its leaves are added: its light part, receiver face, axes and texels.
PairReport frame_report(const ConvolutionInputs& in, const PlanFrame& fr, const LightPart& lp,
                        std::size_t f, double plan_seconds) {
  PairReport report;
  report.light = lp.name;
  report.receiver = in.plan.receiver->name;
  report.part = to_string(fr.face);
  for (int k = 0; k < 3; ++k) report.axis[k] = fr.frame.axis[k];
  report.lit_texels = std::int64_t(fr.texels.size());
  report.outside_texels = fr.outside_texels;
  report.seconds_configure = f == 0 ? plan_seconds : 0;
  return report;
}

// The bake of one frame: its leaves convolved a batch at a time and added into the occluded
// fractions of the frame's texels, which then give the V of its light part there.
struct FrameBake {
  const TexelSpace& space;
  const ConvolutionInputs& in;
  ConvolutionPlan& plan;
  const std::size_t f;
  const PlanFrame& fr;
  const LightPart& lp;
  PairReport report;
  std::vector<Vec3f> occlusion;
  std::vector<Vec3f> largest;
  // Negative until a leaf shades the texel: see ConvolutionVisibility::error_texels.
  std::vector<float> error;
  EulerCounts euler;
  const std::vector<Vec2> gradient;
  DepthRange blockers, receivers;

  FrameBake(const TexelSpace& texel_space, const ConvolutionInputs& inputs,
            ConvolutionPlan& convolution_plan, std::size_t frame, double plan_seconds)
      : space(texel_space),
        in(inputs),
        plan(convolution_plan),
        f(frame),
        fr(plan.frames[f]),
        lp(plan.light_parts[fr.light_part]),
        report(frame_report(in, fr, lp, f, plan_seconds)),
        occlusion(fr.texels.size(), Vec3f::Zero()),
        largest(fr.texels.size(), Vec3f::Zero()),
        error(fr.texels.size(), -1.0f),
        euler(in.combine == BlockerCombine::sum ? fr.texels.size() : 0),
        gradient(in.weighted ? weight_gradients(fr, space, lp.part) : std::vector<Vec2>{}) {}

  // Convolves the frame's leaves and stores the V they give in its light part's tables.
  void run(TexelTables& parts) {
    const std::vector<std::size_t> leaves = collect_leaves();
    // Leaves are convolved in parallel, a batch at a time (their images held until added), with
    // one FFTW thread each: on 2 cores two threads slow a transform below ~400² down
    // (tests/bench/fft_bench.cpp). A larger leaf is convolved alone, with FFTW's threads.
    // Adding into the texels stays in leaf order, so the result does not depend on scheduling.
    for (std::size_t first = 0; first < leaves.size();) {
      const std::size_t last = batch_end(leaves, first);
      add_batch(leaves, first, last);
      first = last;
    }
    euler.begin(-1);  // folds the last solid's count
    if (!blockers.empty()) {
      report.blocker_depth_lo = blockers.lo;
      report.blocker_depth_hi = blockers.hi;
      report.receiver_depth_lo = receivers.lo;
      report.receiver_depth_hi = receivers.hi;
    }
    store(parts);
  }

  // The frame's leaves to convolve, each convex solid's together; a traced leaf only marks the
  // texels it reaches in `error`.
  std::vector<std::size_t> collect_leaves() {
    std::vector<std::size_t> leaves;
    for (std::size_t t = 0; t < plan.triples.size(); ++t) {
      const Triple& tr = plan.triples[t];
      // Sections count only in the sum's Euler counts.
      if (tr.section && in.combine != BlockerCombine::sum) continue;
      if (tr.frame != int(f) || !tr.children.empty() || tr.empty) continue;
      if (tr.traced) {
        mark_traced(plan, tr, error);
      } else {
        leaves.push_back(t);
      }
    }
    // Each convex solid's leaves together, so that one count at a time is held.
    std::stable_sort(leaves.begin(), leaves.end(), [&](std::size_t a, std::size_t b) {
      return plan.triples[a].euler < plan.triples[b].euler;
    });
    return leaves;
  }

  // The end of the batch that starts at leaves[first]: leaves up to kBatchPixels together, or
  // one leaf alone if its transform is threaded.
  std::size_t batch_end(const std::vector<std::size_t>& leaves, std::size_t first) const {
    std::size_t last = first;
    std::size_t pixels = 0;
    while (last < leaves.size()) {
      const Triple& tr = plan.triples[leaves[last]];
      const std::size_t area = std::size_t(tr.fft_width) * std::size_t(tr.fft_height);
      if (last > first &&
          (in.fft->threaded(tr.fft_width, tr.fft_height) || pixels + area > kBatchPixels))
        break;
      pixels += area;
      ++last;
      if (in.fft->threaded(tr.fft_width, tr.fft_height)) break;
    }
    return last;
  }

  // Convolves leaves[first, last) in parallel, then adds their images in leaf order.
  void add_batch(const std::vector<std::size_t>& leaves, std::size_t first, std::size_t last) {
    std::vector<LeafImages> images(last - first);
    std::vector<double> seconds(last - first, 0.0);
    tbb::parallel_for(std::size_t(first), last, [&](std::size_t b) {
      const auto leaf_start = Clock::now();
      images[b - first] = convolve_leaf(plan, plan.triples[leaves[b]], in.combine, in.weighted,
                                        in.island_windows, *in.fft);
      seconds[b - first] = seconds_since(leaf_start);
    });
    for (std::size_t b = first; b < last; ++b)
      add_leaf(plan.triples[leaves[b]], images[b - first], seconds[b - first]);
  }

  // Adds one convolved leaf into the frame's texels and its report, then frees its images.
  void add_leaf(Triple& tr, LeafImages& images, double seconds) {
    const auto leaf_start = Clock::now();
    const bool counted = tr.euler >= 0 && in.combine == BlockerCombine::sum;
    if (counted) euler.begin(tr.euler);
    accumulate_leaf(plan, tr, images, in.combine, gradient, occlusion, largest, error,
                    counted ? &euler : nullptr, report);
    images = LeafImages{};
    tr.seconds = seconds + seconds_since(leaf_start);
    ++report.triples;
    blockers.extend(tr.blocker_depths.lo);
    blockers.extend(tr.blocker_depths.hi);
    receivers.extend(tr.receiver_depths.lo);
    receivers.extend(tr.receiver_depths.hi);
    if (tr.config.penumbra_error + tr.view_error >= report.penumbra_error) {
      report.penumbra_error = tr.config.penumbra_error + tr.view_error;
      report.penumbra_error_texels = tr.penumbra_error_texels;
      report.rho_lo = tr.config.rho_lo;
      report.rho_hi = tr.config.rho_hi;
      report.rho = tr.config.rho;
      report.blocker_plane = tr.config.blocker_plane;
      report.receiver_plane = tr.config.receiver_plane;
      report.light_extent = tr.config.light_extent;
      report.pixel = tr.grid.pixel;
    }
  }

  // Turns the frame's occluded fractions into V and writes it, with the errors, into the tables
  // of the frame's light part.
  void store(TexelTables& parts) const {
    const std::size_t n = space.texels.size();
    auto& vis = parts.visible[std::size_t(fr.light_part)];
    auto& hit = parts.reached[std::size_t(fr.light_part)];
    auto& err = parts.error[std::size_t(fr.light_part)];
    if (vis.empty()) {
      vis.assign(n, Vec3f::Zero());
      hit.assign(n, 0);
      err.assign(n, 0.0f);
    }
    // Without a shaft test a texel no leaf reached is simply lit (0); with one, it lies in a
    // shaft a blocker may cross, and the plan did not account for it (negative).
    for (std::size_t i = 0; i < fr.texels.size(); ++i)
      err[fr.texels[i]] = in.plan.maybe_blocked ? error[i] : std::max(error[i], 0.0f);
    for (std::size_t i = 0; i < fr.texels.size(); ++i) {
      Vec3f v;
      for (int c = 0; c < 3; ++c) {
        float o = std::max(occlusion[i][c], largest[i][c]);
        if (!euler.largest.empty()) o = std::max(o, euler.largest[i][c]);
        v[c] = in.combine == BlockerCombine::sum ? std::clamp(1.0f - o, 0.0f, 1.0f)
                                                 : std::exp(-occlusion[i][c]);
      }
      vis[fr.texels[i]] = v;
      hit[fr.texels[i]] = 1;
    }
  }
};

// Texel t's V for one light from its parts that reach it and differ there: the parts' V averaged
// by their weights (bake_convolution says which).
Vec3f weighted_part_average(const TexelSpace& space, const ConvolutionInputs& in,
                            const ConvolutionPlan& plan, const TexelTables& part,
                            const std::vector<int>& parts, std::size_t t) {
  const Texel& tx = space.texels[t];
  Vec3 sum = Vec3::Zero();
  double weight = 0;
  for (int p : parts) {
    if (!part.reached[std::size_t(p)][t]) continue;
    const LightPart& lp = plan.light_parts[std::size_t(p)];
    // Plus a trace of the power share, so that a texel no part's closed form reaches
    // still averages its parts by power rather than dropping the light.
    const double w = in.weighted ? lp.part.unoccluded_irradiance(tx.position.cast<double>(),
                                                                 tx.normal.cast<double>())
                                           .sum() +
                                       1e-9 * lp.fraction
                                 : lp.fraction;
    sum += w * part.visible[std::size_t(p)][t].cast<double>();
    weight += w;
  }
  return (sum / weight).cast<float>();
}

// Light l's tables in `out` from those of its parts (`part`); a light no part reaches and no
// shaft test covers keeps empty tables.
void combine_light_parts(const TexelSpace& space, const ConvolutionInputs& in,
                         const ConvolutionPlan& plan, const TexelTables& part, std::size_t l,
                         TexelTables& out) {
  const auto& lights = *in.plan.lights;
  const std::size_t n = space.texels.size();
  auto& visible = out.visible;
  auto& reached = out.reached;
  auto& error = out.error;
  std::vector<int> parts;
  for (std::size_t p = 0; p < plan.light_parts.size(); ++p)
    if (plan.light_parts[p].light == int(l) && !part.visible[p].empty()) parts.push_back(int(p));
  const std::vector<std::uint8_t>* maybe =
      in.plan.maybe_blocked ? &(*in.plan.maybe_blocked)[l] : nullptr;
  if (parts.empty() && !maybe) return;
  visible[l].assign(n, Vec3f::Zero());
  reached[l].assign(n, 0);
  error[l].assign(n, 0.0f);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const auto& r) {
    for (std::size_t t = r.begin(); t != r.end(); ++t) {
      if (maybe && !(*maybe)[t]) {
        // Nothing lies between the texel and the light (ShaftCuller): all of it is seen.
        const Texel& tx = space.texels[t];
        if (lights[l].reaches(tx.position.cast<double>(), tx.normal.cast<double>())) {
          visible[l][t] = Vec3f::Ones();
          reached[l][t] = 1;
        }
        continue;
      }
      const Vec3f* first = nullptr;
      bool same = true;
      for (int p : parts) {
        if (!part.reached[std::size_t(p)][t]) continue;
        const Vec3f& v = part.visible[std::size_t(p)][t];
        if (!first) first = &v;
        same = same && (v - *first).cwiseAbs().maxCoeff() <= 1e-6f;
        const float e = part.error[std::size_t(p)][t];
        error[l][t] =
            (e < 0 || error[l][t] < 0) ? std::min(e, error[l][t]) : std::max(e, error[l][t]);
      }
      if (!first) continue;
      reached[l][t] = 1;
      if (same) {
        visible[l][t] = *first;
        continue;
      }
      visible[l][t] = weighted_part_average(space, in, plan, part, parts, t);
    }
  });
}

}  // namespace

Expected<ConvolutionVisibility> bake_convolution(const TexelSpace& space,
                                                 const ConvolutionInputs& in,
                                                 std::vector<PairReport>* reports,
                                                 ConvolutionPlan* plan_out) {
  const auto& lights = *in.plan.lights;
  const std::size_t n = space.texels.size();
  auto start = Clock::now();
  ConvolutionPlan plan = plan_convolution(space, in.plan);
  const double plan_seconds = seconds_since(start);
  if (const double needed = convolution_images_bytes(plan); needed > in.memory_for_images)
    return image_memory_error(plan, in, needed);

  // Per light part and texel: V, and whether one of the part's frames reaches the texel.
  TexelTables part(plan.light_parts.size());
  for (std::size_t f = 0; f < plan.frames.size(); ++f) {
    FrameBake frame(space, in, plan, f, plan_seconds);
    frame.run(part);
    if (reports) reports->push_back(std::move(frame.report));
  }

  // Per light, its parts' V averaged at each texel by the parts' weights: with the irradiance
  // weighting, each part's own unoccluded irradiance there (V is irradiance-weighted, and the
  // part nearer the texel brings more of it); without, its share of the power (V_u weights the
  // light by area). Where every part that reaches a texel sees the same V (fully lit or fully
  // hidden, most texels), that is the average whatever the weights, and no closed form is
  // evaluated.
  TexelTables light(lights.size());
  for (std::size_t l = 0; l < lights.size(); ++l)
    combine_light_parts(space, in, plan, part, l, light);

  // A texel inside a convex closed blocker (a floor under a box) sees no light: exactly, rather
  // than through the slabs' approximate count (buried_texels.h).
  const std::vector<std::uint8_t> buried =
      in.plan.clusters ? buried_texels(space, *in.plan.receiver, in.plan.blockers,
                                       *in.plan.clusters, kBuriedTolerance * plan.texel)
                       : std::vector<std::uint8_t>(n, 0);

  ConvolutionVisibility out;
  out.visible = std::move(light.visible);
  out.reached = std::move(light.reached);
  out.error_texels = std::move(light.error);
  out.buried = buried;
  if (plan_out) *plan_out = std::move(plan);
  return out;
}

}  // namespace sb
