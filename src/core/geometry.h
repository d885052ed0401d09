// Small geometric types shared by every stage. Eigen is the project's vector library; these
// aliases keep the spelling short and the precision choice in one place.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>

namespace sb {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Vec2f = Eigen::Vector2f;
using Vec3f = Eigen::Vector3f;
using Mat3 = Eigen::Matrix3d;
using Affine3 = Eigen::Affine3d;

struct Bounds3 {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());

  void extend(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void extend(const Bounds3& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  bool empty() const { return (hi.array() < lo.array()).any(); }
  Vec3 centre() const { return 0.5 * (lo + hi); }
  // Corner k of 8: bit 0 picks hi's x, bit 1 its y, bit 2 its z.
  Vec3 corner(int k) const {
    return Vec3((k & 1 ? hi : lo).x(), (k & 2 ? hi : lo).y(), (k & 4 ? hi : lo).z());
  }
  double diagonal() const { return empty() ? 0.0 : (hi - lo).norm(); }
  bool contains(const Vec3& p) const {
    return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
  }
};

// Any unit vector orthogonal to the unit vector m: the x or y axis (whichever lies farther from
// m) with its part along m taken out.
inline Vec3 any_orthogonal(const Vec3& m) {
  const Vec3 a = std::abs(m.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  return (a - a.dot(m) * m).normalized();
}

}  // namespace sb
