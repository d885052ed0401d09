#include "scene/sun_light.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sb {

double sun_distance(const Bounds3& bounds) {
  const double extent = bounds.diagonal() + bounds.centre().norm();
  return std::clamp(1e4 * extent, 1e4, 1e5);
}

LightDesc sun_light(const Vec3& direction, double angle_deg, double irradiance,
                    const Bounds3& bounds) {
  const double distance = sun_distance(bounds);
  const double half = 0.5 * angle_deg * std::numbers::pi / 180;
  LightDesc sun;
  sun.shape = LightShape::disk;
  sun.normal = direction;
  sun.position = bounds.centre() - distance * direction;
  sun.radius = distance * std::tan(half);
  const Vec3 y = std::abs(direction.y()) < 0.999 ? Vec3::UnitY() : Vec3::UnitZ();
  sun.up = (y - y.dot(direction) * direction).normalized();
  // On the axis a disk's form factor is r² / (r² + D²) = sin²(α/2): the exitance that gives
  // `irradiance` there, over the disk's area.
  const double sine = std::sin(half);
  sun.power = irradiance / (sine * sine) * std::numbers::pi * sun.radius * sun.radius;
  sun.sun_angle_deg = angle_deg;
  return sun;
}

void set_sun_angle(LightDesc& sun, double angle_deg) {
  const double old_half = 0.5 * sun.sun_angle_deg * std::numbers::pi / 180;
  const double new_half = 0.5 * angle_deg * std::numbers::pi / 180;
  const double distance = sun.radius / std::tan(old_half);
  const double irradiance = sun.power / (std::numbers::pi * sun.radius * sun.radius) *
                            std::sin(old_half) * std::sin(old_half);
  sun.radius = distance * std::tan(new_half);
  sun.power = irradiance / (std::sin(new_half) * std::sin(new_half)) * std::numbers::pi *
              sun.radius * sun.radius;
  sun.sun_angle_deg = angle_deg;
}

void place_sun(LightDesc& sun, const Bounds3& bounds) {
  const double half = 0.5 * sun.sun_angle_deg * std::numbers::pi / 180;
  const double irradiance =
      sun.power / (std::numbers::pi * sun.radius * sun.radius) * std::sin(half) * std::sin(half);
  const LightDesc placed = sun_light(sun.normal, sun.sun_angle_deg, irradiance, bounds);
  sun.position = placed.position;
  sun.radius = placed.radius;
  sun.up = placed.up;
  sun.power = placed.power;
}

}  // namespace sb
