// Tangent-plane bounds (tangent_bounds.h).
#include "occluders/tangent_bounds.h"

namespace sb {

TangentBounds tangent_bounds(const std::vector<Vec2>& tangents) {
  TangentBounds b;
  for (const Vec2& t : tangents) b.extend(t);
  return b;
}

TangentBounds tangent_bounds(const ProjectionFrame& frame, const std::vector<Vec3>& points) {
  TangentBounds b;
  for (const Vec3& p : points) b.extend(frame.tangent(p));
  return b;
}

}  // namespace sb
