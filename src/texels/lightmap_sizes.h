// How many texels each receiver's lightmap gets: `[bake] resolution` on a side for every one, or,
// with `[bake] texels_per_metre`, a side that gives its surface that density (Unity's and
// Godot's "texels per unit"), scaled by the object's lightmap_scale and clamped to what a file or
// an atlas holds.
#pragma once

#include <string>
#include <vector>

#include "scene/mesh.h"
#include "scene/scene.h"

namespace sb {

// The smallest lightmap side a density gives: below it a receiver's charts and their margins do
// not fit (a 4-texel margin around one chart already takes 8).
inline constexpr int kMinLightmapSide = 8;
// The largest side a density gives without an atlas: 8192² RGB float is 768 MiB per lightmap.
inline constexpr int kMaxLightmapSide = 8192;

struct LightmapSide {
  int side = 0;          // texels per side of the square lightmap
  double wanted = 0;     // the side the density asked for, before clamping
  bool clamped = false;  // wanted lay outside [kMinLightmapSide, the largest side]
};

// The square side that gives `mesh`'s surface `texels_per_metre` texels per metre:
// side = density · sqrt(world area / UV area), the UV area being its lightmap UV triangles'
// total area in the unit square (Σ of |area|). Rounded up, clamped to
// [kMinLightmapSide, max_side]. A mesh without lightmap UV area gets kMinLightmapSide.
LightmapSide lightmap_side(const Mesh& mesh, double texels_per_metre, int max_side);

// The largest side a receiver may have: an atlas's size less its padding on both sides, else
// kMaxLightmapSide with texels_per_metre, else [bake] resolution.
int largest_lightmap_side(const Scene& scene);

// Every receiver's side, in scene order of the receivers (objects with receiver = true), and a
// warning, naming the scene file, line and object, for each whose side was clamped.
std::vector<int> lightmap_sides(const Scene& scene, const std::vector<Mesh>& meshes,
                                std::vector<std::string>* warnings);

}  // namespace sb
