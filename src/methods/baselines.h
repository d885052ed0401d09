// The baseline methods users compare shadowbake with (docs/design.md §7), each in lightmap texel
// space: a texel's world position and normal play the part a screen pixel plays in the papers.
//   accumulation                       accumulation_bake.cpp   (Heckbert & Herf)
//   pcf, pcss, adaptive-pcf, chun-oh   shadow_map_bake.cpp     (Reeves; Fernando; Uralsky; Chun &
//   Oh) erosion                            erosion_bake.cpp        (Klein, Nischwitz & Obermeier)
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/image.h"
#include "methods/method.h"
#include "occluders/ray_scene.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "scene/scene.h"
#include "texels/texel_space.h"

namespace sb {

// The baselines' settings, read once per bake from the [bake] table (baseline_settings).
struct BaselineSettings {
  std::string method = "pcf";  // the filter, for the shadow-map baselines
  Quantity quantity = Quantity::visibility;
  int samples = 256;  // accumulation's light samples; adaptive PCF's most taps
  std::uint64_t seed = 0;
  int shadow_map = 2048;             // texels per side of each shadow map
  double pcf_radius = 2.0;           // PCF's footprint, shadow-map texels
  bool erosion_by_distance = false;  // erosion's shadow factor: by distance, else by PCF
};
BaselineSettings baseline_settings(const BakeSettings& bake);

struct BaselineInputs {
  const std::vector<Light>* lights = nullptr;
  // Every blocker, for ray-cast hard shadows: accumulation and erosion only (null for the
  // shadow-map filters, which need none).
  const RayScene* rays = nullptr;
  std::vector<const Mesh*> blockers;  // every blocker mesh, the receiver's own if it blocks
  const Mesh* receiver = nullptr;
  BaselineSettings settings;
  std::uint64_t stream = 0;     // the receiver's index, for its own random streams
  KeepPerLight keep_per_light;  // per-light images wanted (MixedImages)
};

// Each returns width × height RGB images like bake_reference, lights combined by LightMix.
MixedImages bake_accumulation(const TexelSpace& space, const BaselineInputs& in, MethodStats* stats,
                              std::int64_t* rays_traced);
// pcf, pcss, adaptive-pcf and chun-oh, by in.settings.method.
MixedImages bake_shadow_map_filter(const TexelSpace& space, const BaselineInputs& in,
                                   MethodStats* stats);
MixedImages bake_erosion(const TexelSpace& space, const BaselineInputs& in, MethodStats* stats,
                         std::int64_t* rays_traced);

// The registry's entries (each reads the [bake] keys it lists).
MethodEntry accumulation_method();
MethodEntry erosion_method();
// pcf, pcss, adaptive-pcf and chun-oh.
MethodEntry shadow_map_method(const std::string& name);

}  // namespace sb
