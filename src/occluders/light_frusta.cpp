// The frusta of a light (light_frusta.h).
#include "occluders/light_frusta.h"

#include <cassert>
#include <cmath>
#include <numbers>

namespace sb {

double cosine_from_axis(const ProjectionFrame& frame, const Vec3& p) {
  const Vec3 d = p - frame.origin;
  const double len = d.norm();
  return len > 0 ? d.dot(frame.axis) / len : 1.0;
}

double max_frustum_half_angle_cosine() {
  return std::cos(kMaxFrustumHalfAngleDeg * std::numbers::pi / 180.0);
}

int cube_face(const Vec3& centre, const Vec3& p) {
  const Vec3 d = p - centre;
  int axis;
  d.cwiseAbs().maxCoeff(&axis);
  return 2 * axis + (d[axis] < 0 ? 1 : 0);
}

ProjectionFrame cube_face_frame(const Vec3& centre, int face) {
  assert(face >= 0 && face < kCubeFaces);
  Vec3 axis = Vec3::Zero();
  axis[face / 2] = face % 2 ? -1.0 : 1.0;
  return frame_towards(centre, centre + axis);
}

const char* cube_face_name(int face) {
  static const char* const kNames[kCubeFaces] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  assert(face >= 0 && face < kCubeFaces);
  return kNames[face];
}

}  // namespace sb
