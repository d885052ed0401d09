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

#include "methods/backprojection/blocker_rasteriser.h"
#include "occluders/blocker_solids.h"

namespace sb {

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
