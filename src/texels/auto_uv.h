// Lightmap UVs made for a receiver that has none (`uv = "auto"`): the surface cut into charts,
// each flattened with little stretch, packed into the lightmap by texel density with the margin
// between charts, written into the mesh's lightmap UVs. docs/methods.md ("Generated lightmap UVs")
// has the choices and the figures measured against Blender's Smart UV Project and Lightmap Pack.
#pragma once

#include "core/error.h"
#include "scene/mesh.h"

namespace sb {

// What the charts are packed for: a lightmap of `side` texels a side, or (side 0) a density of
// `texels_per_metre` in the smallest square that holds it, at most `max_side` (beyond it, the
// density that fills max_side). `margin`: empty texels between two charts' texels, at least.
struct AutoUvTarget {
  int side = 0;
  double texels_per_metre = 0;
  int max_side = 0;
  int margin = 4;
};

struct AutoUvReport {
  int charts = 0;
  int conformal_charts = 0;     // flattened by least-squares conformal maps (the others: projected)
  int side = 0;                 // the lightmap side packed for
  double texels_per_metre = 0;  // the density the charts got (texels per metre of surface)
};

// Replaces mesh's lightmap UVs (and sets has_uv): charts grown from the largest triangles across
// smooth edges (vertex normals within kSmoothEdgeDegrees, as find_seams) while every triangle's
// normal stays within 60° of the chart's mean; flat charts projected on their plane, curved ones
// by LSCM (chart_lscm.h). A chart that is not a disc, folds over itself in UV, or has a triangle
// whose UV area is more than twice or less than half its surface area (once the chart is scaled
// to its surface) is bisected across its longest axis, and each connected piece placed the same
// way. Each chart is turned to its smallest bounding rectangle and packed (stb_rect_pack) half a
// texel into a rectangle of whole texels plus the margin. Vertices are split where charts meet;
// faces keep their order. An error when even the smallest charts with their margins do not fit
// the side (too many charts for it).
Expected<AutoUvReport> generate_lightmap_uvs(Mesh& mesh, const AutoUvTarget& target);

}  // namespace sb
