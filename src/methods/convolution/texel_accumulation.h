// Adding convolved leaves into a frame's receiver texels (convolution_bake.cpp's overview): cut
// weights, slab weights, the irradiance weighting's moments, the max rule and Euler's counts of
// convex solids. Used by bake_convolution.
#pragma once

#include <cstdint>
#include <vector>

#include "methods/convolution/convolution_plan.h"
#include "methods/convolution/leaf_convolution.h"
#include "methods/convolution/pair_report.h"
#include "scene/lights.h"
#include "scene/scene.h"
#include "texels/texel_space.h"

namespace sb {

// The irradiance weight w = cos θ_light · cos θ_receiver / distance² of the light's points seen
// from each texel, to first order across the light: the gradient of ln w at the light's centre
// along its right and up axes, per metre (docs/design.md §6). Zero where the light's centre lies
// on or below the texel's horizon or the texel on or behind the light's plane (cosines under
// 1e-3), where a first-order weight would mislead.
std::vector<Vec2> weight_gradients(const PlanFrame& fr, const TexelSpace& space,
                                   const Light& light);

// Euler's counts of a frame's convex solids (add_sections): the solid whose leaves are being
// added (leaves are sorted so that each solid's come together), its count per frame texel, the
// texels it touched, and per texel the largest count of the solids done.
struct EulerCounts {
  int solid = -1;
  std::vector<Vec3f> count, largest;
  std::vector<std::uint8_t> touched_flag;
  std::vector<int> touched;

  explicit EulerCounts(std::size_t texels)
      : count(texels, Vec3f::Zero()), largest(texels, Vec3f::Zero()), touched_flag(texels, 0) {}
  // Starts the count of `next`, folding the previous solid's into `largest`.
  void begin(int next) {
    if (next == solid) return;
    for (int i : touched) {
      largest[std::size_t(i)] = largest[std::size_t(i)].cwiseMax(count[std::size_t(i)]);
      count[std::size_t(i)] = Vec3f::Zero();
      touched_flag[std::size_t(i)] = 0;
    }
    touched.clear();
    solid = next;
  }
};

// Adds a convolved leaf's weighted occlusion into `occlusion` (per frame texel), and its whole
// image's occlusion into `largest` (the max rule of `sum`; see convolution_bake.cpp's overview).
// `gradient`: weight_gradients of the leaf's frame, or empty without the irradiance weighting;
// `euler`: the counts of the leaf's convex solid, or null where it is not counted.
void accumulate_leaf(const ConvolutionPlan& plan, const Triple& leaf, const LeafImages& images,
                     BlockerCombine combine, const std::vector<Vec2>& gradient,
                     std::vector<Vec3f>& occlusion, std::vector<Vec3f>& largest,
                     std::vector<float>& error, EulerCounts* euler, PairReport& report);

// A traced leaf's footprint texels: their value is not the convolution's to give (+infinity).
void mark_traced(const ConvolutionPlan& plan, const Triple& leaf, std::vector<float>& error);

}  // namespace sb
