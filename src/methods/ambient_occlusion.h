// The `ambient-occlusion` method (quantity "ambient-occlusion"): the cosine-weighted fraction of
// a texel's hemisphere that no blocker closes within a distance, the map an asset pipeline bakes
// for every prop. No light takes part.
#pragma once

#include <atomic>
#include <cstdint>

#include "core/image.h"
#include "methods/method.h"
#include "occluders/ray_scene.h"
#include "texels/texel_space.h"

namespace sb {

struct AmbientOcclusionInputs {
  const RayScene* rays = nullptr;
  const Mesh* mesh = nullptr;  // the receiver's (RayScene::buried tells its own faces apart)
  double distance = 10.0;      // metres: a blocker further along a ray does not occlude it
  int samples = 256;           // rays per texel
  std::uint64_t seed = 0;
  std::uint64_t stream = 0;                          // the receiver's index: its own random streams
  std::atomic<std::int64_t>* texels_done = nullptr;  // progress counter, may be null
  ProgressFn progress;                               // may be empty
};

// Per covered texel, A = (1/N) Σ unoccluded(ω_i) over N = `samples` stratified cosine-weighted
// directions ω_i about the texel's shading normal (so A → (1/π) ∫ v(ω) cos θ dω), each a segment
// of length `distance` from the texel's lifted shadow origin, as the reference's shadow rays
// leave; the same A in R, G and B; uncovered texels 0. A texel pressed against a surface facing
// it (RayScene::buried: the bottom of a leg standing on a floor, the floor under it) is 0, as
// no direction is open there, though its rays would start beyond the cover and escape. Each texel
// has its own random stream. Adds the rays traced to *rays_traced.
Image bake_ambient_occlusion(const TexelSpace& space, const AmbientOcclusionInputs& in,
                             std::int64_t* rays_traced);

// The registry's entry: reads samples, seed and ao_distance.
MethodEntry ambient_occlusion_method();

}  // namespace sb
