// Fold detection for flattened charts (chart_folds.h): border edges crossing in UV, found by a
// sweep over their u extents, told apart from a crack's lips by their distance in space; and
// triangles overlapping in UV, by the separating axis theorem over their edge normals, found by
// the same sweep.
#include "texels/chart_folds.h"

#include <algorithm>
#include <cmath>

namespace sb {

namespace {

// Two border edges closer in space than this fraction of their length are a crack's two lips.
constexpr double kCrackFraction = 1e-3;

// Whether two segments cross or touch, other than at an end point they share.
bool segments_meet(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  auto orient = [](const Vec2& p, const Vec2& q, const Vec2& r) {
    const double v = (q - p).x() * (r - p).y() - (q - p).y() * (r - p).x();
    return (v > 0) - (v < 0);
  };
  const int o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
  if (o1 != o2 && o3 != o4) return true;
  auto on = [](const Vec2& p, const Vec2& q, const Vec2& r) {  // r on segment pq, collinear
    return std::min(p.x(), q.x()) <= r.x() && r.x() <= std::max(p.x(), q.x()) &&
           std::min(p.y(), q.y()) <= r.y() && r.y() <= std::max(p.y(), q.y());
  };
  return (o1 == 0 && on(a, b, c)) || (o2 == 0 && on(a, b, d)) || (o3 == 0 && on(c, d, a)) ||
         (o4 == 0 && on(c, d, b));
}

// The distance between segments ab and cd in space.
double segment_distance(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3 u = b - a, v = d - c, w = a - c;
  const double uu = u.dot(u), uv = u.dot(v), vv = v.dot(v), uw = u.dot(w), vw = v.dot(w);
  const double det = uu * vv - uv * uv;
  double s = det > 1e-300 ? std::clamp((uv * vw - vv * uw) / det, 0.0, 1.0) : 0.0;
  double t = vv > 0 ? std::clamp((uv * s + vw) / vv, 0.0, 1.0) : 0.0;
  s = uu > 0 ? std::clamp((uv * t - uw) / uu, 0.0, 1.0) : 0.0;
  return (w + s * u - t * v).norm();
}

}  // namespace

std::optional<ChartFold> border_crosses(const std::vector<Vec2>& uv,
                                        const std::vector<Vec3>& positions,
                                        const std::vector<std::array<int, 2>>& border) {
  std::vector<std::size_t> order(border.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  auto lo = [&](std::size_t e) {
    return std::min(uv[std::size_t(border[e][0])].x(), uv[std::size_t(border[e][1])].x());
  };
  auto hi = [&](std::size_t e) {
    return std::max(uv[std::size_t(border[e][0])].x(), uv[std::size_t(border[e][1])].x());
  };
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return lo(a) < lo(b); });
  std::vector<std::size_t> active;
  for (const std::size_t e : order) {
    const double x = lo(e);
    std::erase_if(active, [&](std::size_t a) { return hi(a) < x; });
    const auto& [e0, e1] = border[e];
    for (const std::size_t a : active) {
      const auto& [a0, a1] = border[a];
      if (a0 == e0 || a0 == e1 || a1 == e0 || a1 == e1) continue;  // neighbours share an end
      if (!segments_meet(uv[std::size_t(e0)], uv[std::size_t(e1)], uv[std::size_t(a0)],
                         uv[std::size_t(a1)]))
        continue;
      const Vec3 &p0 = positions[std::size_t(e0)], &p1 = positions[std::size_t(e1)];
      const Vec3 &q0 = positions[std::size_t(a0)], &q1 = positions[std::size_t(a1)];
      const double length = std::max((p1 - p0).norm(), (q1 - q0).norm());
      if (segment_distance(p0, p1, q0, q1) > kCrackFraction * length)
        return ChartFold{(p0 + p1) / 2, (q0 + q1) / 2};
    }
    active.push_back(e);
  }
  return std::nullopt;
}

std::optional<std::array<std::size_t, 2>> overlapping_triangles(const ChartUvs& uv) {
  struct Extent {
    double lo, hi;
  };
  const auto extent = [&](std::size_t t, const Vec2& axis) {
    Extent e{1e300, -1e300};
    for (const Vec2& p : uv[t])
      e.lo = std::min(e.lo, axis.dot(p)), e.hi = std::max(e.hi, axis.dot(p));
    return e;
  };
  const auto longest = [&](std::size_t t) {
    return std::max(
        {(uv[t][1] - uv[t][0]).norm(), (uv[t][2] - uv[t][1]).norm(), (uv[t][0] - uv[t][2]).norm()});
  };
  const auto overlap = [&](std::size_t a, std::size_t b) {
    const double tolerance = 1e-7 * std::max(longest(a), longest(b));
    for (const std::size_t t : {a, b})
      for (int k = 0; k < 3; ++k) {
        const Vec2 edge = uv[t][std::size_t((k + 1) % 3)] - uv[t][std::size_t(k)];
        const double length = edge.norm();
        if (!(length > 0)) continue;
        const Vec2 axis(-edge.y() / length, edge.x() / length);
        const Extent ea = extent(a, axis), eb = extent(b, axis);
        if (std::min(ea.hi, eb.hi) - std::max(ea.lo, eb.lo) <= tolerance) return false;
      }
    return true;
  };
  std::vector<std::size_t> order(uv.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  const Vec2 x_axis(1, 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return extent(a, x_axis).lo < extent(b, x_axis).lo;
  });
  std::vector<std::size_t> active;
  for (const std::size_t t : order) {
    const double x = extent(t, x_axis).lo;
    std::erase_if(active, [&](std::size_t a) { return extent(a, x_axis).hi < x; });
    for (const std::size_t a : active)
      if (overlap(a, t)) return std::array<std::size_t, 2>{a, t};
    active.push_back(t);
  }
  return std::nullopt;
}

}  // namespace sb
