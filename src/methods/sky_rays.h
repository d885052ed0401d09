// The reference's rays over a sky (scene/sky.h) at one texel: the sky itself, not its parts.
// N directions, for a map half drawn by the map's own flux (Sky::sample) and half cosine-weighted
// about the texel's normal, each weighted by the two densities' mixture (so neither a bright
// patch nor the cosine is left to chance), for a uniform sky all cosine-weighted; one ray each.
//   H  = (1/N) Σ L(ω) cos⁺θ v(ω) / p(ω),   H0 = the same with v = 1,
// per colour channel, and V = H / H0 from the same directions (a ratio estimate, as the light
// samples' of shadow_rays.h).
#pragma once

#include <algorithm>
#include <cstdint>
#include <numbers>
#include <vector>

#include "core/sampling.h"
#include "occluders/ray_scene.h"
#include "scene/sky.h"
#include "texels/texel_space.h"

namespace sb {

// Scratch space for one thread's sky estimates.
struct SkyRays {
  std::vector<Vec2> strata;
  std::vector<Vec3> origins, directions;
  std::vector<double> lengths;
  std::vector<Vec3> weights;  // L cos / p per ray, per channel
  std::vector<std::uint8_t> hit;
};

// The sky's H0 and V at `texel` from `samples` rays of length `distance` (the sky's, beyond every
// blocker), from the texel's own stream (seed, receiver stream, the sky's stream, pixel). False
// when the sky sends it nothing (every direction below its horizon, or black there); *rays_traced
// counts the rays.
inline bool estimate_sky(const TexelSpace& space, std::size_t t, const Sky& sky,
                         const RayScene& rays, int samples, std::uint64_t seed,
                         std::uint64_t stream, double distance, SkyRays& s, Vec3* h0, Vec3* v,
                         std::int64_t* rays_traced) {
  const Texel& texel = space.texels[t];
  const double offset = rays.surface_offset();
  const Vec3 normal = texel.normal.cast<double>();
  const Vec3 origin = space.ray_origin(t, offset);
  Rng rng(stream_seed(seed, stream, std::uint64_t(texel.y) * std::uint64_t(space.width) + texel.x));
  const double map_share = sky.uniform() ? 0.0 : 0.5;
  const int from_map = int(map_share * samples);
  s.origins.clear();
  s.directions.clear();
  s.weights.clear();
  Vec3 total = Vec3::Zero();
  const auto add = [&](const Vec3& d) {
    const double cosine = d.dot(normal);
    if (cosine <= 0) return;
    const double density = map_share * sky.pdf(d) + (1 - map_share) * cosine / std::numbers::pi;
    if (!(density > 0)) return;
    const Vec3 w = sky.radiance(d) * (cosine / density);
    total += w;
    if (w.maxCoeff() <= 0) return;
    s.origins.push_back(origin);
    s.directions.push_back(d);
    s.weights.push_back(w);
  };
  stratified_samples(from_map, rng, s.strata);
  for (const Vec2& u : s.strata) {
    double density = 0;
    add(sky.sample(u, &density));
  }
  stratified_samples(samples - from_map, rng, s.strata);
  for (const Vec2& u : s.strata) add(cosine_direction(normal, u));
  if (total.maxCoeff() <= 0) return false;
  const int n = int(s.origins.size());
  s.lengths.assign(std::size_t(n), distance);
  s.hit.resize(std::size_t(n));
  rays.occluded(n, s.origins.data(), s.directions.data(), s.lengths.data(), s.hit.data());
  Vec3 visible = Vec3::Zero();
  for (std::size_t k = 0; k < std::size_t(n); ++k)
    if (!s.hit[k]) visible += s.weights[k];
  *h0 = total / double(samples);
  for (int c = 0; c < 3; ++c) (*v)[c] = total[c] > 0 ? visible[c] / total[c] : 0.0;
  if (rays_traced) *rays_traced += n;
  return true;
}

}  // namespace sb
