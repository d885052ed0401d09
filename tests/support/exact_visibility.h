// An exact oracle for one light's visibility at a point, for tests of the back-projection
// estimator: the blocker triangles (each wholly between the point and the light's plane) are
// projected from the point onto the light's plane, and the form factor of the light minus their
// union is summed by inclusion–exclusion over the intersections of the light with every subset of
// them, each a convex polygon whose form factor Lambert's formula gives exactly
// (polygon_form_factor). Exponential in the number of triangles: for a dozen at most.
#pragma once

#include <cmath>
#include <vector>

#include "core/geometry.h"
#include "scene/lights.h"

namespace sb::exact_visibility {

// A convex polygon in the light's plane, in 2D coordinates (u along e1, v along e2).
using Polygon2 = std::vector<Vec2>;

inline double signed_area(const Polygon2& p) {
  double a = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec2& x = p[i];
    const Vec2& y = p[(i + 1) % p.size()];
    a += x.x() * y.y() - x.y() * y.x();
  }
  return 0.5 * a;
}

// The part of `subject` inside the convex polygon `clip` (Sutherland–Hodgman).
inline Polygon2 intersect(Polygon2 subject, Polygon2 clip) {
  if (signed_area(clip) < 0) std::reverse(clip.begin(), clip.end());
  for (std::size_t e = 0; e < clip.size() && !subject.empty(); ++e) {
    const Vec2 a = clip[e], b = clip[(e + 1) % clip.size()];
    const auto side = [&](const Vec2& p) {
      return (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
    };
    Polygon2 out;
    for (std::size_t i = 0; i < subject.size(); ++i) {
      const Vec2& p = subject[i];
      const Vec2& q = subject[(i + 1) % subject.size()];
      const double sp = side(p), sq = side(q);
      if (sp >= 0) out.push_back(p);
      if ((sp > 0 && sq < 0) || (sp < 0 && sq > 0)) out.push_back(p + (q - p) * (sp / (sp - sq)));
    }
    subject = std::move(out);
  }
  return subject;
}

struct PlaneFrame {
  Vec3 origin, e1, e2, normal;
  Vec3 point(const Vec2& p) const { return origin + p.x() * e1 + p.y() * e2; }
};

// The form factor from (y, n) of a polygon of the plane.
inline double form_factor(const PlaneFrame& f, const Polygon2& p, const Vec3& y, const Vec3& n) {
  if (p.size() < 3) return 0;
  std::vector<Vec3> world;
  for (const Vec2& q : p) world.push_back(f.point(q) - y);
  return polygon_form_factor(std::move(world), n);
}

// V = F(light ∖ ∪ shadows) / F(light) at (y, n); `light` is the light's outline in `frame`'s
// plane, each triangle lies between y and that plane.
inline double visibility(const PlaneFrame& frame, const Polygon2& light, const Vec3& y,
                         const Vec3& n, const std::vector<std::array<Vec3, 3>>& triangles) {
  const double h = frame.normal.dot(y - frame.origin);
  std::vector<Polygon2> shadows;
  for (const auto& tri : triangles) {
    Polygon2 s;
    for (const Vec3& p : tri) {
      const double hp = frame.normal.dot(p - frame.origin);
      const Vec3 x = y + (p - y) * (h / (h - hp));
      s.push_back(Vec2(frame.e1.dot(x - frame.origin), frame.e2.dot(x - frame.origin)));
    }
    if (std::abs(signed_area(s)) > 0) shadows.push_back(s);
  }
  const double whole = form_factor(frame, light, y, n);
  if (!(whole > 0)) return 1;
  double hidden = 0;
  const std::size_t count = shadows.size();
  for (std::size_t mask = 1; mask < (std::size_t(1) << count); ++mask) {
    Polygon2 part = light;
    int bits = 0;
    for (std::size_t i = 0; i < count && !part.empty(); ++i)
      if (mask & (std::size_t(1) << i)) {
        part = intersect(part, shadows[i]);
        ++bits;
      }
    if (part.size() < 3) continue;
    hidden += (bits % 2 ? 1.0 : -1.0) * form_factor(frame, part, y, n);
  }
  return std::clamp(1.0 - hidden / whole, 0.0, 1.0);
}

}  // namespace sb::exact_visibility
