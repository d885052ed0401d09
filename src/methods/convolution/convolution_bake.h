// The `convolution` method: soft-shadow textures by FFT convolution (Soler & Sillion 1998),
// convolution_bake.cpp.
#pragma once

#include <string>
#include <vector>

#include "pipeline/bake.h"
#include "methods/convolution/convolution_plan.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "texels/texel_space.h"
#include "occluders/virtual_configuration.h"

namespace sb {

struct ConvolutionInputs {
  const std::vector<Light>* lights = nullptr;
  const Mesh* receiver = nullptr;  // the receiver's own mesh
  // Every blocker mesh, the receiver's own included when it is a blocker, and their cluster
  // hierarchy built over exactly these meshes in this order (may be null: no shaft culling).
  std::vector<const Mesh*> blockers;
  const ClusterTree* clusters = nullptr;
  Quantity quantity = Quantity::visibility;
  double error_texels = 1.0;  // target penumbra error, receiver texels
  int max_image = 4096;       // largest image side, pixels
  int max_triples = 128;      // leaf triples per light
  int light_parts = 2;        // each rectangular light in at least this many parts (1, 2, 4)
  BlockerCombine combine = BlockerCombine::sum;
  // Weight the occluded fraction by irradiance to first order across the light (design-notes
  // §6: two more convolutions per leaf), so that V is the irradiance-weighted visibility the
  // reference computes rather than the emission-weighted V_u.
  bool weighted = true;
  // Convolve a leaf's far-apart blocker islands (a table's legs) on windows of their own rather
  // than on one grid spanning them all: the same values for a fraction of the pixels
  // (convolution_bake.cpp, leaf_windows). Off only to measure what it saves.
  bool island_windows = true;
  // Per light and texel: where a blocker may lie between them (ShaftCuller); only those texels
  // are convolved for that light, the others see all of it. Null: every texel.
  const std::vector<std::vector<std::uint8_t>>* maybe_blocked = nullptr;
  // When the caller traces what the convolution cannot vouch for (traced_convolution.h): the cost
  // of tracing a texel and the ε above which it does (PlanInputs). Traced leaves are not
  // convolved; their texels' error is +infinity in ConvolutionVisibility.
  double ray_cost_per_texel = 0;
  double trace_error_texels = -1;
  double cost_budget_per_texel = 0;  // PlanInputs::cost_budget_per_texel
  // Bytes the leaves' images may take at once (what the bake's budget leaves them,
  // memory_budget.h); a plan that needs more is refused before anything is convolved.
  double memory_for_images = 1e18;
};

// Each light's own visibility at the receiver's texels, before lights are combined, and how far
// the convolution can vouch for it: what a caller needs to replace some texels' values (by
// shadow rays) before mixing the lights itself.
struct ConvolutionVisibility {
  // Per light (scene order), per texel: V (RGB), whether the light reaches the texel, and the
  // worst penumbra error ε (receiver texels, as the plan counts it) of the leaves that shade it:
  // 0 where no leaf does (nothing in the way that the plan saw), negative where the texel lies
  // in a frame the plan convolved but no leaf reached although a blocker may lie in its shaft.
  std::vector<std::vector<Vec3f>> visible;
  std::vector<std::vector<std::uint8_t>> reached;
  std::vector<std::vector<float>> error_texels;
  std::vector<std::uint8_t> buried;  // per texel: inside a convex closed blocker (no light)
};

// The most memory the leaves' images of `plan` take at once, bytes: leaves are convolved a batch
// at a time, and each transform pixel holds the images and spectra convolve_leaf makes.
double convolution_images_bytes(const ConvolutionPlan& plan);

// Bakes one receiver: plans its triples (plan_convolution), convolves every leaf and combines
// them per texel; lights combined as V = Σ H0_l·V_l / Σ H0_l (or H = Σ H0_l·V_l). Appends one
// report per (light part, frustum) to `reports`, and gives the executed plan, with each leaf's
// measured seconds, in *plan (either may be null). The error: the plan needs more memory than
// in.memory_for_images.
Expected<Image> bake_convolution(const TexelSpace& texels, const ConvolutionInputs& in,
                                 std::vector<PairReport>* reports, ConvolutionPlan* plan = nullptr,
                                 ConvolutionVisibility* per_light = nullptr);

}  // namespace sb
