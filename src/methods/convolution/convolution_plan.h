// The error-driven hierarchy of the convolution method (docs/design.md §4–5; Soler & Sillion's
// blocker, receiver and source subdivision, docs/design.md [S1]): for one
// receiver, the (light part, blocker cluster, receiver part) triples whose convolutions together
// give its soft shadows, each with its virtual configuration, penumbra error ε and image size.
// Built by plan_convolution (convolution_plan.cpp) without convolving anything, so that
// `shadowbake plan` can print it; executed by bake_convolution (convolution_bake.cpp).
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "methods/convolution/blocker_image.h"
#include "methods/convolution/convolution_backend.h"
#include "methods/convolution/texel_index.h"
#include "methods/convolution/virtual_configuration.h"
#include "occluders/tangent_bounds.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "texels/texel_space.h"

namespace sb {

// How the occluded fractions O_i of different blocker clusters over one texel combine
// (docs/design.md §5): `product` takes V = ∏(1 − O_i), clusters hiding independent parts of the
// light; `sum` takes V = 1 − Σ O_i, clusters hiding disjoint parts ([bake] blocker_combine;
// docs/methods.md has the measurement that chose the default).
enum class BlockerCombine { product, sum };

struct ClusterTree;

struct PlanInputs {
  const std::vector<Light>* lights = nullptr;
  const Mesh* receiver = nullptr;
  // Every blocker mesh (the receiver's own too, when it is a blocker) and their cluster
  // hierarchy, built over exactly these meshes in this order.
  std::vector<const Mesh*> blockers;
  const ClusterTree* clusters = nullptr;
  double error_texels = 1.0;  // the target ε, in receiver texels
  int max_image = 4096;       // largest image side, pixels
  int max_triples = 128;      // leaves per light: the work budget
  // Each untextured rectangular light whose plan cuts blockers into depth slabs is split into at
  // least this many parts (1, 2 or 4), whatever ε says: the slabs' error in the shares and in
  // Euler's count scales with the light's size and ε does not measure it (docs/methods.md).
  int light_parts = 2;
  // Per light (scene order) and receiver texel: 1 where a blocker may lie between them
  // (ShaftCuller). Where given, only those texels are planned for that light: the others see all
  // of it. Null: every texel a light reaches.
  const std::vector<std::vector<std::uint8_t>>* maybe_blocked = nullptr;
  // What tracing one texel of a footprint costs, in the FFT pixel-log units of Triple::cost
  // (0: the bake traces nothing). A leaf dearer to convolve than its footprint is to trace is
  // traced and not refined further: costs are compared before either is paid.
  double ray_cost_per_texel = 0;
  // Leaves whose ε stays above this are traced too (negative: never, for ε alone).
  double trace_error_texels = -1;
  // The convolution's work budget, in Triple::cost units per planned texel (0: none): the
  // leaves of a light part cost at most this much in all (refinement stops there), and a leaf
  // at most this much per texel of its footprint (its images are made coarser).
  double cost_budget_per_texel = 0;
  // The transforms leaves will run on: their sizes set each leaf's cost.
  const ConvolutionBackend* backend = nullptr;
};

// A shadow ray's cost in Triple::cost units (FFT pixel-log): 80 ns per ray and core (the
// showcase's reference at 64 samples, 72 M rays in 2.9 s on 2 cores) against 0.64 ns per unit
// (a 512² r2c and c2r pair in 3 ms, 4.7 M units).
inline constexpr double kRayCostUnits = 125;

// One side of a receiver split: the part's texels have depth below (or above) `depth`, blended
// linearly with the other side's over depth ± band so that no seam shows.
struct ReceiverCut {
  double depth = 0, band = 0;
  bool below = true;
  double weight(double r) const {
    const double w =
        band > 0 ? std::clamp((depth + band - r) / (2 * band), 0.0, 1.0) : (r <= depth ? 1.0 : 0.0);
    return below ? w : 1.0 - w;
  }
};

// The depth interval of a receiver part: where every cut's weight is positive.
std::pair<double, double> part_interval(const std::vector<ReceiverCut>& cuts);

// How a triple's children were made: none (a leaf), or the two halves of its blockers by depth
// or by tangent position, or of its receiver texels by depth (plan_refinement.cpp).
enum class TripleSplit { none, blocker_depth, blocker_space, receiver_depth };

// "", "blocker depth", "blocker space" or "receiver depth": the words of describe_plan.
const char* to_string(TripleSplit split);

// A node of the hierarchy: the root of a (light part, frame), a split, or a leaf to convolve.
struct Triple {
  int frame = -1;                         // index into ConvolutionPlan::frames
  int group = 0;                          // index into the frame's texel groups
  int parent = -1;                        // index into ConvolutionPlan::triples; -1 for a root
  TripleSplit split = TripleSplit::none;  // how the children were made
  std::vector<int> children;
  // The blocker cluster: faces, and the slab of depth along D they are clipped to.
  std::vector<FaceRef> faces;
  double slab_lo = 0, slab_hi = 0;
  // The receiver part: the frame's texels whose weight under every cut is positive.
  std::vector<ReceiverCut> cuts;
  // Evaluated: the projected blockers, the footprint's receiver texels (indices into the
  // frame's arrays), the configuration and the image it needs.
  bool empty = true;           // no blocker or no receiver texel: nothing to convolve
  ProjectedBlockers blockers;  // kept for leaves only
  // The root's projection, shared by its whole tree: the layer whose nearest surfaces decide
  // which cluster casts each part of the hard shadow (nearest_layer_coverage).
  std::shared_ptr<const ProjectedBlockers> layer;
  Bounds3 receiver_box;  // world bounds of the texels it may shadow (footprint, or the group)
  DepthRange blocker_depths, receiver_depths;
  VirtualConfiguration config;
  // The kernel is exact for receiver points seen along `view`; a tilted light (its points spread
  // over depths ±z across D) seen from elsewhere in the footprint is sheared by up to
  // z·|t − view|·(ρ_hi − 1) on the receiver (source_image.cpp), metres.
  double view_error = 0;
  // (ε + view_error) in receiver texels while the narrowest penumbra is below kRelativeSpan
  // texels, in kRelativeSpan-ths of that penumbra beyond (triple_evaluation.cpp).
  double penumbra_error_texels = 0;
  double smallest_penumbra = 0;  // L·(ρ_lo − 1), metres on the receiver
  TangentGrid grid;
  Vec2 footprint_lo = Vec2::Zero(), footprint_hi = Vec2::Zero();  // tangent box
  // The tangent direction the light is projected along for the kernel (source_kernel): the
  // middle of the blockers' projection.
  Vec2 view = Vec2::Zero();
  int fft_width = 0, fft_height = 0;
  bool blurred = false;  // the image budget forced pixels coarser than the shadow's detail
  double cost = 0;       // estimated work, FFT pixel-log units
  // Not convolved: its footprint's texels are traced instead, as tracing them costs less than
  // convolving it (PlanInputs::ray_cost_per_texel), or, when set so by the bake, as its ε stays
  // above what tracing is for.
  bool traced = false;
  std::int64_t footprint_texels = 0;
  int polygons = 0;
  double seconds = 0;  // measured by the bake (0 in a plan)
  // A slab of a convex closed solid (add_sections): the triple's blockers are all of one such
  // component's faces within its slab, so its whole image is capped by the component's section
  // at slab_lo; every face of the component, for that section.
  std::shared_ptr<const std::vector<FaceRef>> solid_faces;
  // Slabs of one convex solid count the lines from a texel to the light that meet it by Euler's
  // count (convolution_bake.cpp): `euler` is the triple heading their depth splits (-1: none);
  // a `section` leaf is the solid's section at its slab (slab_lo = slab_hi) between two of them,
  // subtracted.
  int euler = -1;
  bool section = false;
};

// The frustum a frame looks through: the one central frustum from the light part's centre
// towards its lit texels, the frustum along a planar group's normal, or a face of the cube around
// the light, in light_frusta.h's order (+x, −x, +y, −y, +z, −z).
enum class FrameFace {
  central,
  plane,
  cube_pos_x,
  cube_neg_x,
  cube_pos_y,
  cube_neg_y,
  cube_pos_z,
  cube_neg_z
};

// The frame face of cube face `face` (0 … kCubeFaces − 1, light_frusta.h).
FrameFace cube_frame_face(int face);

// "" for the central frustum, "plane", or the cube face's name ("+x" … "-z"): the words of
// describe_plan and of the convolution's pair reports.
const char* to_string(FrameFace face);

// One light part seen through one frustum from its centre: the texels it serves.
struct PlanFrame {
  int light = -1;       // index into the scene's lights
  int light_part = -1;  // index into ConvolutionPlan::light_parts
  FrameFace face = FrameFace::central;
  ProjectionFrame frame;
  std::vector<std::size_t> texels;  // indices into TexelSpace::texels
  std::vector<double> depth;        // per texel of `texels`: depth along D
  std::vector<Vec2> tangent;        // per texel: tangent coordinates
  std::vector<Vec3> position;       // per texel: world position
  double near = 0;                  // texels at or before this depth cannot be projected
  std::int64_t outside_texels = 0;  // at or behind the light's plane: left unshadowed
  // Texels that share their blockers: all of them, or, for a receiver that is its own blocker,
  // those of one convex component, or of one plane of a non-convex one. Indices into the arrays
  // above, the deepest last; one root triple each.
  std::vector<std::vector<int>> groups;
  std::vector<TexelIndex> index;  // per group
  std::vector<int> roots;
};

struct LightPart {
  int light = -1;
  std::string name;     // "panel", or "panel[0]", "panel[1]" ... for parts
  Light part;           // the part as a light of its own
  double fraction = 1;  // its share of the light's power
};

struct ConvolutionPlan {
  std::string receiver;
  const TexelSpace* space = nullptr;
  double texel = 0;   // receiver texel size, metres
  double target = 0;  // ε allowed, metres
  std::vector<LightPart> light_parts;
  std::vector<PlanFrame> frames;
  std::vector<Triple> triples;
  std::vector<std::string> warnings;

  std::vector<int> leaves() const;
  double worst_error_texels() const;
  double estimated_cost() const;
};

// Checks the invariants the bake relies on to index `plan`'s arrays (plan_validation.cpp):
// light parts of the scene's `lights` lights; frames of their light parts, their texels, depths,
// groups, texel indices and one root per group, in range; every triple's frame, group, parent,
// children and Euler head in range, parents before children and each child listed once by its
// parent, a split's children of its frame and group with the slabs it cut; leaves' faces,
// polygons, layer, grid and transform sizes consistent; sections under depth splits of a convex
// solid. The error names the triple or frame and the broken invariant.
Status validate(const ConvolutionPlan& plan, std::size_t lights);

// Plans one receiver's convolutions: per light, the frusta from its centre (one towards the lit
// texels, or cube faces when they spread wider than 60°), and per frustum the refinement of its
// root triple: while the worst leaf's ε exceeds the target, split it where ε falls most per unit
// of estimated work (blocker depth, blocker space, receiver depth); when the budget runs out
// with ε still above it, a rectangular light is split in two and planned again, keeping
// whichever plan has the smaller worst ε.
ConvolutionPlan plan_convolution(const TexelSpace& space, const PlanInputs& in);

// Appends to `plan` the frames, texel groups and evaluated root triples of its light part
// `light_part` (plan_frames.cpp; used by plan_convolution).
void add_frames(ConvolutionPlan& plan, const PlanInputs& in, int light_part);

// A new child of `parent` made by `split`: the same frame, group, slab, cuts and layer, for the
// caller to narrow and evaluate.
Triple child_triple(const Triple& parent, TripleSplit split);

// Marks the triples of `plan` that are slabs of convex closed solids and adds, under every depth
// split between two of a solid's slabs, the section leaf at the split's depth (used by
// plan_convolution; plan_sections.cpp).
void add_sections(ConvolutionPlan& plan, const PlanInputs& in);

// Evaluates one triple in place (used by the planner; exposed for tests).
void evaluate_triple(const ConvolutionPlan& plan, const PlanInputs& in, Triple& triple);

// The hierarchy as indented text, one line per triple, with ε, image sizes, estimated cost and
// (after a bake) measured seconds.
std::string describe_plan(const ConvolutionPlan& plan);

// World size of one texel of `mesh`'s lightmap at width × height, metres: the square root of
// world area per covered texel area.
double texel_size(const Mesh& mesh, int width, int height);

}  // namespace sb
