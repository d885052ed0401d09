// Stage 2's preparation of a listed tile for its texels' evaluations (light_pairs.cpp): the
// tile's candidate blockers sorted into what the estimator takes (penumbra_estimator.h) —
// triangles one by one, convex solids whole, dense meshes through their outline — once per tile
// (tile_blockers.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "core/geometry.h"
#include "methods/backprojection/piercing_blockers.h"
#include "methods/backprojection/shaft_blockers.h"
#include "occluders/shaft_culling.h"
#include "scene/lights.h"

namespace sb {

// A dense mesh's triangles in a tile's list are taken through their outline from this many on
// (fewer, each exact interval beats cells).
constexpr std::size_t kOutlineTriangles = 32;
// A listed tile's blockers as its texels' evaluations take them: triangles one by one, and the
// convex solids its texels all lie outside of whole, each with the edges that may be on its
// silhouette from some point of the tile (between faces that do not face the same way from all
// of it) and a lower bound on the tile's distance to it.
struct TileBlockers {
  std::vector<BlockerPolygon> polygons;
  std::vector<BlockerOutline> outlines;
  std::vector<BlockerSolidRef> solids;
  std::vector<std::vector<int>> edges;             // per solid
  std::vector<std::vector<BlockerPolygon>> faces;  // per solid: its candidate triangles
  std::vector<std::vector<int>> cut_faces;         // per solid: faces across the slab's planes
};

// The parts of a triangle that pierces the light's ball (piercing_blockers.h) as polygons, each
// its own umbra (a part alone is convex; the triangle's parts together are not), reported as
// `key`.
void add_parts(const PiercingBlockers& piercing, std::uint32_t triangle, std::uint32_t key,
               const Vec3& normal, std::vector<BlockerPolygon>& out);

// The tile's blockers among `candidates` (its shaft test's list), for ray origins in the box
// `origins` and rays `offset` off their surfaces; `piercing`: the triangles through the light's
// ball.
TileBlockers tile_blockers(const ShaftCuller& culler, const Light& light,
                           const std::vector<std::uint32_t>& candidates, const Bounds3& origins,
                           double offset, const PiercingBlockers& piercing);

}  // namespace sb
