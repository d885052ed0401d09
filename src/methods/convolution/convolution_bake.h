// The `convolution` method: soft-shadow textures by FFT convolution (Soler & Sillion 1998),
// convolution_bake.cpp.
#pragma once

#include <string>
#include <vector>

#include "methods/convolution/convolution_plan.h"
#include "methods/convolution/pair_report.h"
#include "methods/convolution/virtual_configuration.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "texels/texel_space.h"

namespace sb {

struct ConvolutionInputs {
  // What the planner needs (the lights, the receiver, the blockers and their clusters, ε, the
  // work budget, the shaft test's pairs, the cost of tracing, the backend): one copy, passed on.
  PlanInputs plan;
  Quantity quantity = Quantity::visibility;
  BlockerCombine combine = BlockerCombine::sum;
  // Weight the occluded fraction by irradiance to first order across the light (docs/design.md
  // §6: two more convolutions per leaf), so that V is the irradiance-weighted visibility the
  // reference computes rather than the emission-weighted V_u.
  bool weighted = true;
  // Convolve a leaf's far-apart blocker islands (a table's legs) on windows of their own rather
  // than on one grid spanning them all: the same values for a fraction of the pixels
  // (convolution_bake.cpp, leaf_windows). Off only to measure what it saves.
  bool island_windows = true;
  // Bytes the leaves' images may take at once (what the bake's budget leaves them,
  // memory_budget.h); a plan that needs more is refused before anything is convolved.
  double memory_for_images = 1e18;
  // The transforms (plan.backend, which executes them too).
  ConvolutionBackend* fft = nullptr;
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

// Convolves one receiver: plans its triples (plan_convolution), convolves every leaf and
// combines them per light and texel into ConvolutionVisibility (lights are combined by the
// caller, through LightMix). Appends one report per (light part, frustum) to `reports`, and gives
// the executed plan, with each leaf's measured seconds, in *plan (either may be null). The
// error: the plan needs more memory than in.memory_for_images.
Expected<ConvolutionVisibility> bake_convolution(const TexelSpace& texels,
                                                 const ConvolutionInputs& in,
                                                 std::vector<PairReport>* reports,
                                                 ConvolutionPlan* plan = nullptr);

}  // namespace sb
