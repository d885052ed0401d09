// The baseline methods users compare shadowbake with (design-notes §7), each in lightmap texel
// space: a texel's world position and normal play the part a screen pixel plays in the papers.
//   accumulation                       accumulation_bake.cpp   (Heckbert & Herf)
//   pcf, pcss, adaptive-pcf, chun-oh   shadow_map_bake.cpp     (Reeves; Fernando; Uralsky; Chun & Oh)
//   erosion                            erosion_bake.cpp        (Klein, Nischwitz & Obermeier)
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/image.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "occluders/ray_scene.h"
#include "scene/scene.h"
#include "texels/texel_space.h"

namespace sb {

struct BaselineInputs {
  const std::vector<Light>* lights = nullptr;
  // Every blocker, for ray-cast hard shadows: accumulation and erosion only (null for the
  // shadow-map filters, which need none).
  const RayScene* rays = nullptr;
  std::vector<const Mesh*> blockers;  // every blocker mesh, the receiver's own if it blocks
  const Mesh* receiver = nullptr;
  const BakeSettings* settings = nullptr;  // method, quantity, samples, seed, shadow_map, ...
  std::uint64_t stream = 0;                // the receiver's index, for its own random streams
};

// Named figures a method reports per receiver (e.g. adaptive PCF's fraction of texels that took
// the full filter); written to the manifest and printed by --explain.
using MethodStats = std::vector<std::pair<std::string, double>>;

// Each returns a width × height RGB image like bake_reference: per covered texel
// V = Σ_l H0_l·V_l / Σ_l H0_l (visibility) or Σ_l H0_l·V_l (irradiance), uncovered texels 0.
Image bake_accumulation(const TexelSpace& space, const BaselineInputs& in, MethodStats* stats,
                        std::int64_t* rays_traced);
// pcf, pcss, adaptive-pcf and chun-oh, by in.settings->method.
Image bake_shadow_map_filter(const TexelSpace& space, const BaselineInputs& in,
                             MethodStats* stats);
Image bake_erosion(const TexelSpace& space, const BaselineInputs& in, MethodStats* stats,
                   std::int64_t* rays_traced);

// Accumulates per-light visibilities into the output image the way every method combines
// lights: weights H0_l in closed form (a single light's visibility needs none). add() may be
// called from many threads for distinct texels.
class LightMix {
 public:
  LightMix(const TexelSpace& space, const std::vector<Light>& lights, Quantity quantity);
  // Light l's visibility v (per channel, in [0, 1]) at texel t; a light that does not reach the
  // texel may be skipped or added with any v.
  void add(std::size_t light, std::size_t texel, const Vec3& v);
  Image finish();

 private:
  const TexelSpace& space_;
  const std::vector<Light>& lights_;
  Quantity quantity_;
  bool weighted_;
  Image sum_;
  std::vector<Vec3f> weight_sum_;
};

}  // namespace sb
