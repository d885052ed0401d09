// Least-squares conformal maps (Lévy et al., SIGGRAPH 2002) of one UV chart, by CGAL's
// Surface_mesh_parameterization: the flattening that keeps angles, hence little stretch on
// developable and gently curved charts. chart_lscm.cpp is the only file of src/texels that
// includes CGAL (CMakeLists.txt compiles it with the clusters' file, apart from the library).
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "core/geometry.h"

namespace sb {

// UVs per vertex for the chart made of `triangles` (indices into `positions`), in the chart's own
// units (metres, up to a rotation). Nothing when the chart is not a topological disc (one
// border, no handle) or the solver fails; the caller then cuts the chart smaller.
std::optional<std::vector<Vec2>> lscm_unwrap(const std::vector<Vec3>& positions,
                                             const std::vector<std::array<int, 3>>& triangles);

}  // namespace sb
