// Where a light reaches (lights.h): its spot cone, its range and glTF's window within it, and
// the tests of a point, a box of points or a box with one normal against its horizon and reach,
// which the light lists, the shaft tests and every method's H0 read.
#include "scene/lights.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace sb {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

}  // namespace

double Light::spot_factor(const Vec3& y) const {
  if (!(desc_.spot_outer > 0)) return 1.0;
  const Vec3 d = y - desc_.position;
  const double length = d.norm();
  if (!(length > 0)) return 0.0;
  const double cos_outer = std::cos(desc_.spot_outer), cos_inner = std::cos(desc_.spot_inner);
  const double t = std::clamp(
      (desc_.spot_axis.dot(d) / length - cos_outer) / std::max(1e-3, cos_inner - cos_outer), 0.0,
      1.0);
  return t * t;
}

Light::Reach Light::flat_reach(const Vec3& y, const Vec3& n) const {
  const Vec3 c = desc_.position - y;
  Reach r;
  r.front = -c.dot(desc_.normal);
  if (desc_.shape == LightShape::rectangle) {
    // The horizon clips a positive area off the rectangle as soon as one corner is above it.
    const double hw = 0.5 * desc_.width * std::abs(n.dot(right_));
    const double hh = 0.5 * desc_.height * std::abs(n.dot(up_));
    r.above = n.dot(c) + hw + hh;
  } else if (desc_.shape == LightShape::disk) {
    r.above = n.dot(c) + desc_.radius * (n - n.dot(desc_.normal) * desc_.normal).norm();
  } else {
    r.above = -std::numeric_limits<double>::infinity();
    for (const Vec3& corner : desc_.corners) r.above = std::max(r.above, n.dot(corner - y));
  }
  return r;
}

double range_for_floor(const LightDesc& light, double floor) {
  const double power = light.power * light.color.maxCoeff();
  if (!(floor > 0) || light.sun_angle_deg > 0 || !(power > 0)) return kInfinity;
  switch (light.shape) {
    case LightShape::sphere:
      return std::sqrt(power / (4 * kPi * floor));
    case LightShape::rectangle:
    case LightShape::disk:
      return std::sqrt(power / (kPi * floor));
    case LightShape::polygon:
    case LightShape::mesh:
    case LightShape::sky:
      break;
  }
  return kInfinity;
}

double Light::range_factor(const Vec3& y) const {
  if (!std::isfinite(desc_.range)) return 1.0;
  if (!(desc_.range > 0)) return 0.0;  // a light that reaches nothing (cut_enclosed_lights)
  const double q = (y - desc_.position).squaredNorm() / (desc_.range * desc_.range);
  return q >= 1 ? 0.0 : 1.0 - q * q;
}

bool Light::may_reach(const Bounds3& ys) const {
  if (ys.empty()) return false;
  const Vec3& c = desc_.position;
  if (std::isfinite(desc_.range)) {
    // The box's nearest point to the centre.
    const Vec3 nearest = c.cwiseMax(ys.lo).cwiseMin(ys.hi);
    if (!((nearest - c).norm() < desc_.range)) return false;
  }
  switch (desc_.shape) {
    case LightShape::rectangle:
    case LightShape::disk:
    case LightShape::polygon: {
      // Some corner of the box in front of the emitting side.
      bool front = false;
      for (int k = 0; k < 8 && !front; ++k) front = (ys.corner(k) - c).dot(desc_.normal) > 0;
      if (!front) return false;
      break;
    }
    case LightShape::sphere:
    case LightShape::mesh:
    case LightShape::sky:
      break;
  }
  if (desc_.spot_outer > 0 && !ys.contains(c)) {
    // The cone against the box's bounding ball: no point of the ball lies within the outer cone
    // where the angle from the axis to its centre, less the ball's angular radius, exceeds it.
    const Vec3 to = ys.centre() - c;
    const double distance = to.norm(), radius = 0.5 * ys.diagonal();
    if (distance > radius) {
      const double angle = std::acos(std::clamp(desc_.spot_axis.dot(to) / distance, -1.0, 1.0));
      if (angle - std::asin(std::min(1.0, radius / distance)) >= desc_.spot_outer) return false;
    }
  }
  return true;
}

bool Light::may_reach(const Bounds3& ys, const Vec3& n) const {
  if (!may_reach(ys)) return false;
  // Some of the light above the horizon of some point of the box: its highest point over the
  // plane through y with normal n, at the corner lowest along n.
  double lowest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 8; ++k) lowest = std::min(lowest, n.dot(ys.corner(k)));
  double top = -std::numeric_limits<double>::infinity();
  switch (desc_.shape) {
    case LightShape::rectangle:
      top = n.dot(desc_.position) + 0.5 * desc_.width * std::abs(n.dot(right_)) +
            0.5 * desc_.height * std::abs(n.dot(up_));
      break;
    case LightShape::disk:
      top = n.dot(desc_.position) + desc_.radius * (n - n.dot(desc_.normal) * desc_.normal).norm();
      break;
    case LightShape::sphere:
      top = n.dot(desc_.position) + desc_.radius;
      break;
    case LightShape::polygon:
    case LightShape::mesh:
      for (const Vec3& corner : desc_.corners) top = std::max(top, n.dot(corner));
      break;
    case LightShape::sky:
      return true;
  }
  // A margin against rounding, relative to the distances involved.
  const double margin = 1e-9 * (std::abs(top) + std::abs(lowest) + ys.diagonal());
  return top > lowest - margin;
}

bool Light::reaches(const Vec3& y, const Vec3& n) const {
  if (!(spot_factor(y) > 0) || !(range_factor(y) > 0)) return false;
  switch (desc_.shape) {
    case LightShape::rectangle:
    case LightShape::polygon:
    case LightShape::disk: {
      const Reach r = flat_reach(y, n);
      return r.front > 0 && r.above > 0;
    }
    case LightShape::sphere: {
      const Vec3 c = desc_.position - y;
      const double d = c.norm(), r = desc_.radius;
      if (d <= r) return false;
      if (n.dot(c) >= r) return true;  // wholly above the horizon
      // The silhouette disk, as in form_factor.
      const Vec3 axis = -c / d;
      const Vec3 sil_centre = c * (1.0 - r * r / (d * d));
      const double sil_radius = r * std::sqrt(d * d - r * r) / d;
      return n.dot(sil_centre) + sil_radius * (n - n.dot(axis) * axis).norm() > 0;
    }
    case LightShape::mesh:
    case LightShape::sky:
      break;
  }
  return false;
}

bool Light::within_range_throughout(const Bounds3& ys) const {
  if (!std::isfinite(desc_.range)) return true;
  // Its farthest corner is (by a margin against rounding).
  double farthest = 0;
  for (int k = 0; k < 8; ++k) farthest = std::max(farthest, (ys.corner(k) - desc_.position).norm());
  return farthest < desc_.range * (1 - 1e-9);
}

bool Light::reaches_all(const Bounds3& ys, const Vec3& n) const {
  if (desc_.spot_outer > 0 || ys.empty()) return false;
  if (desc_.shape != LightShape::rectangle && desc_.shape != LightShape::disk &&
      desc_.shape != LightShape::polygon)
    return false;
  if (!within_range_throughout(ys)) return false;
  // For one normal both of flat_reach's terms are linear in y: positive at the box's corners
  // (by a margin against rounding), they are positive throughout.
  for (int k = 0; k < 8; ++k) {
    const Vec3 y = ys.corner(k);
    const Reach r = flat_reach(y, n);
    const double margin = 1e-9 * ((desc_.position - y).norm() + std::abs(r.above) + ys.diagonal());
    if (!(r.front > margin && r.above > margin)) return false;
  }
  return true;
}

bool Light::reaches_all(const Bounds3& ys, const Bounds3& ns) const {
  if (ns.empty()) return false;
  if (desc_.shape != LightShape::sphere) return ns.lo == ns.hi && reaches_all(ys, Vec3(ns.lo));
  if (desc_.spot_outer > 0 || ys.empty()) return false;
  const Vec3& c = desc_.position;
  const double r = desc_.radius;
  if (!within_range_throughout(ys)) return false;
  // Outside the sphere: its nearest point is.
  if (!((c.cwiseMax(ys.lo).cwiseMin(ys.hi) - c).norm() > r * (1 + 1e-6))) return false;
  // Wholly above each horizon (reaches(): n·(c − y) >= r), by a margin for rounding.
  const double margin = 1e-9 * ((c - ys.centre()).norm() + ys.diagonal() + r);
  return height_over_horizons(ys, ns).first >= r + margin;
}

bool Light::reaches_none(const Bounds3& ys, const Bounds3& ns) const {
  if (ys.empty() || ns.empty()) return false;
  const Vec3& c = desc_.position;
  if (std::isfinite(desc_.range)) {
    // range_factor is 0 from the range on: the box's nearest point lies beyond it.
    if (!(desc_.range > 0)) return true;
    if ((c.cwiseMax(ys.lo).cwiseMin(ys.hi) - c).norm() > desc_.range * (1 + 1e-9)) return true;
  }
  if (desc_.shape != LightShape::sphere) return false;
  // Wholly below each horizon, n·(c − y) <= −r: so is its silhouette, and F = 0.
  const double r = desc_.radius;
  const double margin = 1e-9 * ((c - ys.centre()).norm() + ys.diagonal() + r);
  return height_over_horizons(ys, ns).second <= -r - margin;
}

std::pair<double, double> Light::height_over_horizons(const Bounds3& ys, const Bounds3& ns) const {
  // n·(c − y) summed over components, each a product of two ranges: its least and greatest
  // products bound it.
  const Vec3& c = desc_.position;
  double least = 0, greatest = 0;
  for (int i = 0; i < 3; ++i) {
    const double a = c[i] - ys.hi[i], b = c[i] - ys.lo[i];
    const double p[4] = {ns.lo[i] * a, ns.lo[i] * b, ns.hi[i] * a, ns.hi[i] * b};
    least += std::min({p[0], p[1], p[2], p[3]});
    greatest += std::max({p[0], p[1], p[2], p[3]});
  }
  return {least, greatest};
}

}  // namespace sb
