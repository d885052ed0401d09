// One leaf triple's convolution (convolution_bake.cpp's overview): its source kernel and blocker
// images rendered on its grid, or on a window per island of its blockers, and convolved by the
// bake's backend. Used by bake_convolution; texel_accumulation.h adds the results into texels.
#pragma once

#include <array>
#include <vector>

#include "methods/convolution/blocker_image.h"
#include "methods/convolution/convolution_backend.h"
#include "methods/convolution/convolution_plan.h"
#include "methods/convolution/source_image.h"
#include "scene/scene.h"

namespace sb {

// One window of a leaf's grid and its convolved images: the whole grid, or, where the leaf's
// blockers fall into islands whose shadows cannot meet (leaf_windows), the part around one
// island. `lo`, `hi` bound the tangents of the texels that read it.
struct LeafWindow {
  TangentGrid grid;
  Vec2 lo = Vec2::Zero(), hi = Vec2::Zero();
  int tw = 0, th = 0;
  std::array<std::vector<float>, 3> occluded;       // share of the nearest layer ⊛ kernel
  std::array<std::vector<float>, 3> occluded_full;  // whole image ⊛ kernel; empty if equal
  std::array<std::vector<float>, 2> moment;         // share ⊛ moment kernels (weighting)
  std::array<std::vector<float>, 2> moment_full;    // whole ⊛ moment kernels, if whole differs
};

// One leaf's convolved images, made independently of every other leaf (so leaves run in
// parallel) and then added into the frame's texels by accumulate_leaf.
struct LeafImages {
  SourceKernel kernel;
  std::vector<LeafWindow> windows;
  int convolutions = 0;
  double seconds_source = 0, seconds_blocker = 0, seconds_fft = 0;
};

// Renders one leaf's kernel and blocker images and convolves them, on a window per island of
// its blockers when `windows` is set and that saves work (leaf_convolution.cpp).
LeafImages convolve_leaf(const ConvolutionPlan& plan, const Triple& leaf, BlockerCombine combine,
                         bool weighted, bool windows, ConvolutionBackend& fft);

}  // namespace sb
