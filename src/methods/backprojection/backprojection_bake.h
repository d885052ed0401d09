// The `backprojection` method's bake of one receiver (backprojection_bake.cpp): per light, the
// shaft test of its tiles, the exact estimator at the samples adaptive refinement asks for, and
// interpolation where it vouches for it; lights combined by LightMix. texel_routes.h says where
// each pair's value comes from.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "methods/backprojection/backprojection_settings.h"
#include "methods/backprojection/texel_refinement.h"
#include "methods/backprojection/texel_routes.h"
#include "methods/light_mix.h"
#include "texels/texel_space.h"

namespace sb {

// Bakes one receiver; lights combined by LightMix. `routes`, when given, gets its pairs' counts.
MixedImages bake_backprojection(const TexelSpace& space, const BackprojectionInputs& in,
                                RouteCounts* routes);

// The same light's field alone (visibility and route per texel), for tests and benchmarks.
LightField backprojection_light(const TexelSpace& space, const BackprojectionInputs& in,
                                std::size_t light);

}  // namespace sb
