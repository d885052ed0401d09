// Deterministic random numbers and stratified sample sets for the sampling methods.
// Every texel draws from its own stream, seeded from (seed, receiver, light, texel), so results
// do not depend on the number of threads or the order they run in; a light's key is its name
// (Light::stream), so they do not depend on the other lights either.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "core/geometry.h"

namespace sb {

// SplitMix64 (Steele, Lea & Flood, "Fast splittable pseudorandom number generators", OOPSLA
// 2014): a 64-bit state, one add and a bijective mix per draw; small enough to make one per texel.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next_u64() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1).
  double next_double() { return double(next_u64() >> 11) * 0x1.0p-53; }
  // Uniform integer in [0, n).
  std::uint32_t next_below(std::uint32_t n) { return std::uint32_t((next_u64() >> 32) * n >> 32); }

 private:
  std::uint64_t state_;
};

// A seed for one stream, mixed from several keys.
std::uint64_t stream_seed(std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0);

// A light's or receiver's stream key from its name (FNV-1a over its bytes): stable across runs,
// builds and platforms, and the same whatever else the scene holds or in what order.
std::uint64_t name_stream(std::string_view name);

// Fills `out` with `count` jittered stratified points in [0,1)²: the unit square is cut into
// nx × ny cells (nx = ceil(√count), ny = ceil(count / nx)), one jittered point per cell; when
// count < nx·ny a random subset of `count` cells is used, so every cell is equally likely and the
// estimate stays unbiased.
void stratified_samples(int count, Rng& rng, std::vector<Vec2>& out);

// The unit direction that u ∈ [0,1)² maps to under cosine-weighted sampling of the hemisphere
// about unit n (Malley's method: a uniform point of the unit disk lifted onto the hemisphere), so
// its density is cos θ / π; stratified u give stratified directions.
Vec3 cosine_direction(const Vec3& n, const Vec2& u);

}  // namespace sb
