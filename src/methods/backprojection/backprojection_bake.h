// The `backprojection` method's bake of one receiver (backprojection_bake.cpp): per light, the
// shaft test of its tiles, the exact estimator at the samples adaptive refinement asks for, and
// interpolation where it vouches for it; lights combined by LightMix. texel_routes.h says where
// each pair's value comes from.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/error.h"
#include "methods/backprojection/texel_refinement.h"
#include "methods/backprojection/texel_routes.h"
#include "methods/light_mix.h"
#include "occluders/ray_scene.h"
#include "occluders/shaft_culling.h"
#include "scene/lights.h"
#include "texels/texel_space.h"

namespace sb {

struct BackprojectionInputs {
  const std::vector<Light>* lights = nullptr;
  const ShaftCuller* culler = nullptr;
  const RayScene* rays = nullptr;  // the surface offset; the traced routes' rays
  Quantity quantity = Quantity::visibility;
  int light_rows = 32;     // rows of cells across each light (PenumbraEstimator)
  int max_polygons = 256;  // a shaft with more blocker polygons is traced instead of listed
  RefinementSettings refinement;
  // A textured light's traced texels: the reference's estimate, its samples and streams.
  int samples = 256;
  std::uint64_t seed = 0, stream = 0;
  KeepPerLight keep_per_light;
  // Which lights may reach each block of texels (light_lists.h); null: the bake makes them.
  const LightLists* lists = nullptr;
};

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
