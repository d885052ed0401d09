// What the back-projection estimator (penumbra_estimator.h) takes of a texel's shaft — its
// blockers as polygons, convex solids and dense meshes' outlines, prepared per tile by stage 2
// (light_pairs.cpp) — and what one evaluation finds (PenumbraSample), which the rasterisers
// (light_rows.h) fill in part as they go.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "core/geometry.h"
#include "scene/lights.h"

namespace sb {

class ShaftCuller;
struct BlockerSolid;

// A blocker polygon as the estimator takes it: convex, in world space (a triangle of the scene,
// or its part in a texel's shaft), with its plane's unit normal, what `blocking` reports it as
// (its triangle, or ShaftCuller::blocker_key of it), and the triangle it comes from where that
// key names a dense mesh: a polygon that hides all of the light alone reports the convex
// blocker whose umbra holds the texel (PenumbraSample::umbra), never a mesh's many triangles.
struct BlockerPolygon {
  static constexpr std::uint32_t kKeyIsConvex = 0xffffffffu;
  const Vec3* v = nullptr;
  int count = 0;
  Vec3 normal = Vec3::Zero();
  std::uint32_t triangle = 0;
  std::uint32_t source = kKeyIsConvex;  // kKeyIsConvex: `triangle` names one triangle or solid
};

// A convex, closed blocker solid (occluders/blocker_solids.h), taken whole through its
// silhouette, and the key `blocking` reports it by. `edges` (count of them), when given, are the
// only edges of the solid that may be on its silhouette from the texel (those between faces
// that do not face the same way from every point of its tile), and `distance` a lower bound on
// the texel's distance to the solid.
// `faces` (count of them), when given, are its triangles a texel may need one by one, where the
// solid reaches behind the texel's origin (a ball resting on the floor the texel is on), which a
// silhouette cannot take.
struct BlockerSolidRef {
  const BlockerSolid* solid = nullptr;
  std::uint32_t key = 0;
  const int* edges = nullptr;
  int edge_count = 0;
  double distance = 0;
  const BlockerPolygon* faces = nullptr;
  int face_count = 0;
  // The faces that may cross the light's plane or a texel's origin height, when the tile knows.
  const int* cut_faces = nullptr;
  int cut_count = 0;
};

// One edge of a dense mesh's triangle that may bound the union of a tile's triangles of it.
struct OutlineEdge {
  Vec3 a, b;  // its ends, copied: a tile's edges are read in order, not from all of the mesh
  std::uint32_t triangle = 0;
  // Whether the triangle faces every ray origin of the tile (1) or none (0); -1: some, so
  // decided per texel.
  std::int8_t facing = -1;
  // The triangle across the edge when the edge bounds the union only where the two face
  // different ways and that is decided per texel (one of them faces some origins of the tile
  // only); -1: it bounds it for every texel of the tile.
  std::int32_t across = -1;
  std::int8_t across_facing = -1;  // as `facing`, for `across`
};

// Many triangles of a dense mesh, taken at once through the outline of their union: an edge two
// of them share, both facing the same way, bounds neither. Made per tile by prepare_outline.
// They report `key` as reaching the light; `distance` is a lower bound on the texel's distance
// to them.
struct BlockerOutline {
  const ShaftCuller* culler = nullptr;
  std::vector<OutlineEdge> edges;
  // Triangles taken one by one: reaching past the light's plane or the origins' height, or
  // passing within the rays' offset of the tile.
  std::vector<BlockerPolygon> apart;
  // For a sphere light, whose plane changes from texel to texel: every triangle, each decided
  // per texel (edges and apart are then empty).
  std::vector<std::uint32_t> triangles;
  double distance = 0;
  std::uint32_t key = 0;
};

// A tile's triangles of one dense mesh (`key`) as its texels' evaluations take them, given the
// box of the tile's ray origins and the rays' surface offset.
BlockerOutline prepare_outline(const ShaftCuller& culler, const Light& light,
                               const std::vector<std::uint32_t>& triangles, std::uint32_t key,
                               const Bounds3& origins, double offset);

// What may block a texel's view of the light, as the estimator takes it.
struct Blockers {
  const std::vector<BlockerPolygon>* polygons = nullptr;  // one by one
  const std::vector<BlockerSolidRef>* solids = nullptr;   // convex solids, by silhouette
  const std::vector<BlockerOutline>* outlines = nullptr;  // dense meshes, by outline
  // The ray from the texel's origin to the light's centre meets a blocker (which hides not all
  // of the light alone): the nearest polygons are tried first, for a wall of several that hides
  // all of it (PenumbraEstimator::visibility).
  bool centre_hidden = false;
};

// What a texel's evaluation found, beside V.
struct PenumbraSample {
  double visibility = 1;     // V = H / H0 of this light at the texel, [0, 1]
  bool contributes = false;  // false: no part of the light is above the texel's horizon (V unset)
  // A lower bound on the distance from the texel's ray origin to the nearest polygon that may
  // hide some of the light from it (metres; infinity for none): how narrow a penumbra near it
  // can be (texel_refinement.cpp). From the rays' nearest hit on the traced route.
  double nearest_blocker = 0;
  // The key of a convex solid, or of one polygon, that hides all of the light by itself (its
  // umbra), or kNoUmbra.
  static constexpr std::uint32_t kNoUmbra = 0xffffffffu;
  std::uint32_t umbra = kNoUmbra;
};

}  // namespace sb
