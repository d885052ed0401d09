// Blocker polygons and convex solids, projected from a texel's ray origin onto the light's rows
// (light_rows.h; the estimator's design is in penumbra_estimator.cpp).
//
// A polygon is cut to the slab between the light's plane and the origin's height (nothing
// beyond either can cut a segment from the origin to the light), projected (a convex polygon
// stays convex), and each row its t-range holds gets the chord between the outline's crossings.
// The part of a polygon within the rays' surface offset of the origin is left out, as the
// reference's rays skip it. A convex solid is taken through its silhouette: the edges between a
// face that faces the origin and one that does not outline its projection, one convex polygon.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "methods/backprojection/light_rows.h"
#include "occluders/blocker_solids.h"

namespace sb {

namespace {

// A shaft polygon cut by up to 8 more lines, and by the light's plane.
constexpr int kPieceVertices = 32;
}  // namespace

Vec3 any_orthogonal(const Vec3& m) {
  const Vec3 a = std::abs(m.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  return (a - a.dot(m) * m).normalized();
}

std::uint64_t BlockedRows::cells_of(double enter, double leave, double a, double b) {
  const double width = leave - enter;
  if (!(width > 0)) return 0;
  const double c0 = std::ceil((a - enter) / width * kCells - 0.5);
  const double c1 = std::floor((b - enter) / width * kCells - 0.5);
  if (c1 < 0 || c0 > kCells - 1 || c0 > c1) return 0;
  const int from = int(std::max(0.0, c0)), to = int(std::min(double(kCells - 1), c1));
  const int count = to - from + 1;
  return (count == kCells ? kAllCells : ((std::uint64_t(1) << count) - 1)) << from;
}

void BlockedRows::add(const LightRows& lights, int r, double a, double b) {
  Row& row = rows[std::size_t(r)];
  if (row.count < kExactIntervals) {
    row.intervals[std::size_t(row.count++)] = {a, b};
    return;
  }
  const double enter = lights.enter[std::size_t(r)], leave = lights.leave[std::size_t(r)];
  if (row.count == kExactIntervals) {  // too many to keep exactly: to cells from here on
    for (const auto& [x, y] : row.intervals) row.cells |= cells_of(enter, leave, x, y);
    ++row.count;
  }
  row.cells |= cells_of(enter, leave, a, b);
}

void BlockedRows::add_cells(const LightRows& lights, int r, std::uint64_t cells) {
  Row& row = rows[std::size_t(r)];
  if (row.count <= kExactIntervals) {
    const double enter = lights.enter[std::size_t(r)], leave = lights.leave[std::size_t(r)];
    for (int k = 0; k < row.count; ++k)
      row.cells |= cells_of(enter, leave, row.intervals[std::size_t(k)].first,
                            row.intervals[std::size_t(k)].second);
    row.count = kExactIntervals + 1;
  }
  row.cells |= cells;
}

namespace {

// A polygon's plane (unit normal `normal`, at signed distance `height` from the origin) near
// the origin: the rays that meet it within the surface offset of the origin skip it there.
struct Skip {
  Vec3 normal;
  double height = 0;
};
struct Span {
  double a, b;
};

// The box of a polygon's corners.
void box_of(const BlockerPolygon& poly, Vec3& lo, Vec3& hi) {
  lo = poly.v[0], hi = poly.v[0];
  for (int k = 1; k < poly.count; ++k) {
    lo = lo.cwiseMin(poly.v[k]);
    hi = hi.cwiseMax(poly.v[k]);
  }
}

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

Rasteriser::Rasteriser(const RasterTarget& target)
    : f(*target.frame),
      rows(*target.rows),
      origin(target.origin),
      position(target.position),
      normal(target.normal),
      light_offset(target.light_offset),
      blocked(*target.blocked),
      out(*target.out),
      blocking(target.blocking),
      nearest(target.out->nearest_blocker),
      n(target.rows->count),
      h_origin(f.normal.dot(origin - f.centre)),
      s_origin(f.s_axis.dot(origin - f.centre)),
      t_origin(f.t_axis.dot(origin - f.centre)),
      h_top(origin_ceiling(h_origin, light_offset)),
      horizon(normal.dot(f.s_axis), normal.dot(f.t_axis), normal.dot(f.centre - position)),
      t_first(rows.first - 0.5 * rows.pitch),
      t_last(rows.first + (n - 0.5) * rows.pitch),
      s_step(f.s_axis / f.s_axis.squaredNorm()),
      t_step(f.t_axis / f.t_axis.squaredNorm()),
      floor_level(std::min(normal.dot(position), normal.dot(origin))) {
  for (int r = 0; r < n; ++r) {
    extent_lo = std::min(extent_lo, rows.enter[std::size_t(r)]);
    extent_hi = std::max(extent_hi, rows.leave[std::size_t(r)]);
  }
  const Vec3 to = f.ball_centre - origin;
  const double distance = to.norm();
  if (f.ball_radius > 0 && distance > f.ball_radius * (1 + 1e-6)) {
    cone_axis = to / distance;
    cone_sin = f.ball_radius / distance;
    cone_cos = std::sqrt(1 - cone_sin * cone_sin);
  }
}

void Rasteriser::begin(double t_lo, double t_hi) {
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

void Rasteriser::edge(Vec2 p, Vec2 q) {
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

// Along row r, the s where the ray from the origin meets the skip's plane within the offset:
// |x − o| < offset at x = o + λ·w, λ = height / (normal·w) > 0, w = L(s) − o, which is
// height²·|w|² < offset²·(normal·w)² (a quadratic in s) with normal·w of height's sign (a
// half-line): at most two intervals, ends possibly infinite.
int Rasteriser::skipped(const Skip& skip, int r, std::array<Span, 2>& out) const {
  const Vec3 w0 = f.centre + (rows.first + r * rows.pitch) * t_step - origin;
  const double h2 = skip.height * skip.height, o2 = light_offset * light_offset;
  const double mw = skip.normal.dot(w0), ms = skip.normal.dot(s_step);
  const double qa = h2 * s_step.squaredNorm() - o2 * ms * ms;
  const double qb = 2 * (h2 * w0.dot(s_step) - o2 * mw * ms);
  const double qc = h2 * w0.squaredNorm() - o2 * mw * mw;
  // Where the quadratic is negative.
  std::array<Span, 2> negative;
  int count = 0;
  const double big = kInfinity;
  if (qa == 0) {
    if (qb > 0)
      negative[std::size_t(count++)] = {-big, -qc / qb};
    else if (qb < 0)
      negative[std::size_t(count++)] = {-qc / qb, big};
    else if (qc < 0)
      negative[std::size_t(count++)] = {-big, big};
  } else {
    const double disc = qb * qb - 4 * qa * qc;
    if (disc > 0) {
      const double root = std::sqrt(disc);
      // Numerically stable roots.
      const double q = -0.5 * (qb + std::copysign(root, qb));
      double x0 = q / qa, x1 = q != 0 ? qc / q : x0;
      if (x0 > x1) std::swap(x0, x1);
      if (qa > 0) {
        negative[std::size_t(count++)] = {x0, x1};
      } else {
        negative[std::size_t(count++)] = {-big, x0};
        negative[std::size_t(count++)] = {x1, big};
      }
    } else if (qa < 0) {
      negative[std::size_t(count++)] = {-big, big};
    }
  }
  // Towards the plane: sign(mw + s·ms) = sign(height).
  Span towards{-big, big};
  const double sign = skip.height > 0 ? 1.0 : -1.0;
  if (ms * sign > 0)
    towards.a = -mw / ms;
  else if (ms * sign < 0)
    towards.b = -mw / ms;
  else if (mw * sign <= 0)
    towards = {big, -big};  // never
  int n_out = 0;
  for (int k = 0; k < count; ++k) {
    const Span c{std::max(negative[std::size_t(k)].a, towards.a),
                 std::min(negative[std::size_t(k)].b, towards.b)};
    if (c.a < c.b) out[std::size_t(n_out++)] = c;
  }
  return n_out;
}

// Each row's chord within the light, less what `skip` leaves out, into the rows.
bool Rasteriser::commit(const Skip* skip) {
  bool reaches = false;
  covers = r0 == 0 && r1 == n - 1;
  for (int r = r0; r <= r1; ++r) {
    covers = covers && lo[std::size_t(r)] <= rows.enter[std::size_t(r)] &&
             hi[std::size_t(r)] >= rows.leave[std::size_t(r)];
    const double a = std::max(lo[std::size_t(r)], rows.enter[std::size_t(r)]);
    const double b = std::min(hi[std::size_t(r)], rows.leave[std::size_t(r)]);
    if (!(a < b)) continue;
    const double t = rows.first + r * rows.pitch;
    std::array<Span, 2> cut;
    const int cuts = skip ? skipped(*skip, r, cut) : 0;
    if (cuts == 2 && cut[1].a < cut[0].a) std::swap(cut[0], cut[1]);
    // [a, b] less the cuts, piece by piece.
    double from = a;
    for (int k = 0; k <= cuts; ++k) {
      const double to = k < cuts ? std::min(cut[std::size_t(k)].a, b) : b;
      if (from < to) {
        reaches = reaches || is_above(Vec2(from, t)) || is_above(Vec2(to, t));
        blocked.add(rows, r, from, to);
      }
      if (k < cuts) {
        if (cut[std::size_t(k)].b > a && cut[std::size_t(k)].a < b) covers = false;
        from = std::max(from, cut[std::size_t(k)].b);
      }
    }
  }
  return reaches;
}

// A convex polygon: its part between the light's plane (clip_height above it) and the origin's
// height, projected from the origin. Whether it reaches the light above the horizon (what lies
// in the texel's shaft, and may hide some of the light).
bool Rasteriser::add(const Vec3* v, int count, const Skip* skip) {
  // Heights over the light's plane: a polygon wholly within the slab is taken as it is.
  std::array<double, kPieceVertices> height;
  bool inside = true, beyond = true, behind = true;
  for (int k = 0; k < count; ++k) {
    height[std::size_t(k)] = f.normal.dot(v[k] - f.centre);
    inside = inside && height[std::size_t(k)] >= f.clip_height && height[std::size_t(k)] <= h_top;
    beyond = beyond && height[std::size_t(k)] < f.clip_height;
    behind = behind && height[std::size_t(k)] > h_top;
  }
  if (beyond || behind) return false;
  const Vec3* poly = v;
  int m = count;
  if (!inside) {
    int k0 = 0;
    for (int k = 0; k < count; ++k) {  // at least clip_height above the light's plane
      const double da = height[std::size_t(k)] - f.clip_height;
      const double db = height[std::size_t((k + 1) % count)] - f.clip_height;
      if (k0 + 2 > kPieceVertices) return false;  // not convex: cannot happen
      if (da >= 0) below[std::size_t(k0++)] = v[k];
      if ((da < 0 && db > 0) || (da > 0 && db < 0))
        below[std::size_t(k0++)] = v[k] + (v[(k + 1) % count] - v[k]) * (da / (da - db));
    }
    m = 0;
    for (int k = 0; k < k0; ++k) {  // below the origin's height
      const Vec3& a = below[std::size_t(k)];
      const Vec3& b = below[std::size_t((k + 1) % k0)];
      const double da = h_top - f.normal.dot(a - f.centre);
      const double db = h_top - f.normal.dot(b - f.centre);
      if (m + 2 > kPieceVertices) return false;
      if (da >= 0) clipped[std::size_t(m++)] = a;
      if ((da < 0 && db > 0) || (da > 0 && db < 0))
        clipped[std::size_t(m++)] = a + (b - a) * (da / (da - db));
    }
    poly = clipped.data();
  }
  if (m < 3) return false;
  double t_lo = kInfinity, t_hi = -kInfinity, s_lo = kInfinity, s_hi = -kInfinity;
  bool above = false, corner_in_light = false;
  for (int k = 0; k < m; ++k) {
    const Vec2 p = project(poly[k]);
    projected[std::size_t(k)] = p;
    t_lo = std::min(t_lo, p.y());
    t_hi = std::max(t_hi, p.y());
    s_lo = std::min(s_lo, p.x());
    s_hi = std::max(s_hi, p.x());
    above = above || is_above(p);
    corner_in_light = corner_in_light || in_light(p);
  }
  // Wholly beside the light, or below the horizon: it hides nothing that arrives.
  if (!above || t_hi < t_first || t_lo > t_last || s_hi < extent_lo || s_lo > extent_hi)
    return false;
  begin(t_lo, t_hi);
  for (int k = 0; k < m; ++k) edge(projected[std::size_t(k)], projected[std::size_t((k + 1) % m)]);
  return commit(skip) || (corner_in_light && !skip);
}

// A polygon of a blocker. A shadow ray ignores what it meets within the surface offset of its
// origin (RayScene): where the polygon comes that near, the rows leave out, exactly, the part
// of each chord whose rays meet its plane within that distance (commit's skip).
bool Rasteriser::add_blocker(const Vec3* v, int count, const Vec3& plane_normal, double gap) {
  bool below_horizon = true;
  for (int k = 0; k < count && below_horizon; ++k) below_horizon = normal.dot(v[k]) < floor_level;
  if (below_horizon) return false;
  const double plane = plane_normal.dot(origin - v[0]);
  if (gap >= light_offset || !(plane * plane < light_offset * light_offset)) return add(v, count);
  // The origin on the polygon's plane: a ray either stays in it or leaves it at once.
  if (plane == 0) return false;
  const Skip skip{plane_normal, -plane};
  return add(v, count, &skip);
}

void Rasteriser::found(bool reaches, double gap, std::uint32_t key) {
  if (!reaches) return;
  nearest = std::min(nearest, std::max(gap, light_offset));
  if (blocking) blocking->push_back(key);
}

void Rasteriser::add_polygon(const BlockerPolygon& poly) {
  Vec3 box_lo, box_hi;
  box_of(poly, box_lo, box_hi);
  const double gap = gap_to(box_lo, box_hi);
  covers = false;
  // It hides none of the light where no ray to the light crosses its plane or comes near it.
  if (beside_plane(poly.v[0], poly.normal) || outside_cone(box_lo, box_hi)) return;
  const bool reaches = add_blocker(poly.v, poly.count, poly.normal, gap);
  // One polygon, clear of the origin, covering the whole light: its umbra, convex as a convex
  // solid's is (a tree crown's facet over a texel in the sun's shadow), so refinement may
  // interpolate between samples in it.
  if (covers && gap >= light_offset)
    out.umbra = poly.source == BlockerPolygon::kKeyIsConvex ? poly.triangle : poly.source;
  found(reaches, gap, poly.triangle);
}

// A convex solid by its silhouette: seen from the origin, the edges between a face that faces
// it and one that does not outline the solid's projection, one convex polygon, whose chord in a
// row runs between the outline's leftmost and rightmost crossings of it.
void Rasteriser::add_solid(const BlockerSolidRef& ref) {
  thread_local std::vector<std::int8_t> front;  // per face: -1 not yet known, else 0 or 1
  thread_local std::vector<Vec2> at;
  thread_local std::vector<std::uint8_t> known;
  const BlockerSolid& solid = *ref.solid;
  const double gap = std::max(gap_to(solid.bounds.lo, solid.bounds.hi), ref.distance);
  if (gap < light_offset) return solid_by_faces(ref, gap);
  // Its box between the light's plane and the origin's height: every corner is, else each
  // silhouette corner must be (a ball resting on the floor reaches below a floor texel's
  // origin, but from most of the floor not on its silhouette: a ray from the origin inside the
  // tangent cone meets the ball at once, however low the ball's bottom).
  bool box_within = true;
  for (int k = 0; k < 8 && box_within; ++k) {
    const Vec3 c = solid.bounds.corner(k);
    const double height = f.normal.dot(c - f.centre);
    box_within = height >= f.clip_height && height <= h_top;
  }
  front.assign(solid.faces.size(), -1);
  known.assign(solid.corners.size(), 0);
  at.resize(solid.corners.size());
  const auto facing = [&](int face) {
    std::int8_t& v = front[std::size_t(face)];
    if (v < 0)
      v = solid.normals[std::size_t(face)].dot(
              origin - solid.corners[std::size_t(solid.faces[std::size_t(face)][0])]) > 0;
    return v;
  };
  double t_lo = kInfinity, t_hi = -kInfinity, s_lo = kInfinity, s_hi = -kInfinity;
  bool corners_within = true;
  const auto corner = [&](int c) -> const Vec2& {
    if (!known[std::size_t(c)]) {
      const Vec3& point = solid.corners[std::size_t(c)];
      if (!box_within) {
        const double height = f.normal.dot(point - f.centre);
        corners_within = corners_within && height >= f.clip_height && height <= h_top;
      }
      at[std::size_t(c)] = project(point);
      known[std::size_t(c)] = 1;
      const Vec2& p = at[std::size_t(c)];
      t_lo = std::min(t_lo, p.y());
      t_hi = std::max(t_hi, p.y());
      s_lo = std::min(s_lo, p.x());
      s_hi = std::max(s_hi, p.x());
    }
    return at[std::size_t(c)];
  };
  const int edge_count = ref.edges ? ref.edge_count : int(solid.edges.size());
  thread_local std::vector<int> silhouette;
  silhouette.clear();
  for (int k = 0; k < edge_count; ++k) {
    const int e = ref.edges ? ref.edges[k] : k;
    const auto& edge_faces = solid.edges[std::size_t(e)];
    if (facing(edge_faces[2]) == facing(edge_faces[3])) continue;
    silhouette.push_back(e);
    corner(edge_faces[0]);
    corner(edge_faces[1]);
  }
  if (!corners_within) return solid_cut_to_slab(ref, gap, silhouette);
  if (silhouette.empty() || t_hi < t_first || t_lo > t_last || s_hi < extent_lo || s_lo > extent_hi)
    return;
  begin(t_lo, t_hi);
  bool corner_in_light = false;
  double edge_distance = kInfinity;  // of the silhouette's edges that cross the light's box
  for (const int e : silhouette) {
    const auto& ends = solid.edges[std::size_t(e)];
    const Vec2& p = at[std::size_t(ends[0])];
    const Vec2& q = at[std::size_t(ends[1])];
    edge(p, q);
    corner_in_light = corner_in_light || in_light(p);
    near_edge(p, q, solid.corners[std::size_t(ends[0])], solid.corners[std::size_t(ends[1])],
              edge_distance);
  }
  settle(ref, commit(nullptr) || corner_in_light, gap, edge_distance);
}

// Face by face (those facing the origin), each cut where it must be: where the silhouette would
// reach past the light's plane or behind the origin, or the origin lies on the solid.
void Rasteriser::solid_by_faces(const BlockerSolidRef& ref, double gap) {
  const BlockerSolid& solid = *ref.solid;
  bool reaches = false;
  if (ref.faces) {
    for (int k = 0; k < ref.face_count; ++k) {
      const BlockerPolygon& face = ref.faces[k];
      if (face.normal.dot(origin - face.v[0]) < 0 && gap > 0) continue;
      reaches = add_blocker(face.v, face.count, face.normal, gap) || reaches;
    }
  } else {
    for (std::size_t k = 0; k < solid.faces.size(); ++k) {
      const Vec3 corners[3] = {solid.corners[std::size_t(solid.faces[k][0])],
                               solid.corners[std::size_t(solid.faces[k][1])],
                               solid.corners[std::size_t(solid.faces[k][2])]};
      if (solid.normals[k].dot(origin - corners[0]) < 0 && gap > 0) continue;
      reaches = add_blocker(corners, 3, solid.normals[k], gap) || reaches;
    }
  }
  found(reaches, gap, ref.key);
}

// A solid reaching past the slab (a crate on the floor a texel is on, a wall up to the ceiling):
// its part within the slab is convex, outlined by its silhouette edges cut to the slab and by
// the cuts of its faces across the slab's planes (those the tile says may cross them, or all): a
// ray inside that outline enters the part.
void Rasteriser::solid_cut_to_slab(const BlockerSolidRef& ref, double gap,
                                   const std::vector<int>& silhouette) {
  const BlockerSolid& solid = *ref.solid;
  thread_local std::vector<std::pair<Vec2, Vec2>> outline;
  outline.clear();
  // How near the outline's segments that cross the light's box lie (as for a silhouette,
  // below): a crate beside a texel on the floor is near, but its outline's edges that hide
  // some of the light may not be.
  double edge_distance = kInfinity;
  const auto add_segment = [&](const Vec3& a, const Vec3& b) {
    const Vec2 p = project(a), q = project(b);
    outline.emplace_back(p, q);
    near_edge(p, q, a, b, edge_distance);
  };
  const auto levels = {f.clip_height, h_top};
  for (const int e : silhouette) {
    Vec3 a = solid.corners[std::size_t(solid.edges[std::size_t(e)][0])];
    Vec3 b = solid.corners[std::size_t(solid.edges[std::size_t(e)][1])];
    double ha = f.normal.dot(a - f.centre), hb = f.normal.dot(b - f.centre);
    if ((ha < f.clip_height && hb < f.clip_height) || (ha > h_top && hb > h_top)) continue;
    for (const double level : levels) {
      if ((ha - level) * (hb - level) >= 0) continue;
      const Vec3 cut = a + (b - a) * ((level - ha) / (hb - ha));
      // Keep the part on the slab's side of this level.
      if ((level == h_top) == (ha > level)) {
        a = cut, ha = level;
      } else {
        b = cut, hb = level;
      }
    }
    add_segment(a, b);
  }
  const int cuts = ref.cut_faces ? ref.cut_count : int(solid.faces.size());
  for (int k = 0; k < cuts; ++k) {
    const auto& face = solid.faces[std::size_t(ref.cut_faces ? ref.cut_faces[k] : k)];
    std::array<double, 3> h;
    for (int j = 0; j < 3; ++j)
      h[std::size_t(j)] = f.normal.dot(solid.corners[std::size_t(face[std::size_t(j)])] - f.centre);
    for (const double level : levels) {
      Vec3 ends[2];
      int found_ends = 0;
      for (int j = 0; j < 3 && found_ends < 2; ++j) {
        const double ha = h[std::size_t(j)], hb = h[std::size_t((j + 1) % 3)];
        if ((ha - level) * (hb - level) >= 0) continue;
        const Vec3& a = solid.corners[std::size_t(face[std::size_t(j)])];
        const Vec3& b = solid.corners[std::size_t(face[std::size_t((j + 1) % 3)])];
        ends[found_ends++] = a + (b - a) * ((level - ha) / (hb - ha));
      }
      if (found_ends == 2) add_segment(ends[0], ends[1]);
    }
  }
  if (outline.empty()) return;
  double lo_t = kInfinity, hi_t = -kInfinity, lo_s = kInfinity, hi_s = -kInfinity;
  bool outline_in_light = false;
  for (const auto& [p, q] : outline)
    for (const Vec2& x : {p, q}) {
      lo_t = std::min(lo_t, x.y()), hi_t = std::max(hi_t, x.y());
      lo_s = std::min(lo_s, x.x()), hi_s = std::max(hi_s, x.x());
      outline_in_light = outline_in_light || in_light(x);
    }
  if (hi_t < t_first || lo_t > t_last || hi_s < extent_lo || lo_s > extent_hi) return;
  begin(lo_t, hi_t);
  for (const auto& [p, q] : outline) edge(p, q);
  const bool reaches = commit(nullptr) || outline_in_light;
  settle(ref, reaches, gap, edge_distance);
}

// An outline edge a → b, projected p → q, that crosses the light's box: how near the origin it
// passes, into `distance` (its nearest, not the solid's: a ball's contact with the floor is not
// where V changes fastest here).
void Rasteriser::near_edge(const Vec2& p, const Vec2& q, const Vec3& a, const Vec3& b,
                           double& distance) const {
  if (std::max(p.y(), q.y()) < t_first || std::min(p.y(), q.y()) > t_last ||
      std::max(p.x(), q.x()) < extent_lo || std::min(p.x(), q.x()) > extent_hi)
    return;
  const Vec3 ab = b - a;
  const double along =
      std::clamp((origin - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
  distance = std::min(distance, (a + along * ab - origin).norm());
}

// The solid rasterised: whether it reaches the light, and its umbra where it covers it.
void Rasteriser::settle(const BlockerSolidRef& ref, bool reaches, double gap,
                        double edge_distance) {
  if (covers) {
    out.umbra = ref.key;
    found(reaches, gap, ref.key);
  } else {
    found(reaches, std::max(gap, std::isfinite(edge_distance) ? edge_distance : gap), ref.key);
  }
}

}  // namespace

bool nearest_hide_all(const RasterTarget& target, const Blockers& blockers, std::size_t fewest,
                      std::size_t budget) {
  if (!blockers.polygons || blockers.polygons->size() <= fewest) return false;
  const std::vector<BlockerPolygon>& polygons = *blockers.polygons;
  // The attempt's own sample: the target's is written only where it succeeds.
  PenumbraSample scratch;
  RasterTarget attempt = target;
  attempt.out = &scratch;
  attempt.blocking = nullptr;
  Rasteriser rasteriser(attempt);
  if (!rasteriser.usable()) return false;
  // The polygons in the shaft (add_polygon's first tests), by their boxes' distance.
  thread_local std::vector<std::pair<double, std::uint32_t>> in_shaft;
  in_shaft.clear();
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    const BlockerPolygon& poly = polygons[i];
    Vec3 box_lo, box_hi;
    box_of(poly, box_lo, box_hi);
    if (rasteriser.beside_plane(poly.v[0], poly.normal) || rasteriser.outside_cone(box_lo, box_hi))
      continue;
    in_shaft.emplace_back(rasteriser.gap_to(box_lo, box_hi), std::uint32_t(i));
  }
  if (in_shaft.size() <= fewest) return false;
  budget = std::min(budget, in_shaft.size());
  std::partial_sort(in_shaft.begin(), in_shaft.begin() + std::ptrdiff_t(budget), in_shaft.end());
  // Nearest first, the rows checked after 2, 4, 6, 9, 13, 19, … of them.
  bool hidden = false;
  for (std::size_t k = 0, check = 2; k < budget && !hidden; ++k) {
    rasteriser.add_polygon(polygons[in_shaft[k].second]);
    if (k + 1 == check || k + 1 == budget) {
      hidden = every_row_hidden(*target.rows, *target.blocked);
      check += std::max<std::size_t>(2, check / 2);
    }
  }
  if (!hidden) {
    target.blocked->clear(target.rows->count);  // for the whole pass
    return false;
  }
  // What every blocker of the shaft may hide, bounded as its rasterisation would bound it: at
  // its distance (a solid's as add_solid takes it; a dense mesh's outline's bounds the
  // triangles it takes apart too), by its key.
  const auto bound = [&](double gap, std::uint32_t key) {
    target.out->nearest_blocker =
        std::min(target.out->nearest_blocker, std::max(gap, target.light_offset));
    if (target.blocking) target.blocking->push_back(key);
  };
  for (const auto& [gap, i] : in_shaft) bound(gap, polygons[i].triangle);
  if (blockers.solids)
    for (const BlockerSolidRef& ref : *blockers.solids)
      bound(std::max(rasteriser.gap_to(ref.solid->bounds.lo, ref.solid->bounds.hi), ref.distance),
            ref.key);
  if (blockers.outlines)
    for (const BlockerOutline& outline : *blockers.outlines) bound(outline.distance, outline.key);
  return true;
}

void rasterise_polygons_and_solids(const RasterTarget& target,
                                   const std::vector<BlockerPolygon>& polygons,
                                   const std::vector<BlockerSolidRef>& solids) {
  Rasteriser rasteriser(target);
  if (!rasteriser.usable()) return;  // the origin is on or behind the light
  for (const BlockerPolygon& poly : polygons) rasteriser.add_polygon(poly);
  for (const BlockerSolidRef& ref : solids) rasteriser.add_solid(ref);
}

}  // namespace sb
