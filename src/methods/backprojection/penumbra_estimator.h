// The back-projection estimator of one light's visibility at one texel, without noise
// (penumbra_estimator.cpp): the blocker polygons in the texel's shaft are projected from the
// texel's ray origin onto the light, rasterised row by row over the light, and the light's
// irradiance weight is integrated in closed form along each row over what they hide.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/geometry.h"
#include "scene/lights.h"

namespace sb {

class RayScene;
class ShaftCuller;
struct LightFrame;
struct BlockedRows;
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

// Rows across (the visible part of) a light, in the light's turned frame (s across rows, t along
// the frame): row r's centre line is t = first + r·pitch, and it crosses the light from `enter`
// to `leave` (s). Metres, but for a sphere's own rows, which are those of the unit disk.
struct LightRows {
  static constexpr int kMaxRows = 64;
  static constexpr int kCells = 64;  // a row falls back to cells (one bit each) past a few polygons
  int count = 0;
  double pitch = 0, first = 0;
  bool whole = true;  // across the whole light; false: across the part above a texel's horizon
  std::array<double, kMaxRows> enter, leave;  // rows [0, count) written
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

class PenumbraEstimator {
 public:
  // `rows`: rows across the light (at most LightRows::kMaxRows). `light_offset`: how far short of
  // the light's surface a shadow ray stops (RayScene::surface_offset): geometry closer to the
  // light's plane than this (a ceiling around a flush panel) does not block it, as it does not
  // block the reference's rays.
  PenumbraEstimator(const Light& light, int rows, double light_offset);

  // The light's visibility at the texel whose surface point is `position` (shading normal
  // `normal`; the irradiance weight cosθ_light·cosθ_texel/r² is taken there) and whose shadow rays
  // leave from `origin`, given blocker polygons and convex solids that hold every blocker of
  // its shaft (the shaft's own polygons, ShaftCuller::shaft_polygons, or a tile's candidate
  // triangles, with those of convex solids given as the solids: the parts beyond the light's
  // plane or behind the origin are cut off here, and what projects outside the light or below
  // the texel's horizon hides nothing). `form_factor`: the light's F at the
  // texel (Light::form_factor) when the caller has it, else <= 0 and it is computed here.
  // `blocking`, when given, receives the triangles of the polygons and the keys of the solids
  // that reach the part of the light above the texel's horizon, sorted: those that may hide
  // some of it.
  // V = 1 exactly where nothing is blocked, 0 where every row is blocked from end to end.
  PenumbraSample visibility(const Vec3& position, const Vec3& normal, const Vec3& origin,
                            const Blockers& blockers, double form_factor = 0,
                            std::vector<std::uint32_t>* blocking = nullptr) const;
  // The same for polygons alone.
  PenumbraSample visibility(const Vec3& position, const Vec3& normal, const Vec3& origin,
                            const std::vector<BlockerPolygon>& polygons,
                            double form_factor = 0) const {
    return visibility(position, normal, origin, Blockers{&polygons, nullptr, nullptr}, form_factor);
  }

  // The same estimate with each pair of cells' blocking found by one shadow ray (32 per row:
  // 1024 at 32 rows) instead of from listed polygons: for shafts that hold too many polygons to
  // list (a dense mesh), where tracing costs less than rasterising. Deterministic like the rest:
  // the rays go to fixed points of the light's rows.
  PenumbraSample visibility_traced(const Vec3& position, const Vec3& normal, const Vec3& origin,
                                   const RayScene& scene, double form_factor = 0) const;

  // For the tests that show a wrong weight would be seen: the weight of the half of the light
  // with s > 0 (its turned frame) is multiplied by this. 1 in every bake.
  double weight_bias = 1.0;

 private:
  bool frame(const Vec3& position, LightFrame& f) const;
  // The rows for a texel: the light's own where all of it is above the texel's horizon, else
  // rows spread over the part above (so a sliver of light near the horizon has all of them).
  const LightRows& rows_for(const LightFrame& f, const Vec3& position, const Vec3& normal,
                            LightRows& scratch) const;
  double chord_half(double t, double radius) const;  // a disk's half chord
  void integrate(const LightFrame& f, const LightRows& rows, const Vec3& position,
                 const Vec3& normal, const BlockedRows& blocked, double form_factor,
                 PenumbraSample& out) const;

  const Light* light_;
  int row_count_;
  LightRows rows_;  // all of the light (a sphere's: of the unit disk)
  double light_offset_;
  Vec3 row_axis_s_, row_axis_t_;  // a rectangle's, disk's or polygon's frame (world)
  std::array<Vec2, 4> corners_;   // a rectangle's or polygon's corners in (s, t)
  double ball_radius_ = 0;        // of a ball about the light's centre that holds it
};

// The angle between a light's own axes and its rows, radians: far from 0°, 45° and 90°, the
// directions furniture and panels share most.
constexpr double kRowAngle = 0.4;

}  // namespace sb
