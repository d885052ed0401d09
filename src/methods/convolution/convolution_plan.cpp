// The error-driven hierarchy of (light part, blocker cluster, receiver part) triples
// (docs/design.md §4–5; docs/design.md [S1], "Measuring the Error" and
// "Subdivision"). One virtual configuration per triple gets every penumbra width wrong by at
// most ε = L·(ρ_hi − ρ_lo)/2, ρ = r/d over the triple's blocker depths d and receiver depths r.
// Splitting the blockers by depth narrows d, splitting the receiver by depth narrows r,
// splitting the light halves L; the planner applies whichever split lowers the worst leaf's ε
// most per unit of estimated FFT work, until every leaf is within `error_texels` receiver
// texels or the budget is spent.
//
// What the paper leaves open and is chosen here:
// - A planar group of texels (a floor; one face plane of a bracket) is seen along its plane's
//   normal (add_frames): every texel then lies at one depth, so the receiver's own depth range is
//   exact and only the blockers' depths and the light's tilt need subdividing; blockers clipped
//   to depths before the plane are exactly those on the light's side of it. Other receivers are
//   seen through one frustum from the light's centre (or cube faces) and split by depth.
// - ρ is taken over the receiver texels of the blocker cluster's footprint only (its projection
//   from the light's centre, grown by the widest penumbra), not the whole receiver: a post's
//   shadow needs the depths of the floor around the post, not of the whole floor. This is what
//   makes clusters pay: separate clusters have separate, small footprints.
// - A light tilted against the axis has points off its centre's plane; its kernel is exact for
//   receiver points seen along the triple's view (source_image.cpp) and sheared elsewhere, an
//   error counted with ε (Triple::view_error) that blocker-space and light splits reduce.
// - ε counts in receiver texels up to penumbrae kRelativeSpan texels wide and relative to the
//   penumbra beyond (docs/design.md §4 allows either): contact shadows get thin slabs, wide soft
//   penumbrae do not spend the budget on invisible width errors.
// - The blockers of a triple are clipped to a slab of depth; a texel takes a slab's shadow in
//   proportion to how much of the slab's geometry lies in front of it (bake_convolution), so
//   geometry behind a texel never shadows it and contact shadows converge as slabs thin.
// - Self-shadowing: the receiver's own faces are blockers too, except for texels on a convex
//   component of the receiver, which cannot shadow itself (H0 already counts its horizon).
//   Texels of a non-convex component are grouped by the plane of their face, so that the
//   plane-side test of project_faces drops the faces they lie on.
#include "methods/convolution/convolution_plan.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "methods/convolution/plan_refinement.h"

namespace sb {

double texel_size(const Mesh& mesh, int width, int height) {
  const SurfaceAreas areas = surface_areas(mesh);
  if (areas.uv <= 0) return 0;
  return std::sqrt(areas.world / (areas.uv * double(width) * height));
}

std::vector<int> ConvolutionPlan::leaves() const {
  std::vector<int> out;
  for (std::size_t i = 0; i < triples.size(); ++i)
    if (triples[i].children.empty() && !triples[i].empty) out.push_back(int(i));
  return out;
}

double ConvolutionPlan::worst_error_texels() const {
  double worst = 0;
  for (int i : leaves())
    if (!triples[i].traced) worst = std::max(worst, triples[i].penumbra_error_texels);
  return worst;
}

double ConvolutionPlan::estimated_cost() const {
  double cost = 0;
  for (int i : leaves())
    if (!triples[i].traced) cost += triples[i].cost;
  return cost;
}

namespace {

// Light splits: at most this many halvings (2^2 = 4 parts).
constexpr int kMaxLightSplits = 2;

// A plan whose invariants fail (validate) would make the bake index past its arrays: refused in
// every build, as an internal error (core/error.h).
void require_valid(const ConvolutionPlan& plan, std::size_t lights) {
  if (const Status valid = validate(plan, lights); !valid)
    throw std::logic_error("invariant failed: " + valid.error().message);
}

// Appends `from` (planned for the same receiver, with `lights` lights) to `to`, renumbering its
// indices; `from` is validated first.
void merge_plan(ConvolutionPlan& to, ConvolutionPlan&& from, std::size_t lights) {
  require_valid(from, lights);
  const int parts = int(to.light_parts.size()), frames = int(to.frames.size()),
            triples = int(to.triples.size());
  for (auto& lp : from.light_parts) to.light_parts.push_back(std::move(lp));
  for (auto& f : from.frames) {
    f.light_part += parts;
    for (int& r : f.roots) r += triples;
    to.frames.push_back(std::move(f));
  }
  for (auto& t : from.triples) {
    t.frame += frames;
    if (t.parent >= 0) t.parent += triples;
    if (t.euler >= 0) t.euler += triples;
    for (int& c : t.children) c += triples;
    to.triples.push_back(std::move(t));
  }
  for (auto& w : from.warnings) to.warnings.push_back(std::move(w));
}

ConvolutionPlan empty_like(const ConvolutionPlan& plan) {
  ConvolutionPlan p;
  p.receiver = plan.receiver;
  p.space = plan.space;
  p.texel = plan.texel;
  p.target = plan.target;
  return p;
}

bool has_slabs(const ConvolutionPlan& plan) {
  return std::any_of(plan.triples.begin(), plan.triples.end(),
                     [](const Triple& t) { return t.split == TripleSplit::blocker_depth; });
}

ConvolutionPlan plan_whole_part(const ConvolutionPlan& base, const PlanInputs& in, LightPart part,
                                int budget) {
  ConvolutionPlan whole = empty_like(base);
  whole.light_parts.push_back(std::move(part));
  add_frames(whole, in, 0);
  refine_triples(whole, in, 0, whole.frames.size(), budget);
  add_sections(whole, in);
  return whole;
}

ConvolutionPlan plan_light_part(const ConvolutionPlan& base, const PlanInputs& in, LightPart part,
                                int budget, int level);

// The part's two halves along its longer side, planned at once on their own threads with half
// the budget each, merged into one plan.
ConvolutionPlan plan_halves(const ConvolutionPlan& base, const PlanInputs& in,
                            const LightPart& part, int budget, int level) {
  const LightDesc& d = part.part.desc();
  std::array<ConvolutionPlan, 2> half_plans;
  tbb::parallel_for(0, 2, [&](int side) {
    LightDesc h = d;
    const double sign = side == 0 ? -0.5 : 0.5;
    if (d.width >= d.height) {
      h.width = 0.5 * d.width;
      h.position = d.position + sign * h.width * part.part.right();
    } else {
      h.height = 0.5 * d.height;
      h.position = d.position + sign * h.height * part.part.up();
    }
    h.power = 0.5 * d.power;
    LightPart half{part.light, part.name + "." + std::to_string(side), Light(h),
                   0.5 * part.fraction};
    half_plans[std::size_t(side)] =
        plan_light_part(base, in, std::move(half), std::max(1, budget / 2), level + 1);
  });
  ConvolutionPlan halves = empty_like(base);
  for (ConvolutionPlan& h : half_plans) merge_plan(halves, std::move(h), in.lights->size());
  return halves;
}

// Plans one light part within `budget` leaves; when the target is missed, tries the part's two
// halves (a source subdivision, docs/design.md §5) and keeps the plan with the smaller worst ε.
// Where blockers are cut into depth slabs, the part is split into at least `light_parts` pieces
// whatever ε says (the slabs' plane error, which ε does not measure, scales with the light's
// size; one plane per blocker has none). Below that count the halves are planned first: if they
// cut blockers into slabs, the whole part (whose ε is larger) would too, and its plan, which
// would be thrown away, is never made.
ConvolutionPlan plan_light_part(const ConvolutionPlan& base, const PlanInputs& in, LightPart part,
                                int budget, int level) {
  const LightDesc& d = part.part.desc();
  const bool splittable =
      d.shape == LightShape::rectangle && !part.part.textured() && level < kMaxLightSplits;
  if (splittable && (1 << level) < in.light_parts) {
    ConvolutionPlan halves = plan_halves(base, in, part, budget, level);
    if (has_slabs(halves)) return halves;
    ConvolutionPlan whole = plan_whole_part(base, in, part, budget);
    const double worst = whole.worst_error_texels();
    const bool better = worst > in.error_texels && halves.worst_error_texels() < worst;
    return has_slabs(whole) || better ? std::move(halves) : std::move(whole);
  }
  ConvolutionPlan whole = plan_whole_part(base, in, part, budget);
  const double worst = whole.worst_error_texels();
  if (worst <= in.error_texels || !splittable) return whole;
  ConvolutionPlan halves = plan_halves(base, in, part, budget, level);
  return halves.worst_error_texels() < worst ? std::move(halves) : std::move(whole);
}

}  // namespace

ConvolutionPlan plan_convolution(const TexelSpace& space, const PlanInputs& in) {
  ConvolutionPlan plan;
  plan.receiver = in.receiver->name;
  plan.space = &space;
  plan.texel = texel_size(*in.receiver, space.width, space.height);
  plan.target = in.error_texels * plan.texel;
  for (std::size_t l = 0; l < in.lights->size(); ++l) {
    const Light& light = (*in.lights)[l];
    LightPart whole{int(l), light.desc().name, light, 1.0};
    merge_plan(plan, plan_light_part(plan, in, std::move(whole), in.max_triples, 0),
               in.lights->size());
  }
  // Leaves the budget left above the tracing threshold are traced rather than convolved: their
  // values would be replaced anyway.
  if (in.ray_cost_per_texel > 0 && in.trace_error_texels >= 0) {
    for (Triple& t : plan.triples)
      if (t.children.empty() && !t.empty && t.penumbra_error_texels > in.trace_error_texels)
        t.traced = true;
  }
  for (const Triple& t : plan.triples) {
    if (t.children.empty() && t.blurred && !t.traced) {
      plan.warnings.push_back("receiver '" + plan.receiver +
                              "': a convolution image reached max_image and is coarser than "
                              "its sharpest penumbra; raise max_image to keep it sharp");
      break;
    }
  }
  const double worst = plan.worst_error_texels();
  if (worst > in.error_texels) {
    plan.warnings.push_back(
        "receiver '" + plan.receiver + "': penumbra error " + std::to_string(worst).substr(0, 5) +
        " texels after " + std::to_string(in.max_triples) +
        " triples per light, above error_texels = " + std::to_string(in.error_texels).substr(0, 5));
  }
  require_valid(plan, in.lights->size());
  return plan;
}

}  // namespace sb
