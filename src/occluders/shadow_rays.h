// One texel's shadow rays towards one light's sample points, traced together: what the
// reference and accumulation methods share (each picks its points differently: stratified per
// texel, or one constellation for every texel).
#pragma once

#include <cstdint>
#include <vector>

#include "core/sampling.h"
#include "occluders/ray_scene.h"
#include "scene/lights.h"
#include "texels/texel_space.h"

namespace sb {

class ShadowRays {
 public:
  explicit ShadowRays(int capacity)
      : origins_(std::size_t(capacity)),
        directions_(std::size_t(capacity)),
        lengths_(std::size_t(capacity)),
        weights_(std::size_t(capacity)),
        hit_(std::size_t(capacity)) {}

  int capacity() const { return int(origins_.size()); }
  void clear() {
    n_ = 0;
    weight_sum_ = Vec3::Zero();
  }
  // Adds the segment from `origin` to a sample point, unless the point cannot contribute or
  // lies within the surface offset. The segment stops that offset short of the light's own
  // surface, which may lie on a blocker (a panel on a ceiling).
  void add(const Vec3& origin, const LightSample& ls, double offset) {
    if (ls.weight <= 0) return;
    const Vec3 d = ls.point - origin;
    const double len = d.norm();
    if (len <= 2 * offset) return;
    const std::size_t i = std::size_t(n_++);
    origins_[i] = origin;
    directions_[i] = d;
    lengths_[i] = 1.0 - offset / len;
    weights_[i] = ls.weight * ls.tint;  // per channel
    weight_sum_ += weights_[i];
  }
  int size() const { return n_; }
  // Traces the segments; per channel, the weighted fraction that reaches the light. False, and
  // nothing traced, when no point contributes.
  bool visible_fraction(const RayScene& rays, Vec3* v) {
    if (n_ == 0 || weight_sum_.maxCoeff() <= 0) return false;
    rays.occluded(n_, origins_.data(), directions_.data(), lengths_.data(), hit_.data());
    Vec3 visible = Vec3::Zero();
    for (std::size_t s = 0; s < std::size_t(n_); ++s)
      if (!hit_[s]) visible += weights_[s];
    *v = Vec3::Zero();
    for (int c = 0; c < 3; ++c)
      if (weight_sum_[c] > 0) (*v)[c] = visible[c] / weight_sum_[c];
    return true;
  }

 private:
  std::vector<Vec3> origins_, directions_;
  std::vector<double> lengths_;
  std::vector<Vec3> weights_;
  std::vector<std::uint8_t> hit_;
  int n_ = 0;
  Vec3 weight_sum_ = Vec3::Zero();
};

// The reference's samples of `light` at one texel (reference_bake.cpp), into `batch`: `samples`
// stratified points of the part of the light above the texel's horizon (Light::above_horizon),
// from the texel's own random stream (seed, receiver stream, the light's stream (Light::stream,
// from its name), pixel), one shadow ray each from the lifted shadow origin.
inline void add_reference_samples(const TexelSpace& space, std::size_t t, const Light& light,
                                  const RayScene& rays, int samples, std::uint64_t seed,
                                  std::uint64_t stream, ShadowRays& batch,
                                  std::vector<Vec2>& strata) {
  const Texel& texel = space.texels[t];
  const double offset = rays.surface_offset();
  const Vec3 position = texel.position.cast<double>();
  const Vec3 normal = texel.normal.cast<double>();
  const Vec3 origin = space.ray_origin(t, offset);
  Rng rng(stream_seed(seed, stream_seed(stream, light.stream()),
                      std::uint64_t(texel.y) * std::uint64_t(space.width) + texel.x));
  stratified_samples(samples, rng, strata);
  batch.clear();
  const HorizonPart part = light.above_horizon(position, normal);
  for (int s = 0; s < samples; ++s) batch.add(origin, part.sample(strata[s]), offset);
}

// The reference's estimate of `light`'s visibility at texel t, traced from those samples.
// False when no point contributes. Any method that traces a texel this way gets the reference's
// value at that many samples, bit for bit.
inline bool estimate_visibility(const TexelSpace& space, std::size_t t, const Light& light,
                                const RayScene& rays, int samples, std::uint64_t seed,
                                std::uint64_t stream, ShadowRays& batch, std::vector<Vec2>& strata,
                                Vec3* v) {
  add_reference_samples(space, t, light, rays, samples, seed, stream, batch, strata);
  return batch.visible_fraction(rays, v);
}

}  // namespace sb
