// A projection frame from a light: a direction D with two axes across it, the tangent coordinates
// the convolution's images and the shadow maps live in (docs/design.md §3), and a range of depths
// along D. The convolution's virtual configuration (methods/convolution/virtual_configuration.h)
// and the baselines' shadow maps (methods/shadow_map.h) both project through it.
#pragma once

#include <algorithm>
#include <limits>

#include "core/geometry.h"

namespace sb {

struct DepthRange {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void extend(double d) {
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  bool empty() const { return hi < lo; }
  double mid() const { return 0.5 * (lo + hi); }
};

// A projection direction D from the light's centre with two unit axes across it. Images live in
// "tangent" coordinates: a point p maps to ((p − o)·e1, (p − o)·e2) / ((p − o)·D), its central
// projection onto the plane at unit depth; the blocker plane at depth d is that plane scaled by d.
struct ProjectionFrame {
  Vec3 origin = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
  Vec3 e1 = Vec3::UnitX(), e2 = Vec3::UnitY();

  double depth(const Vec3& p) const { return (p - origin).dot(axis); }
  // Tangent coordinates of p (depth must be positive).
  Vec2 tangent(const Vec3& p) const {
    const Vec3 v = p - origin;
    const double inv = 1.0 / v.dot(axis);
    return Vec2(v.dot(e1) * inv, v.dot(e2) * inv);
  }
};

// The frame whose axis runs from `origin` towards `target`.
ProjectionFrame frame_towards(const Vec3& origin, const Vec3& target);

}  // namespace sb
