// The frame whose axis runs from a light's point towards a target (occluders/projection_frame.h).
#include "occluders/projection_frame.h"

#include <cmath>

namespace sb {

ProjectionFrame frame_towards(const Vec3& origin, const Vec3& target) {
  ProjectionFrame f;
  f.origin = origin;
  const Vec3 d = target - origin;
  f.axis = d.norm() > 0 ? Vec3(d.normalized()) : Vec3(Vec3::UnitZ());
  const Vec3 helper = std::abs(f.axis.z()) < 0.9 ? Vec3::UnitZ() : Vec3::UnitX();
  f.e1 = helper.cross(f.axis).normalized();
  f.e2 = f.axis.cross(f.e1);
  return f;
}

}  // namespace sb
