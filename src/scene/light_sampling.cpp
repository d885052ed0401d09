// Sampling lights for the ray-traced reference (docs/design.md §7; lights.h): area sampling for
// rectangles, disks and polygons, cone sampling for spheres, and the part of a light above a
// point's horizon, sampled uniformly by area.
//
// The reference estimates V with the ratio Σ w·v / Σ w over the same samples rather than
// Σ w·v / (N · H0): both converge to H/H0, but the ratio is always in [0, 1] and its noise is only
// that of v, not of the weight's variation over the light.
#include "scene/lights.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "scene/light_geometry.h"

namespace sb {

namespace {

constexpr double kPi = std::numbers::pi;

// Clips a polygon to the half-space n·x >= 0 (Sutherland–Hodgman, one plane).
std::vector<Vec3> clip_to_horizon(const std::vector<Vec3>& poly, const Vec3& n) {
  std::vector<Vec3> out;
  out.reserve(poly.size() + 2);
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec3& a = poly[i];
    const Vec3& b = poly[(i + 1) % poly.size()];
    const double da = n.dot(a), db = n.dot(b);
    if (da >= 0) out.push_back(a);
    if ((da >= 0) != (db >= 0)) out.push_back(a + (b - a) * (da / (da - db)));
  }
  return out;
}

}  // namespace

LightSample Light::sample(const Vec3& y, const Vec3& n, const Vec2& u) const {
  LightSample s;
  switch (desc_.shape) {
    case LightShape::rectangle:
    case LightShape::disk:
    case LightShape::polygon: {
      Vec2 local;  // metres in the light's (right, up) frame
      if (desc_.shape == LightShape::rectangle) {
        local = Vec2((u.x() - 0.5) * desc_.width, (u.y() - 0.5) * desc_.height);
      } else if (desc_.shape == LightShape::polygon) {
        // Uniform by area: u.x picks a triangle of the fan by its share of the area (a quad's
        // two), the rest of it and u.y fold the stratum onto that triangle by √u.
        const std::vector<Vec3>& c = desc_.corners;
        double ux = u.x();
        std::size_t k = 1;
        if (c.size() == 4) {
          const double first = (c[1] - c[0]).cross(c[2] - c[0]).norm();
          const double share = first / (first + (c[2] - c[0]).cross(c[3] - c[0]).norm());
          if (ux < share) {
            ux /= share;
          } else {
            ux = (ux - share) / (1 - share);
            k = 2;
          }
        }
        const double su = std::sqrt(std::clamp(ux, 0.0, 1.0));
        const Vec3 x = (1 - su) * c[0] + su * ((1 - u.y()) * c[k] + u.y() * c[k + 1]) - centre();
        local = Vec2(x.dot(right_), x.dot(up_));
      } else {
        // Shirley–Chiu concentric map: keeps the strata's shapes compact on the disk.
        const double a = 2 * u.x() - 1, b = 2 * u.y() - 1;
        double r, phi;
        if (a == 0 && b == 0) {
          r = 0, phi = 0;
        } else if (std::abs(a) > std::abs(b)) {
          r = a, phi = (kPi / 4) * (b / a);
        } else {
          r = b, phi = kPi / 2 - (kPi / 4) * (a / b);
        }
        local = desc_.radius * r * Vec2(std::cos(phi), std::sin(phi));
      }
      s.point = desc_.position + local.x() * right_ + local.y() * up_;
      s.tint = tint(local);
      const Vec3 d = s.point - y;
      const double dist2 = d.squaredNorm();
      if (dist2 <= 0) return s;
      const double inv = 1.0 / std::sqrt(dist2);
      const double cos_light = -d.dot(desc_.normal) * inv;
      const double cos_receiver = d.dot(n) * inv;
      if (cos_light > 0 && cos_receiver > 0) s.weight = cos_light * cos_receiver / dist2;
      return s;
    }
    case LightShape::sphere: {
      const Vec3 c = desc_.position - y;
      const double d = c.norm(), r = desc_.radius;
      if (d <= r) return s;
      const Vec3 axis = c / d;
      const double cos_max = std::sqrt(std::max(0.0, 1.0 - r * r / (d * d)));
      const double cos_t = 1.0 - u.x() * (1.0 - cos_max);
      const double sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
      const double phi = 2 * kPi * u.y();
      const Vec3 a = any_orthogonal(axis), b = axis.cross(a);
      const Vec3 dir = cos_t * axis + sin_t * (std::cos(phi) * a + std::sin(phi) * b);
      // Nearest intersection of the ray y + t·dir with the sphere.
      const double proj = dir.dot(c);
      const double t = proj - std::sqrt(std::max(0.0, r * r - (d * d - proj * proj)));
      s.point = y + t * dir;
      const double cos_receiver = dir.dot(n);
      if (cos_receiver > 0) s.weight = cos_receiver;
      return s;
    }
    case LightShape::mesh:
    case LightShape::sky:
      break;
  }
  return s;
}

bool Light::partly_below_horizon(const Vec3& y, const Vec3& n) const {
  const Vec3 c = desc_.position - y;
  switch (desc_.shape) {
    case LightShape::rectangle:
      return n.dot(c) - 0.5 * desc_.width * std::abs(n.dot(right_)) -
                 0.5 * desc_.height * std::abs(n.dot(up_)) <
             0;
    case LightShape::disk:
      return n.dot(c) - desc_.radius * (n - n.dot(desc_.normal) * desc_.normal).norm() < 0;
    case LightShape::sphere:
      return n.dot(c) - desc_.radius < 0;
    case LightShape::polygon: {
      double lowest = std::numeric_limits<double>::infinity();
      for (const Vec3& corner : desc_.corners) lowest = std::min(lowest, n.dot(corner - y));
      return lowest < 0;
    }
    case LightShape::mesh:
    case LightShape::sky:
      break;
  }
  return true;
}

HorizonPart Light::above_horizon(const Vec3& y, const Vec3& n) const {
  HorizonPart part;
  part.light_ = this;
  part.y_ = y;
  part.n_ = n;
  if (!partly_below_horizon(y, n)) return part;
  part.whole_ = false;
  // The light's outline (relative to y), as its closed form clips it.
  std::vector<Vec3> outline;
  const auto polygon = [&](const Vec3& centre, const Vec3& a, const Vec3& b, double radius) {
    const DiskPolygon& unit = disk_polygon();
    const double r = radius * unit.area_radius;
    for (const Vec2& u : unit.unit) outline.push_back(centre + r * (u.x() * a + u.y() * b));
  };
  const Vec3 c = desc_.position - y;
  switch (desc_.shape) {
    case LightShape::rectangle:
    case LightShape::polygon: {
      if (c.dot(desc_.normal) >= 0) break;
      std::array<Vec3, 4> corners;
      const int count = this->outline(corners);
      for (int k = 0; k < count; ++k) outline.push_back(corners[std::size_t(k)] - y);
      break;
    }
    case LightShape::disk:
      if (c.dot(desc_.normal) >= 0) break;
      polygon(c, right_, up_, desc_.radius);
      break;
    case LightShape::sphere: {
      const double d = c.norm(), r = desc_.radius;
      if (d <= r) break;
      const Vec3 axis = -c / d;
      const Vec3 a = any_orthogonal(axis);
      part.plane_ = (d * d - r * r) / d;
      polygon(c * (1.0 - r * r / (d * d)), a, axis.cross(a), r * std::sqrt(d * d - r * r) / d);
      break;
    }
    case LightShape::mesh:
    case LightShape::sky:
      break;
  }
  const std::vector<Vec3> clipped = clip_to_horizon(outline, n);
  double total = 0;
  for (std::size_t i = 1; i + 1 < clipped.size(); ++i) {
    const double a = 0.5 * (clipped[i] - clipped[0]).cross(clipped[i + 1] - clipped[0]).norm();
    if (!(a > 0)) continue;
    part.fan_.insert(part.fan_.end(), {clipped[0], clipped[i], clipped[i + 1]});
    total += a;
    part.area_.push_back(total);
  }
  return part;
}

LightSample HorizonPart::sample(const Vec2& u) const {
  if (whole_) return light_->sample(y_, n_, u);
  LightSample s;
  if (area_.empty()) return s;
  // The triangle by area along u.x, then uniform in it.
  const double at = u.x() * area_.back();
  const std::size_t k =
      std::size_t(std::upper_bound(area_.begin(), area_.end(), at) - area_.begin());
  const std::size_t tri = std::min(k, area_.size() - 1);
  const double before = tri == 0 ? 0.0 : area_[tri - 1];
  const double ux = std::clamp((at - before) / (area_[tri] - before), 0.0, 1.0);
  const double su = std::sqrt(ux);
  const Vec3& a = fan_[3 * tri];
  const Vec3& b = fan_[3 * tri + 1];
  const Vec3& c = fan_[3 * tri + 2];
  const Vec3 x = (1 - su) * a + su * ((1 - u.y()) * b + u.y() * c);  // relative to y
  const double dist2 = x.squaredNorm();
  if (!(dist2 > 0)) return s;
  const double inv = 1.0 / std::sqrt(dist2);
  const double cos_receiver = x.dot(n_) * inv;
  if (!(cos_receiver > 0)) return s;
  const LightDesc& d = light_->desc();
  if (d.shape != LightShape::sphere) {
    s.point = y_ + x;
    const Vec3 local = s.point - d.position;
    s.tint = light_->tint(Vec2(local.dot(light_->right()), local.dot(light_->up())));
    const double cos_light = -x.dot(d.normal) * inv;
    if (cos_light > 0) s.weight = cos_light * cos_receiver / dist2;
    return s;
  }
  // On the silhouette's plane, uniform by area: a direction's solid angle is plane/ℓ³ per unit
  // area, and the ray ends where it meets the sphere.
  const Vec3 dir = x * inv;
  const Vec3 to_centre = d.position - y_;
  const double proj = dir.dot(to_centre);
  const double t = proj - std::sqrt(std::max(
                              0.0, d.radius * d.radius - (to_centre.squaredNorm() - proj * proj)));
  s.point = y_ + t * dir;
  s.weight = cos_receiver * plane_ * inv * inv * inv;
  return s;
}

}  // namespace sb
