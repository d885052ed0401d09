// Evaluating one triple of the convolution plan (docs/design.md §4–5;
// docs/design.md [S1], "Measuring the Error"): its blockers projected and
// clipped to its slab, its footprint on the receiver, the virtual configuration of its depths,
// its penumbra error ε (in receiver texels, or relative to wide penumbrae), and the image sizes
// and estimated cost of convolving it.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <utility>

#include "methods/convolution/convolution_plan.h"
#include "methods/convolution/source_image.h"

namespace sb {

namespace {

// Penumbra errors count in texels up to penumbrae this many texels wide, and relative to the
// penumbra beyond: a width error of one texel is visible at a contact shadow, while a penumbra
// 100 texels wide may be off by a few texels unseen. (docs/design.md §4: "compare it with the texel
// size, or with the penumbra width, for a relative error".)
constexpr double kRelativeSpan = 16.0;
// Image pixels across a leaf's narrowest penumbra, where that is wider than one texel per pixel.
// Fewer cost accuracy where it is checked exactly: with 32 (or 16), bilinear reads of the
// convolved image and the coarser kernel put the parallel square light's maximum error at 0.02
// (0.05) against its closed form, above the 0.02 its test allows (convolution_bake_test.cpp).
constexpr double kPenumbraPixels = 64.0;

double light_radius(const Light& light) {
  std::array<Vec3, 4> corners;
  const int count = light.outline(corners);
  if (count == 0) return light.desc().radius;
  double radius = 0;  // the farthest corner from the centre
  for (int k = 0; k < count; ++k)
    radius = std::max(radius, (corners[std::size_t(k)] - light.centre()).norm());
  return radius;
}

}  // namespace

std::pair<double, double> part_interval(const std::vector<ReceiverCut>& cuts) {
  double lo = -std::numeric_limits<double>::infinity(), hi = -lo;
  for (const ReceiverCut& c : cuts) {
    if (c.below) {
      hi = std::min(hi, c.depth + c.band);
    } else {
      lo = std::max(lo, c.depth - c.band);
    }
  }
  return {lo, hi};
}

namespace {

// The receiver texels of the triple's group that its blockers may shade: those with tangents in
// [lo, hi] and depths beyond d_floor within [part_lo, part_hi], added to `receiver_depths`,
// `footprint` and `box`, and counted in t.footprint_texels.
void find_footprint(const PlanFrame& fr, Triple& t, const Vec2& lo, const Vec2& hi, double d_floor,
                    double part_lo, double part_hi, DepthRange& receiver_depths,
                    TangentBounds& footprint, Bounds3& box) {
  fr.index[std::size_t(t.group)].for_each_cell(
      lo, hi,
      [&](const TexelIndex::Cell& c) {
        return c.depth.lo > d_floor && c.depth.lo >= part_lo && c.depth.hi <= part_hi;
      },
      [&](const TexelIndex::Cell& c) {
        receiver_depths.extend(c.depth.lo);
        receiver_depths.extend(c.depth.hi);
        footprint.extend(c.tangents);
        box.extend(c.box.lo);
        box.extend(c.box.hi);
        t.footprint_texels += c.count;
      },
      [&](int i) {
        const double d = fr.depth[i];
        if (d <= d_floor || d < part_lo || d > part_hi) return;
        const Vec2& tc = fr.tangent[i];
        if ((tc.array() < lo.array()).any() || (tc.array() > hi.array()).any()) return;
        receiver_depths.extend(d);
        footprint.extend(tc);
        box.extend(fr.position[std::size_t(i)]);
        ++t.footprint_texels;
      });
}

// The triple's virtual configuration and its penumbra error ε, in receiver texels (relative to
// the penumbra where that is wide), from its depths and its footprint.
void set_penumbra_error(const ConvolutionPlan& plan, const Light& light, const PlanFrame& fr,
                        const TangentBounds& footprint, Triple& t) {
  const double extent = light.extent_across(fr.frame.axis);
  t.config = choose_configuration(fr.frame, t.blocker_depths, t.receiver_depths, extent);
  t.smallest_penumbra = extent * (t.config.rho_lo - 1.0);
  const Vec2 reach =
      (footprint.lo - t.view).cwiseAbs().cwiseMax((footprint.hi - t.view).cwiseAbs());
  t.view_error = depth_half_spread(light, fr.frame) * reach.norm() * (t.config.rho_hi - 1.0);
  const double scale = std::max(plan.texel, t.smallest_penumbra / kRelativeSpan);
  t.penumbra_error_texels = scale > 0 ? (t.config.penumbra_error + t.view_error) / scale : 0;
}

// The grid and its cost at a pixel size `at`: the transform, the kernel's splatting (about 9
// samples of the light per kernel pixel, source_image.cpp), the footprint's lookups and the
// faces' rasterisation.
void size_images(const PlanInputs& in, const Light& light, const TangentBounds& footprint,
                 const Vec2& kernel_extent, const Vec2& span, double at, Triple& t) {
  const int kernel_w = 2 * int(std::ceil(kernel_extent.x() / (2 * at))) + 1;
  const int kernel_h = 2 * int(std::ceil(kernel_extent.y() / (2 * at))) + 1;
  const int margin_x = kernel_w / 2 + 1, margin_y = kernel_h / 2 + 1;
  t.grid.pixel = at;
  t.grid.origin = footprint.lo - Vec2(margin_x, margin_y) * at;
  t.grid.width = int(std::ceil(span.x() / at)) + 2 * margin_x + 1;
  t.grid.height = int(std::ceil(span.y() / at)) + 2 * margin_y + 1;
  t.fft_width = in.backend->transform_size(t.grid.width);
  t.fft_height = in.backend->transform_size(t.grid.height);
  const double n = double(t.fft_width) * t.fft_height;
  // The blocker images: 4 × 4 coverage samples per pixel, for the share and the whole image
  // (blocker_image.cpp); on the showcase they took three times the transforms' time.
  const double blocker_pixels = 2.0 * 16.0 * double(t.grid.width) * t.grid.height;
  t.cost = (n * std::log2(std::max(2.0, n)) + 9.0 * double(kernel_w) * kernel_h) *
               (light.textured() ? 3 : 1) +
           blocker_pixels + 30.0 * double(t.footprint_texels) + 20.0 * double(t.faces.size());
}

// The triple's image grid, its transform sizes and cost, and whether its pixels blur the
// shadow beyond the texel or the narrowest penumbra.
void choose_grid(const ConvolutionPlan& plan, const PlanInputs& in, const Light& light,
                 const PlanFrame& fr, const TangentBounds& footprint, Triple& t) {
  // Image resolution: one pixel per receiver texel at the receiver plane, coarser only where the
  // narrowest penumbra spans kPenumbraPixels pixels anyway (docs/design.md §5, "texture
  // resolution"); then within max_image, flagging any loss of detail.
  const double r_star = t.config.receiver_plane;
  const double detail = std::max(plan.texel, t.smallest_penumbra / kPenumbraPixels);
  double pixel =
      (plan.texel > 0 ? detail : (footprint.hi - footprint.lo).maxCoeff() / 512) / r_star;
  const double k = std::max(0.0, 1.0 / t.config.blocker_plane - 1.0 / r_star);
  const Vec2 kernel_extent = 2 * k * projected_half_extents(light, fr.frame, t.view, r_star);
  const Vec2 span = footprint.hi - footprint.lo;
  const double needed = (span + kernel_extent).maxCoeff();
  if (needed / pixel + 8 > in.max_image) {
    pixel = needed / (in.max_image - 8);
    t.blurred = pixel * r_star > 1.01 * std::max(plan.texel, t.smallest_penumbra / 2.0);
  } else {
    t.blurred = false;
  }
  size_images(in, light, footprint, kernel_extent, span, pixel, t);
  // Within the work budget (PlanInputs::cost_budget_per_texel): a leaf whose images would cost
  // more than its footprint may takes coarser pixels. Its ε, which decides where it is traced,
  // does not change; only the blur it adds, which ε's scale already allows for where the
  // penumbra is wide (the case that makes images this large: blockers near the light's depth).
  if (in.cost_budget_per_texel > 0) {
    const double cap = in.cost_budget_per_texel * std::max(4096.0, double(t.footprint_texels));
    for (int step = 0; step < 40 && t.cost > cap && t.grid.width * t.grid.height > 256; ++step) {
      pixel *= 1.5;
      size_images(in, light, footprint, kernel_extent, span, pixel, t);
      t.blurred = true;
    }
  }
}

}  // namespace

void evaluate_triple(const ConvolutionPlan& plan, const PlanInputs& in, Triple& t) {
  const PlanFrame& fr = plan.frames[t.frame];
  const Light& light = plan.light_parts[fr.light_part].part;
  const std::vector<int>& group = fr.groups[std::size_t(t.group)];
  t.empty = true;
  t.footprint_texels = 0;
  t.polygons = 0;
  t.blockers = ProjectedBlockers{};
  // Plain variables, not a structured binding: clang 14 (the fuzz build) cannot capture one.
  const std::pair<double, double> part = part_interval(t.cuts);
  const double part_lo = part.first, part_hi = part.second;
  if (t.faces.empty() || group.empty()) return;
  const double part_depth_hi = std::min(part_hi, fr.depth[group.back()]);

  ShadowCaster caster;
  caster.light_radius = light_radius(light);
  caster.receiver = t.receiver_box;
  // The slab grown by a hair, so that a face lying exactly on a slab boundary (a flat top seen
  // along its normal) keeps its polygon in both slabs: nearest_layer_coverage gives its samples
  // to one of them, and that one's footprint must hold them.
  const double hair = 1e-7 * std::max(1.0, part_depth_hi);
  t.blockers = project_faces(t.faces, fr.frame, std::max(t.slab_lo - hair, fr.near),
                             std::min(t.slab_hi + hair, part_depth_hi), caster);
  t.polygons = int(t.blockers.polygons.size());
  if (t.blockers.polygons.empty()) return;
  if (!t.layer) t.layer = std::make_shared<const ProjectedBlockers>(t.blockers);
  DepthRange blocker_depths;
  TangentBounds projection;
  for (const auto& pg : t.blockers.polygons) {
    blocker_depths.extend(pg.depth_lo);
    blocker_depths.extend(pg.depth_hi);
    projection.extend(TangentBounds{pg.lo, pg.hi});
  }
  // The footprint: the blockers' projection grown by the widest penumbra they can cast on the
  // part, k_max times the light's half extents (tangent units).
  t.view = projection.centre();
  const Vec2 half = projected_half_extents(light, fr.frame, t.view, part_depth_hi);
  const double k_max = std::max(0.0, 1.0 / blocker_depths.lo - 1.0 / part_depth_hi);
  const Vec2 lo = projection.lo - half * k_max, hi = projection.hi + half * k_max;
  DepthRange receiver_depths;
  TangentBounds footprint;
  Bounds3 box;
  find_footprint(fr, t, lo, hi, blocker_depths.lo, part_lo, part_hi, receiver_depths, footprint,
                 box);
  if (receiver_depths.empty()) return;
  t.empty = false;
  t.receiver_box = box;
  t.blocker_depths = blocker_depths;
  t.receiver_depths = receiver_depths;
  t.footprint_lo = footprint.lo;
  t.footprint_hi = footprint.hi;
  set_penumbra_error(plan, light, fr, footprint, t);
  choose_grid(plan, in, light, fr, footprint, t);
  t.traced =
      in.ray_cost_per_texel > 0 && t.cost > in.ray_cost_per_texel * double(t.footprint_texels);
}

Triple child_triple(const Triple& parent, TripleSplit split) {
  Triple c;
  c.frame = parent.frame;
  c.group = parent.group;
  c.split = split;
  c.slab_lo = parent.slab_lo;
  c.slab_hi = parent.slab_hi;
  c.cuts = parent.cuts;
  c.layer = parent.layer;
  c.receiver_box = parent.receiver_box;
  return c;
}

}  // namespace sb
