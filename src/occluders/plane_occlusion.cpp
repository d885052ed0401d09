// plane_hides_light (plane_occlusion.h): the blocker triangles of one plane, together, between a
// box of points and a light.
#include "occluders/plane_occlusion.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace sb {

namespace {

// Planes tried per box: the first few the ray from its centre to the light's centre crosses (a
// wall's two faces, and one more).
constexpr int kPlanesTried = 3;
// A triangle lies in the plane where each corner lies within this of it, metres, plus a
// ten-millionth of the corner's distance from the origin (a level's float coordinates).
constexpr double kInPlane = 1e-5;
constexpr double kInPlaneRelative = 1e-7;
// What is left of the crossings' polygon, as a share of its area, under which it counts as
// covered: slivers along the triangles' shared edges, from rounding.
constexpr double kUncovered = 1e-7;
// The most convex pieces the subtraction may hold before it gives up (a wall of many small
// triangles over a hole).
constexpr std::size_t kMaxPieces = 256;

using Polygon = std::vector<Vec2>;  // convex, counter-clockwise

double area(const Polygon& p) {
  double twice = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec2& a = p[i];
    const Vec2& b = p[(i + 1) % p.size()];
    twice += a.x() * b.y() - a.y() * b.x();
  }
  return 0.5 * twice;
}

// 2 × the signed area of (a, b, p): > 0 where p lies left of a → b.
double side(const Vec2& a, const Vec2& b, const Vec2& p) {
  return (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
}

// The part of `p` on the left of a → b (`left`) or on its right, into `out`.
void clip(const Polygon& p, const Vec2& a, const Vec2& b, bool left, Polygon& out) {
  out.clear();
  const auto inside = [&](double s) { return left ? s >= 0 : s <= 0; };
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec2& u = p[i];
    const Vec2& v = p[(i + 1) % p.size()];
    const double su = side(a, b, u), sv = side(a, b, v);
    if (inside(su)) out.push_back(u);
    if ((su > 0 && sv < 0) || (su < 0 && sv > 0)) out.push_back(u + (v - u) * (su / (su - sv)));
  }
}

// Removes from `points` those strictly inside the polygon of their extremes in 8 directions
// (Akl and Toussaint's filter): none of them is a corner of their hull, and sorting them is the
// hull's main cost (a box's 4 or 8 corners to a sphere light's 8 give 32 or 64 points, about 10
// of them corners).
void discard_inside(std::vector<Vec2>& points) {
  if (points.size() < 16) return;
  // The directions counter-clockwise; the point farthest along each.
  static constexpr std::array<std::array<double, 2>, 8> kDirections = {
      {{1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0}, {-1, -1}, {0, -1}, {1, -1}}};
  std::array<Vec2, 8> extreme;
  std::array<double, 8> best;
  best.fill(-std::numeric_limits<double>::infinity());
  for (const Vec2& p : points)
    for (std::size_t i = 0; i < 8; ++i) {
      const double along = kDirections[i][0] * p.x() + kDirections[i][1] * p.y();
      if (along > best[i]) best[i] = along, extreme[i] = p;
    }
  std::array<Vec2, 8> corners;
  std::size_t count = 0;
  for (const Vec2& e : extreme)
    if (count == 0 || e != corners[count - 1]) corners[count++] = e;
  while (count > 1 && corners[count - 1] == corners[0]) --count;
  if (count < 3) return;
  const auto inside = [&](const Vec2& p) {
    for (std::size_t i = 0; i < count; ++i)
      if (!(side(corners[i], corners[(i + 1) % count], p) > 0)) return false;
    return true;
  };
  points.erase(std::remove_if(points.begin(), points.end(), inside), points.end());
}

// The convex hull of `points` (sorted in place), counter-clockwise (Andrew's monotone chain).
void convex_hull(std::vector<Vec2>& points, Polygon& hull) {
  discard_inside(points);
  std::sort(points.begin(), points.end(), [](const Vec2& a, const Vec2& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  hull.clear();
  if (points.size() < 3) return;
  hull.resize(2 * points.size());
  std::size_t k = 0;
  for (const Vec2& p : points) {
    while (k >= 2 && side(hull[k - 2], hull[k - 1], p) <= 0) --k;
    hull[k++] = p;
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && side(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
}

// The corners of a polytope that holds every point a shadow ray may end at: a rectangle's or
// polygon's own, the square around a disk in its plane, the cube around a sphere. None for the
// other shapes.
void light_corners(const Light& light, std::vector<Vec3>& corners) {
  corners.clear();
  std::array<Vec3, 4> outline;
  switch (light.shape()) {
    case LightShape::rectangle:
    case LightShape::polygon: {
      const int count = light.outline(outline);
      corners.assign(outline.begin(), outline.begin() + count);
      break;
    }
    case LightShape::disk: {
      const double r = light.desc().radius;
      for (const double a : {-r, r})
        for (const double b : {-r, r})
          corners.push_back(light.centre() + a * light.right() + b * light.up());
      break;
    }
    case LightShape::sphere: {
      Bounds3 box;
      box.extend(light.centre() - Vec3::Constant(light.desc().radius));
      box.extend(light.centre() + Vec3::Constant(light.desc().radius));
      for (int k = 0; k < 8; ++k) corners.push_back(box.corner(k));
      break;
    }
    case LightShape::mesh:
    case LightShape::sky:
      break;
  }
}

// A plane n·x = d, with a frame (u, v) in it.
struct PlaneFrame {
  Vec3 n;
  double d;
  Vec3 u, v;
  // A point's coordinates in the plane's frame.
  Vec2 in_plane(const Vec3& p) const { return Vec2(u.dot(p), v.dot(p)); }
};

// Whether the box lies wholly on one side of the plane n·x = d and the light's ends wholly on the
// other, each clear of it by more than `offset`; the heights above it into `h_box` and `h_end`.
bool box_and_light_apart(const Vec3& n, double d, const std::array<Vec3, 8>& box,
                         const std::vector<Vec3>& ends, double offset, std::array<double, 8>& h_box,
                         std::vector<double>& h_end) {
  // The box wholly on one side, the light wholly on the other, each clear of the plane by more
  // than a shadow ray skips.
  for (std::size_t k = 0; k < 8; ++k) h_box[k] = n.dot(box[k]) - d;
  const double sign = h_box[0] > 0 ? 1.0 : -1.0;
  for (const double h : h_box)
    if (!(sign * h > offset)) return false;
  h_end.resize(ends.size());
  for (std::size_t k = 0; k < ends.size(); ++k) {
    h_end[k] = n.dot(ends[k]) - d;
    if (!(-sign * h_end[k] > offset)) return false;
  }
  return true;
}

// The convex hull, in the plane's frame, of the points where the segments from the box's corners
// to the light's ends cross the plane (their heights above it `h_box` and `h_end`).
void crossings_hull(const PlaneFrame& plane, const std::array<Vec3, 8>& box,
                    const std::vector<Vec3>& ends, const std::array<double, 8>& h_box,
                    const std::vector<double>& h_end, Polygon& hull) {
  thread_local std::vector<Vec2> crossings;
  crossings.clear();
  for (std::size_t a = 0; a < 8; ++a) {
    // A corner equal to an earlier one (a box flat in an axis: a patch of floor or wall) adds
    // the same crossings again.
    if (std::find(box.begin(), box.begin() + std::ptrdiff_t(a), box[a]) !=
        box.begin() + std::ptrdiff_t(a))
      continue;
    for (std::size_t b = 0; b < ends.size(); ++b)
      crossings.push_back(
          plane.in_plane((-h_end[b] * box[a] + h_box[a] * ends[b]) / (h_box[a] - h_end[b])));
  }
  convex_hull(crossings, hull);
}

// The blocker triangles lying in the plane whose boxes meet the box (lo, hi) of the polygon
// `hull`, counter-clockwise in the plane's frame, into `triangles`.
void triangles_in_plane(const ShaftCuller& culler, const PlaneFrame& plane, const Polygon& hull,
                        const Vec2& lo, const Vec2& hi,
                        std::vector<std::array<Vec2, 3>>& triangles) {
  const Vec3& n = plane.n;
  const double d = plane.d;
  // The blocker triangles whose boxes meet the polygon's (in space, as thick as a triangle may
  // stand off the plane and count as in it), then those in the plane over the polygon's box,
  // counter-clockwise in its frame.
  Bounds3 slab;
  for (const Vec2& p : hull) slab.extend(Vec3(d * n + p.x() * plane.u + p.y() * plane.v));
  const double thick = kInPlane + kInPlaneRelative * std::max(slab.lo.norm(), slab.hi.norm());
  slab.lo -= Vec3::Constant(thick), slab.hi += Vec3::Constant(thick);
  thread_local std::vector<std::uint32_t> near;
  culler.triangles_in_box(slab, near);
  triangles.clear();
  for (const std::uint32_t i : near) {
    const Vec3* c = culler.triangle_corners(i);
    bool in = true;
    for (int k = 0; k < 3 && in; ++k)
      in = std::abs(n.dot(c[k]) - d) <= kInPlane + kInPlaneRelative * c[k].norm();
    if (!in) continue;
    std::array<Vec2, 3> t = {plane.in_plane(c[0]), plane.in_plane(c[1]), plane.in_plane(c[2])};
    const Vec2 t_lo = t[0].cwiseMin(t[1]).cwiseMin(t[2]), t_hi = t[0].cwiseMax(t[1]).cwiseMax(t[2]);
    if ((t_hi.array() < lo.array()).any() || (t_lo.array() > hi.array()).any()) continue;
    const double twice = side(t[0], t[1], t[2]);
    if (twice == 0) continue;
    if (twice < 0) std::swap(t[1], t[2]);
    triangles.push_back(t);
  }
}

// Whether the triangles can cover a polygon of area `hull_area` and box (lo, hi) at all, from
// what each covers of the box and the slivers the subtraction may drop.
bool may_cover(const std::vector<std::array<Vec2, 3>>& triangles, const Vec2& lo, const Vec2& hi,
               double hull_area, double negligible) {
  const std::array<Vec2, 4> frame = {lo, Vec2(hi.x(), lo.y()), hi, Vec2(lo.x(), hi.y())};
  thread_local Polygon part, cut;
  double reach = 0;
  for (const auto& t : triangles) {
    part.assign(t.begin(), t.end());
    for (std::size_t e = 0; e < 4 && part.size() >= 3; ++e) {
      clip(part, frame[e], frame[(e + 1) % 4], true, cut);
      part.swap(cut);
    }
    if (part.size() >= 3) reach += area(part);
  }
  const double dropped = 4.0 * double(kMaxPieces) * double(triangles.size()) * negligible;
  if (reach + dropped < hull_area * (1 - 1e-9)) return false;
  return true;
}

// Whether subtracting the triangles (sorted here, the largest first) from the polygon `hull`
// leaves nothing but pieces under `negligible`; false too where the pieces grow too many.
bool subtract_covers(std::vector<std::array<Vec2, 3>>& triangles, const Polygon& hull,
                     double negligible) {
  // The largest first: a wall's big triangles leave the fewest pieces.
  std::sort(triangles.begin(), triangles.end(), [](const auto& a, const auto& b) {
    return side(a[0], a[1], a[2]) > side(b[0], b[1], b[2]);
  });
  // The pieces left, each with its box; a piece the triangle's box misses passes on whole.
  struct Piece {
    Polygon polygon;
    Vec2 lo, hi;
  };
  const auto boxed = [](const Polygon& p) {
    Piece piece{p, p[0], p[0]};
    for (const Vec2& q : p) piece.lo = piece.lo.cwiseMin(q), piece.hi = piece.hi.cwiseMax(q);
    return piece;
  };
  thread_local std::vector<Piece> pieces, next;
  thread_local Polygon rest, outside, inside;
  pieces.clear();
  pieces.push_back(boxed(hull));
  for (const auto& t : triangles) {
    const Vec2 t_lo = t[0].cwiseMin(t[1]).cwiseMin(t[2]), t_hi = t[0].cwiseMax(t[1]).cwiseMax(t[2]);
    next.clear();
    for (Piece& piece : pieces) {
      if ((t_hi.array() < piece.lo.array()).any() || (t_lo.array() > piece.hi.array()).any()) {
        next.push_back(std::move(piece));
        continue;
      }
      // The piece less the triangle: its parts outside each edge, in turn, of what is left.
      rest = piece.polygon;
      for (int e = 0; e < 3 && !rest.empty(); ++e) {
        const Vec2& a = t[std::size_t(e)];
        const Vec2& b = t[std::size_t((e + 1) % 3)];
        clip(rest, a, b, false, outside);
        if (outside.size() >= 3 && area(outside) > negligible) next.push_back(boxed(outside));
        clip(rest, a, b, true, inside);
        rest.swap(inside);
        if (rest.size() < 3 || area(rest) <= negligible) rest.clear();
      }
    }
    pieces.swap(next);
    if (pieces.empty()) return true;
    if (pieces.size() > kMaxPieces) return false;
  }
  return false;
}

// Whether the triangles lying in the plane of triangle `seed` cover every crossing of the plane
// by a segment from the box's corners `box` to the light's `ends`.
bool plane_covers(const ShaftCuller& culler, std::uint32_t seed, const std::array<Vec3, 8>& box,
                  const std::vector<Vec3>& ends, double offset) {
  const Vec3 n = culler.triangle_normal(seed);
  const double d = n.dot(culler.triangle_corners(seed)[0]);
  std::array<double, 8> h_box;
  thread_local std::vector<double> h_end;
  if (!box_and_light_apart(n, d, box, ends, offset, h_box, h_end)) return false;
  // The plane's frame, and the crossings' polygon in it.
  const Vec3 u = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
  const Vec3 v = n.cross(u);
  const PlaneFrame plane{n, d, u, v};
  thread_local Polygon hull;
  crossings_hull(plane, box, ends, h_box, h_end, hull);
  const double hull_area = hull.empty() ? 0.0 : area(hull);
  if (!(hull_area > 0)) return false;
  Vec2 lo = hull[0], hi = hull[0];
  for (const Vec2& p : hull) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  thread_local std::vector<std::array<Vec2, 3>> triangles;
  triangles_in_plane(culler, plane, hull, lo, hi, triangles);
  // Whether they can cover it at all: its area is what they cover of it, what is left, and the
  // slivers dropped (each under `negligible`, at most 4 per piece and triangle, below), and a
  // triangle covers no more of it than of its box. Most polygons a plane fails to cover (a
  // pillar's face, a floor's edge) fail here, before the subtraction.
  const double negligible = kUncovered * hull_area;
  if (!may_cover(triangles, lo, hi, hull_area, negligible)) return false;
  return subtract_covers(triangles, hull, negligible);
}

}  // namespace

bool plane_hides_light(const ShaftCuller& culler, const RayScene& rays, const Light& light,
                       const Bounds3& origins, const RayScene::Hit* first) {
  if (origins.empty()) return false;
  thread_local std::vector<Vec3> ends;
  light_corners(light, ends);
  if (ends.empty()) return false;
  std::array<Vec3, 8> box;
  for (int k = 0; k < 8; ++k) box[std::size_t(k)] = origins.corner(k);
  const double offset = rays.surface_offset();
  // Along the ray from the box's centre to the light's centre, plane after plane.
  Vec3 from = origins.centre();
  const Vec3 to = light.centre();
  std::array<std::pair<Vec3, double>, kPlanesTried> tried;  // (unit normal, offset)
  int planes = 0;
  for (int k = 0; k < kPlanesTried; ++k) {
    const RayScene::Hit hit = k == 0 && first ? *first : rays.first_hit_face(from, to - from, 1.0);
    if (hit.face < 0) return false;  // nothing more between the centres
    const std::uint32_t triangle = culler.triangle_of_face(hit.face);
    const Vec3& n = culler.triangle_normal(triangle);
    const double d = n.dot(culler.triangle_corners(triangle)[0]);
    // A plane tried already (a wall's coplanar triangle further on) is not tried again.
    const bool again = std::any_of(tried.begin(), tried.begin() + planes, [&](const auto& p) {
      const double cosine = p.first.dot(n);
      return std::abs(cosine) > 1 - 1e-9 && std::abs(p.second - (cosine > 0 ? d : -d)) < kInPlane;
    });
    if (!again) {
      if (plane_covers(culler, triangle, box, ends, offset)) return true;
      tried[std::size_t(planes++)] = {n, d};
    }
    // On past the hit.
    from = from + (to - from) * std::min(1.0, hit.t + 1e-6);
  }
  return false;
}

}  // namespace sb
