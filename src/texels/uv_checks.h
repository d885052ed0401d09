// Checks of a receiver's lightmap UV layout, reported per receiver in the manifest and as
// warnings (uv_checks.cpp): how much of its UV area lies outside the lightmap, texels two charts
// claim, and texels so close to another chart that bilinear filtering and the margin's dilation mix
// the two.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "scene/mesh.h"
#include "texels/texel_space.h"

namespace sb {

struct UvLayoutReport {
  double uv_area = 0;                   // Σ of the UV triangles' areas (the unit square is 1)
  double uv_area_outside = 0;           // the part of it outside [0, 1]², which gets no texels
  std::int64_t overlapping_texels = 0;  // TexelSpace::overlapping_texels
  int charts = 0;  // UV charts: triangles joined by edges with the same UVs at both ends
  int margin = 0;  // texels, [bake] margin
  // Covered texels with a texel of another chart within `margin` texels (either axis).
  std::int64_t texels_near_other_charts = 0;
  // How evenly the layout spends its texels on the surface (uv_quality): Sander et al.'s L2
  // stretch with the layout's overall scale taken out (1: every triangle keeps its shape and its
  // share of area; higher is worse), and the spread of texel density, the 95th over the 5th
  // percentile of texels per metre by surface area (1: even).
  double stretch = 0;
  double density_spread = 0;
  bool generated = false;  // the bake made these UVs (texels/auto_uv.h)
};

// The two quality figures of a UV layout (UvLayoutReport::stretch, density_spread), over the
// triangles with UV area; {0, 0} for a mesh without UVs.
struct UvQuality {
  double stretch = 0, density_spread = 0;
};
UvQuality uv_quality(const Mesh& mesh);

UvLayoutReport check_uv_layout(const Mesh& mesh, const TexelSpace& space, int margin);

// One message per problem the report shows, without the object's name (the caller adds it).
std::vector<std::string> uv_layout_warnings(const UvLayoutReport& report);

}  // namespace sb
