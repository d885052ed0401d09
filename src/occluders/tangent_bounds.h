// Bounds of points on a ProjectionFrame's tangent plane: the axis-aligned box, in tangent
// coordinates, of points seen from the frame's origin (their central projections onto the plane
// at unit depth). The convolution planner bounds receiver texels, blocker polygons and convex
// hulls with it; the shadow map sizes its square frustum by it. It sits in occluders beside
// projection_frame.h, which defines the tangent coordinates, so both methods may include it.
#pragma once

#include <limits>
#include <vector>

#include "core/geometry.h"
#include "occluders/projection_frame.h"

namespace sb {

struct TangentBounds {
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity());
  Vec2 hi = Vec2::Constant(-std::numeric_limits<double>::infinity());

  void extend(const Vec2& tangent) {
    lo = lo.cwiseMin(tangent);
    hi = hi.cwiseMax(tangent);
  }
  void extend(const TangentBounds& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  bool empty() const { return (hi.array() < lo.array()).any(); }
  Vec2 centre() const { return 0.5 * (lo + hi); }
  // The largest |coordinate| of the points: the half side, tangent units, of the smallest square
  // centred on the frame's axis that holds them; 0 when empty.
  double widest() const { return empty() ? 0.0 : lo.cwiseAbs().cwiseMax(hi.cwiseAbs()).maxCoeff(); }
};

// The bounds of tangent coordinates already projected.
TangentBounds tangent_bounds(const std::vector<Vec2>& tangents);

// The bounds of `points`' tangent coordinates in `frame`; every point must lie at positive depth.
TangentBounds tangent_bounds(const ProjectionFrame& frame, const std::vector<Vec3>& points);

}  // namespace sb
