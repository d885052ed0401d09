// The `erosion` baseline's own knobs, beyond BakeSettings (erosion_bake.cpp). bake() calls
// bake_erosion (baselines.h), which uses the defaults; tests switch parts of the method off to
// measure what each part buys.
#pragma once

#include <cstdint>

#include "methods/baselines.h"

namespace sb {

struct ErosionOptions {
  // The paper's best-fit line correction: the distance to an edge texel is taken to the
  // least-squares line through its neighbouring edge texels, not to its centre. (The line's
  // normal sets the penumbra width and footprint either way.)
  bool line_distance = true;
};

MixedImages bake_erosion(const TexelSpace& space, const BaselineInputs& in,
                         const ErosionOptions& options, MethodStats* stats,
                         std::int64_t* rays_traced);

}  // namespace sb
