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

// (light, texel) pairs by route (texel_routes.h), and the rays traced.
struct RouteCounts {
  std::array<std::int64_t, 7> pairs{};  // indexed by TexelRoute
  std::int64_t rays = 0;
  std::int64_t& operator[](TexelRoute r) { return pairs[std::size_t(r)]; }
  std::int64_t operator[](TexelRoute r) const { return pairs[std::size_t(r)]; }
  std::int64_t reached() const;  // every pair but none
};

// Bakes one receiver; lights combined by LightMix. `routes`, when given, gets its pairs' counts.
MixedImages bake_backprojection(const TexelSpace& space, const BackprojectionInputs& in,
                                RouteCounts* routes);

// The same light's field alone (visibility and route per texel), for tests and benchmarks.
LightField backprojection_light(const TexelSpace& space, const BackprojectionInputs& in,
                                std::size_t light);

}  // namespace sb
