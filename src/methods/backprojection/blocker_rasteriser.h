// One texel's rasteriser of blocker polygons and convex solids into its light rows
// (light_rows.h), shared by its two files: blocker_rasteriser.cpp (its frame, the regions it
// fills, polygons one by one, and the nearest-first attempt) and solid_rasteriser.cpp (convex
// solids, by their silhouette or their faces).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "methods/backprojection/light_rows.h"

namespace sb {

// A shaft polygon cut by up to 8 more lines, and by the light's plane.
constexpr int kPieceVertices = 32;

// A polygon's plane (unit normal `normal`, at signed distance `height` from the origin) near
// the origin: the rays that meet it within the surface offset of the origin skip it there.
struct Skip {
  Vec3 normal;
  double height = 0;
};
struct Span {
  double a, b;
};

// One texel's rasterisation of polygons and convex solids into its light rows: the light's frame
// as the texel's ray origin sees it, and the convex region being rasterised (the rows it holds,
// r0 to r1, and each one's chord, lo to hi), which every step reads and writes.
struct Rasteriser {
  explicit Rasteriser(const RasterTarget& target);
  // Whether anything can hide the light: the origin lies above the light's plane, with rows.
  bool usable() const { return h_origin > f.clip_height && n > 0; }

  Vec2 project(const Vec3& point) const {
    const Vec3 d = point - origin;
    const double scale = h_origin / std::max(-f.normal.dot(d), 1e-12 * h_origin);
    return Vec2(s_origin + scale * f.s_axis.dot(d), t_origin + scale * f.t_axis.dot(d));
  }
  // The texel's horizon in the light's plane: above it where x·s + y·t + z > 0.
  bool is_above(const Vec2& p) const {
    return horizon.x() * p.x() + horizon.y() * p.y() + horizon.z() > 0;
  }
  // Whether a projected point lies in the light's box above the horizon: a sliver between two
  // rows' centre lines reaches the light by that.
  bool in_light(const Vec2& p) const {
    return p.y() >= t_first && p.y() <= t_last && p.x() >= extent_lo && p.x() <= extent_hi &&
           is_above(p);
  }
  double gap_to(const Vec3& lo_corner, const Vec3& hi_corner) const {
    return (lo_corner - origin).cwiseMax(origin - hi_corner).cwiseMax(Vec3::Zero()).norm();
  }
  // Whether the box lies wholly outside the cone from the origin around the light's ball (every
  // ray the rows stand for runs inside it), by the box's bounding ball: a lower bound on its
  // distance to the cone's side, perp·cos α − along·sin α, above the ball's radius. Cheaper than
  // cutting and projecting a polygon that hides nothing.
  // Whether the plane through `point` with unit normal `n` leaves the origin and the light's ball
  // on one side: no ray from the origin to the light crosses it.
  bool beside_plane(const Vec3& point, const Vec3& n) const {
    const double h_from = n.dot(origin - point), h_ball = n.dot(f.ball_centre - point);
    return f.ball_radius > 0 &&
           ((h_from > 0 && h_ball > f.ball_radius) || (h_from < 0 && h_ball < -f.ball_radius));
  }
  bool outside_cone(const Vec3& lo_corner, const Vec3& hi_corner) const {
    if (!(cone_cos > 0)) return false;
    const Vec3 v = 0.5 * (lo_corner + hi_corner) - origin;
    const double along = v.dot(cone_axis);
    const double perp = (v - along * cone_axis).norm();
    return perp * cone_cos - along * cone_sin > 0.5 * (hi_corner - lo_corner).norm();
  }

  // One convex region of the light's plane, given by its outline's edges: the rows its t-range
  // holds (begin), each edge's crossing of them (edge), then each row's chord within the light
  // kept (commit), which says whether any of it lies above the horizon.
  void begin(double t_lo, double t_hi);
  void edge(Vec2 p, Vec2 q);
  bool commit(const Skip* skip);
  int skipped(const Skip& skip, int r, std::array<Span, 2>& out) const;
  bool add(const Vec3* v, int count, const Skip* skip = nullptr);
  bool add_blocker(const Vec3* v, int count, const Vec3& plane_normal, double gap);
  void found(bool reaches, double gap, std::uint32_t key);

  void add_polygon(const BlockerPolygon& poly);
  void add_solid(const BlockerSolidRef& ref);
  void solid_by_faces(const BlockerSolidRef& ref, double gap);
  void solid_cut_to_slab(const BlockerSolidRef& ref, double gap,
                         const std::vector<int>& silhouette);
  void near_edge(const Vec2& p, const Vec2& q, const Vec3& a, const Vec3& b,
                 double& distance) const;
  void settle(const BlockerSolidRef& ref, bool reaches, double gap, double edge_distance);

  const LightFrame& f;
  const LightRows& rows;
  const Vec3 origin, position, normal;
  const double light_offset;
  BlockedRows& blocked;
  PenumbraSample& out;
  std::vector<std::uint32_t>* blocking;
  double& nearest;
  const int n;
  const double h_origin, s_origin, t_origin;
  const double h_top;  // above: behind the origin
  const Vec3 horizon;
  double extent_lo = kInfinity, extent_hi = -kInfinity;  // the rows' s-range
  // The cone from the origin around the light's ball (outside_cone); cone_cos 0: none (the
  // origin in the ball).
  Vec3 cone_axis = Vec3::Zero();
  double cone_sin = 1, cone_cos = 0;
  const double t_first, t_last;
  // A point (s, t) of the light's plane in world space: the frame's axes may be scaled (a
  // sphere's rows are those of the unit disk).
  const Vec3 s_step, t_step;
  // Below the texel's horizon (and the origin's, which may lie a little below it on a curved
  // surface): no segment from the origin to a point of the light above the horizon gets there.
  const double floor_level;

  std::array<double, LightRows::kMaxRows> lo, hi;
  int r0 = 0, r1 = -1;
  bool covers = false;  // the last region committed covered every row from end to end
  std::array<Vec2, kPieceVertices> projected;
  std::array<Vec3, kPieceVertices> clipped, below;
};

// The box of a polygon's corners.
inline void box_of(const BlockerPolygon& poly, Vec3& lo, Vec3& hi) {
  lo = poly.v[0], hi = poly.v[0];
  for (int k = 1; k < poly.count; ++k) {
    lo = lo.cwiseMin(poly.v[k]);
    hi = hi.cwiseMax(poly.v[k]);
  }
}

inline void Rasteriser::begin(double t_lo, double t_hi) {
  const double r_from = std::ceil((t_lo - rows.first) / rows.pitch);
  const double r_to = std::floor((t_hi - rows.first) / rows.pitch);
  r0 = 0, r1 = -1;
  if (!(r_to >= 0 && r_from <= n - 1 && r_from <= r_to)) return;  // (and not NaN)
  r0 = int(std::max(0.0, r_from)), r1 = int(std::min(double(n - 1), r_to));
  for (int r = r0; r <= r1; ++r) {
    lo[std::size_t(r)] = kInfinity;
    hi[std::size_t(r)] = -kInfinity;
  }
}

inline void Rasteriser::edge(Vec2 p, Vec2 q) {
  if (p.y() == q.y() || r1 < r0) return;
  if (p.y() > q.y()) std::swap(p, q);
  // Clamped in double: an edge far beyond the rows would overflow an int.
  const int a =
      int(std::clamp(std::ceil((p.y() - rows.first) / rows.pitch), double(r0), double(r1 + 1)));
  const int b =
      int(std::clamp(std::floor((q.y() - rows.first) / rows.pitch), double(r0 - 1), double(r1)));
  const double slope = (q.x() - p.x()) / (q.y() - p.y());
  for (int r = a; r <= b; ++r) {
    const double x = p.x() + (rows.first + r * rows.pitch - p.y()) * slope;
    lo[std::size_t(r)] = std::min(lo[std::size_t(r)], x);
    hi[std::size_t(r)] = std::max(hi[std::size_t(r)], x);
  }
}

}  // namespace sb
