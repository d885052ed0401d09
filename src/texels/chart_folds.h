// Where a flattened chart folds over itself (chart_folds.cpp): the generator of lightmap UVs
// (auto_uv.cpp) cuts such a chart between the two places found and flattens each piece again.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include "core/geometry.h"

namespace sb {

// One chart flattened: per face of the chart (in its order), its corners' UVs in metres.
using ChartUvs = std::vector<std::array<Vec2, 3>>;

// Two places in space between which a flattened chart folds over itself.
struct ChartFold {
  Vec3 a, b;
};

// Whether a flattened chart folds over itself: two of its border edges (by local vertex) crossing
// in UV, found by a sweep over their u extents. Edges that also touch in space are the two lips
// of a crack (T-junctions, unwelded panels: common in assets made by others) laid side by side,
// not a fold. Where they fold, the midpoints in space of the first two edges found crossing.
// `uv` and `positions` are per local vertex; `border` holds the border edges' local vertices.
std::optional<ChartFold> border_crosses(const std::vector<Vec2>& uv,
                                        const std::vector<Vec3>& positions,
                                        const std::vector<std::array<int, 2>>& border);

// Whether two triangles of a flattened chart overlap with positive area in UV (coplanar faces
// that overlap in space, as brushwork's often do, lie on each other once projected; their border
// edges cross as a crack's lips do): the separating axis test over the six edge normals, with
// overlaps thinner than a ten-millionth of the longer triangle counted as touching (neighbours,
// T-junctions). Found by a sweep over their u extents; where they overlap, the indices in `uv`
// of the first two triangles found overlapping.
std::optional<std::array<std::size_t, 2>> overlapping_triangles(const ChartUvs& uv);

}  // namespace sb
