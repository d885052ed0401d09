// The `convolution` method as a bake runs it on real scenes (traced_convolution.cpp): the shaft
// test decides exactly which (light, texel) pairs nothing stands between; the convolution shades
// the rest; and where the convolution cannot vouch for its value (a leaf's penumbra error above
// `trace_error_texels`, or a texel whose shaft a blocker may cross that no leaf accounted for),
// shadow rays take over, so hard cases cost what the reference costs there and no more.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "methods/convolution/convolution_bake.h"
#include "methods/method.h"
#include "occluders/ray_scene.h"
#include "occluders/shaft_culling.h"

namespace sb {

struct TracedConvolutionInputs {
  ConvolutionInputs convolution;
  const ShaftCuller* culler = nullptr;  // null: no shaft test, the convolution shades every pair
  const RayScene* rays = nullptr;       // null: no rays, the convolution's values stand
  bool convolve = true;                 // false: no convolution, every pair not clear is traced
  int samples = 64;                     // rays per light per traced texel
  double trace_error_texels = 1.0;      // leaves' ε above this are traced
  std::uint64_t seed = 0, stream = 0;   // as the reference's, so a traced texel matches it
  KeepPerLight keep_per_light;          // per-light images wanted (MixedImages)
};

// What the method did with the receiver's (light, texel) pairs the lights reach.
struct TracedConvolutionStats {
  std::int64_t pairs = 0, clear = 0, convolved = 0, traced = 0;
  std::int64_t rays = 0;
};

// Bakes one receiver; lights combined by LightMix.
Expected<MixedImages> bake_traced_convolution(const TexelSpace& space,
                                              const TracedConvolutionInputs& in,
                                              std::vector<PairReport>* reports,
                                              ConvolutionPlan* plan, TracedConvolutionStats* stats);

// The registry's entry: the convolution and its settings (error_texels, max_image, max_triples,
// light_parts, trace, convolve, trace_error_texels, blocker_combine, weighting, samples, seed).
MethodEntry convolution_method();

// The method's settings, read once per bake from the [bake] table (convolution_settings).
struct ConvolutionSettings {
  Quantity quantity = Quantity::visibility;
  // The planner's (PlanInputs).
  double error_texels = 0;
  int max_image = 0, max_triples = 0, light_parts = 0;
  // The convolution's (ConvolutionInputs) and the traced route's (TracedConvolutionInputs).
  BlockerCombine combine = BlockerCombine::sum;
  bool weighted = true;
  bool convolve = true;
  double trace_error_texels = 0;
  int samples = 256;
  std::uint64_t seed = 0;
};
ConvolutionSettings convolution_settings(const BakeSettings& bake);

// The planner's inputs for one receiver from the bake's settings (what `shadowbake plan` and the
// method share).
PlanInputs plan_inputs(const BakeContext& context, const ConvolutionSettings& settings,
                       const Mesh* receiver, const ConvolutionBackend* backend);

}  // namespace sb
