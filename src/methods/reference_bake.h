// The `reference` method: exact visibility by ray casting (reference_bake.cpp).
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "methods/method.h"
#include "occluders/ray_scene.h"
#include "scene/lights.h"
#include "texels/texel_space.h"

namespace sb {

struct ReferenceInputs {
  const std::vector<Light>* lights = nullptr;
  const RayScene* rays = nullptr;
  Quantity quantity = Quantity::visibility;
  int samples = 256;  // per light per texel
  std::uint64_t seed = 0;
  std::uint64_t stream = 0;  // distinguishes receivers so each has its own random streams
  std::atomic<std::int64_t>* texels_done = nullptr;  // progress counter, may be null
  ProgressFn progress;          // called with texels_done after each chunk, may be empty
  KeepPerLight keep_per_light;  // per-light images wanted (MixedImages)
  // Which lights may reach each block of texels (light_lists.h); null: the bake makes them.
  const LightLists* lists = nullptr;
};

// Returns width × height RGB images (LightMix's rule: per covered texel V = Σ_l H_l / Σ_l H0_l or
// H = Σ_l H_l), V_l estimated from `samples` stratified
// shadow rays per light; uncovered texels 0. Adds the number of rays traced to *rays_traced.
MixedImages bake_reference(const TexelSpace& texels, const ReferenceInputs& in,
                           std::int64_t* rays_traced);

// The registry's entry: reads samples and seed.
MethodEntry reference_method();

}  // namespace sb
