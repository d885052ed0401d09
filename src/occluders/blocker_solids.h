// The closed pieces of the blocker meshes (blocker_solids.cpp): connected components whose
// triangles close a surface with normals pointing out, and among them the convex ones, with
// what their silhouette needs (corners, faces, and the two faces of every edge). Seen from a
// point outside it, a closed solid is hidden behind its front faces alone (a ray enters through
// one of them before it meets any other), and a convex one projects onto a plane as one convex
// polygon whose outline is the projection of its silhouette edges: what the back-projection
// estimator rasterises instead of its many faces (a bevelled box leg's hundred triangles become
// about twenty edges).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/geometry.h"

namespace sb {

struct BlockerSolid {
  Bounds3 bounds;
  bool convex = false;  // within 0.1 % of its size (blocker_solids.cpp)
  // Filled for a convex solid: its corners (welded), its faces' corners and unit normals, and
  // its edges as (corner a, corner b, face on one side, face on the other).
  std::vector<Vec3> corners;
  std::vector<std::array<int, 3>> faces;
  std::vector<Vec3> normals;
  std::vector<std::array<int, 4>> edges;
  // A ball inside the solid (inner_radius > 0; 0 where none was found): no triangle of it
  // nearer to the centre than the radius, the centre inside (its winding number 1). A segment
  // from a point outside the solid to the ball crosses the solid's surface, so wherever the ball
  // hides a light, the solid does, and the ball is convex (one of its umbrae holds every point
  // between its points): what proves a lumpy tree crown's umbra (blocker_solids.cpp). Every
  // corner lies within outer_radius of the centre: a point farther away is outside the solid.
  Vec3 inner_centre = Vec3::Zero();
  double inner_radius = 0, outer_radius = 0;
};

struct BlockerSolids {
  std::vector<BlockerSolid> solids;
  std::vector<int> solid_of;  // per triangle given: the solid it belongs to, or -1
  // Per triangle given, its neighbour across each edge (corners k, k + 1): the triangle of the
  // same mesh holding that edge the other way round; -1 at a border, or where more than two
  // triangles meet at the edge or two hold it the same way round.
  std::vector<std::array<int, 3>> across;
};

// The solids among `triangles` and their neighbours, which come as consecutive ranges, one per mesh
// (mesh_ends[i]: one past mesh i's last triangle); a component never spans two meshes.
// Positions are welded on a grid of 1e-6 of each mesh's size, so that UV seams do not open a
// surface; a zero-area triangle belongs to no solid.
BlockerSolids find_solids(const std::vector<std::array<Vec3, 3>>& triangles,
                          const std::vector<std::size_t>& mesh_ends);

}  // namespace sb
