// The frusta from a light's centre that cover a set of receiver points (docs/design.md §3: the
// projection direction D is the axis of the frustum from the light to the receiver). One frustum
// towards the middle of the points' bounding box serves them when every point lies within
// kMaxFrustumHalfAngleDeg of its axis; otherwise (a light beside or among its receiver) the six
// faces of a cube around the light do, each point going to the face of its dominant direction.
// The convolution planner (methods/convolution/plan_frames.cpp) and the shadow maps
// (methods/shadow_map.cpp) split alike. It sits in occluders beside projection_frame.h,
// whose frames it makes, so both methods may include it.
#pragma once

#include <algorithm>
#include <optional>

#include "core/geometry.h"
#include "occluders/projection_frame.h"

namespace sb {

// The widest angle, from the light's centre, between a receiver point and its frustum's axis
// that one frustum serves; beyond it the tangent plane stretches without bound (tan 60° = 1.7).
inline constexpr double kMaxFrustumHalfAngleDeg = 60.0;

// The cosine of the angle between frame.axis and the direction from frame.origin to p; 1 for p
// at the origin.
double cosine_from_axis(const ProjectionFrame& frame, const Vec3& p);

// cos(kMaxFrustumHalfAngleDeg).
double max_frustum_half_angle_cosine();

// The frame from `centre` towards the middle of the bounding box of `points` (a range of Vec3,
// read twice), when every point lies within kMaxFrustumHalfAngleDeg of its axis; none otherwise.
template <class Points>
std::optional<ProjectionFrame> central_frustum(const Vec3& centre, const Points& points) {
  Bounds3 bounds;
  for (const Vec3& p : points) bounds.extend(p);
  const ProjectionFrame central = frame_towards(centre, bounds.centre());
  double widest = 1.0;  // the smallest cosine between a point and the axis
  for (const Vec3& p : points) widest = std::min(widest, cosine_from_axis(central, p));
  if (widest >= max_frustum_half_angle_cosine()) return central;
  return std::nullopt;
}

// The cube faces around the light, in the order +x, −x, +y, −y, +z, −z.
inline constexpr int kCubeFaces = 6;

// The face of the cube around `centre` that holds p: that of the largest coordinate of p − centre.
int cube_face(const Vec3& centre, const Vec3& p);

// The frame of cube face `face` (0 … 5), from `centre` along its axis.
ProjectionFrame cube_face_frame(const Vec3& centre, int face);

// "+x", "-x", "+y", "-y", "+z" or "-z".
const char* cube_face_name(int face);

}  // namespace sb
