// What the `backprojection` bake (backprojection_bake.cpp) is given: the method's settings, read
// once per bake from the scene's [bake] table (backprojection_method.cpp), and the shared
// structures every receiver's bake reads. Each stage takes its part of them.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "methods/light_lists.h"
#include "methods/light_mix.h"
#include "occluders/ray_scene.h"
#include "occluders/shaft_culling.h"
#include "scene/lights.h"

namespace sb {

struct RefinementSettings {
  int max_cell = 8;         // texels between the coarsest samples (a power of two, ≤ kTile)
  double tolerance = 2e-3;  // largest |V(centre) − V predicted from the corners| interpolated
  double normal_cos = std::cos(15.0 * 3.14159265358979 / 180.0);  // normals of one smooth piece
  double position_texels = 1.0;  // a texel's distance from the cell's bilinear surface, in texels
  double feature_cells = 2.0;    // the narrowest penumbra allowed, in cells
  double midpoint_cells = 4.0;   // under this, the cell's edge midpoints are checked too
};

// The method's settings: its own [bake] keys (their defaults are these) and the bake's keys it
// reads, as backprojection_settings(bake) reads them once per bake.
struct BackprojectionSettings {
  Quantity quantity = Quantity::visibility;
  int light_rows = 32;     // rows of cells across each light (PenumbraEstimator)
  int max_polygons = 256;  // a shaft with more blocker polygons is traced instead of listed
  RefinementSettings refinement;
  // A textured light's traced texels: the reference's estimate, its samples and seed.
  int samples = 256;
  std::uint64_t seed = 0;
};

// One receiver's bake: the settings, and what it reads beside them.
struct BackprojectionInputs : BackprojectionSettings {
  const std::vector<Light>* lights = nullptr;
  const ShaftCuller* culler = nullptr;
  const RayScene* rays = nullptr;  // the surface offset; the traced routes' rays
  std::uint64_t stream = 0;        // the receiver's sampling streams' key
  KeepPerLight keep_per_light;
  // Which lights may reach each block of texels (light_lists.h); null: the bake makes them.
  const LightLists* lists = nullptr;
};

}  // namespace sb
