// Proofs that one blocker hides all of a light from a point (umbra_proofs.h).
#include "methods/backprojection/umbra_proofs.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace sb {

namespace {

// The unit normal of the plane through `origin` and the triangle's edge k (corners k, k + 1),
// turned towards its third corner: false where the edge and the origin are collinear.
bool inward_edge_plane(const Vec3* corners, int k, const Vec3& origin, Vec3& n) {
  const Vec3 a = corners[k] - origin, b = corners[(k + 1) % 3] - origin;
  n = a.cross(b);
  const double norm = n.norm();
  if (!(norm > 0)) return false;
  n /= norm;
  if (n.dot(corners[(k + 2) % 3] - origin) < 0) n = -n;
  return true;
}

// triangle_hides_light for a sphere: every segment from the origin to the ball crosses the
// triangle exactly where the ball lies beyond the triangle's plane (seen from the origin) and
// inside the three planes through the origin and each edge, each by the radius (distances to a
// plane are the ball's, exactly). Clear of the origin and of the light's surface by the offset
// a shadow ray skips at each end.
bool triangle_hides_sphere(const Light& light, const Vec3* corners, const Vec3& origin,
                           double light_offset) {
  const Vec3 c = light.centre();
  const double radius = light.desc().radius;
  Vec3 normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
  const double area = normal.norm();
  if (!(area > 0)) return false;
  normal /= area;
  double h_origin = normal.dot(origin - corners[0]), h_centre = normal.dot(c - corners[0]);
  if (h_origin < 0) h_origin = -h_origin, h_centre = -h_centre;
  if (!(h_origin > light_offset && -h_centre > radius + 2 * light_offset)) return false;
  const double reach = (c - origin).norm();
  for (int k = 0; k < 3; ++k) {
    Vec3 n;
    if (!inward_edge_plane(corners, k, origin, n)) return false;
    if (!(n.dot(c - origin) > radius + 1e-9 * reach)) return false;
  }
  return true;
}

}  // namespace

bool triangle_hides_light(const Light& light, const Vec3* corners, const Vec3& origin,
                          double light_offset) {
  if (light.shape() == LightShape::sphere)
    return triangle_hides_sphere(light, corners, origin, light_offset);
  if (light.shape() != LightShape::rectangle && light.shape() != LightShape::disk &&
      light.shape() != LightShape::polygon)
    return false;
  // Between the light's plane and the origin, each corner clear of both.
  const Vec3& m = light.normal();
  const double h_origin = m.dot(origin - light.centre());
  Vec3 lo = corners[0], hi = corners[0];
  for (int k = 0; k < 3; ++k) {
    const double h = m.dot(corners[k] - light.centre());
    if (!(h > light_offset && h < h_origin * (1 - 1e-9))) return false;
    lo = lo.cwiseMin(corners[k]), hi = hi.cwiseMax(corners[k]);
  }
  if ((lo - origin).cwiseMax(origin - hi).cwiseMax(Vec3::Zero()).norm() < light_offset)
    return false;
  // First a cheap necessary test (a dense mesh's small triangles fail it): the triangle projected
  // from the origin onto the light's plane holds the light, so its inscribed circle is no smaller
  // than the light's (a rectangle's half its shorter side, a disk's radius).
  if (light.shape() != LightShape::polygon) {
    const double inradius = light.shape() == LightShape::disk
                                ? light.desc().radius
                                : 0.5 * std::min(light.desc().width, light.desc().height);
    std::array<Vec3, 3> projected;
    for (int k = 0; k < 3; ++k) {
      const double h = m.dot(corners[k] - light.centre());
      projected[std::size_t(k)] = origin + (corners[k] - origin) * (h_origin / (h_origin - h));
    }
    const double area2 =
        (projected[1] - projected[0]).cross(projected[2] - projected[0]).norm();  // twice
    const double perimeter = (projected[1] - projected[0]).norm() +
                             (projected[2] - projected[1]).norm() +
                             (projected[0] - projected[2]).norm();
    if (area2 < inradius * perimeter * (1 - 1e-6)) return false;
  }
  // The light inside the cone from the origin over the triangle: on the inner side of each plane
  // through the origin and an edge, with a margin of a billionth against rounding.
  std::array<Vec3, 4> outline;
  const int count = light.outline(outline);
  for (int k = 0; k < 3; ++k) {
    Vec3 n;
    if (!inward_edge_plane(corners, k, origin, n)) return false;
    if (count > 0) {
      for (int c = 0; c < count; ++c) {
        const Vec3 d = outline[std::size_t(c)] - origin;
        if (!(n.dot(d) > 1e-9 * d.norm())) return false;
      }
    } else {  // a disk: its nearest point to the plane
      const Vec3 d = light.centre() - origin;
      const double across = std::sqrt(std::max(0.0, 1 - std::pow(n.dot(m), 2)));
      if (!(n.dot(d) - light.desc().radius * across > 1e-9 * d.norm())) return false;
    }
  }
  return true;
}

bool ball_hides_light(const Light& light, const Vec3& centre, double radius, const Vec3& origin,
                      double light_offset) {
  if (light.shape() != LightShape::rectangle && light.shape() != LightShape::disk &&
      light.shape() != LightShape::polygon)
    return false;
  const Vec3& m = light.normal();
  const double h_origin = m.dot(origin - light.centre()), h_centre = m.dot(centre - light.centre());
  if (!(h_centre - radius > light_offset && h_centre + radius < h_origin)) return false;
  const Vec3 axis = centre - origin;
  const double distance = axis.norm();
  if (!(distance > radius)) return false;
  // The cone touching the ball: directions within asin(radius / distance) of its axis, less a
  // billionth against rounding.
  const double sin_cone = radius / distance, cos_cone = std::sqrt(1 - sin_cone * sin_cone);
  std::array<Vec3, 4> outline;
  const int count = light.outline(outline);
  if (count > 0) {  // a convex polygon: inside the (convex) cone where its corners are
    for (int c = 0; c < count; ++c) {
      const Vec3 d = outline[std::size_t(c)] - origin;
      if (!(axis.dot(d) > distance * d.norm() * (cos_cone + 1e-9))) return false;
    }
    return true;
  }
  // A disk: its centre's direction within the cone by more than the angle its bounding sphere
  // subtends.
  const Vec3 d = light.centre() - origin;
  const double to_light = d.norm();
  if (!(to_light > light.desc().radius)) return false;
  const double off_axis = std::acos(std::clamp(axis.dot(d) / (distance * to_light), -1.0, 1.0));
  return off_axis + std::asin(light.desc().radius / to_light) < std::asin(sin_cone) - 1e-9;
}

}  // namespace sb
