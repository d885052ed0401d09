// Geometry that the lights' closed forms (lights.cpp) and their samplers for the reference
// (light_sampling.cpp) share: a disk's regular polygon of equal area. Private to the scene
// module.
#pragma once

#include <array>

#include "core/geometry.h"

namespace sb {

inline constexpr int kDiskPolygonSides = 128;

// The regular kDiskPolygonSides-gon's corners on the unit circle, (cos t, sin t), and the radius
// that gives it a disk's area, per unit radius: computed once (a form factor near a light's
// horizon asked for 256 sines and cosines each time).
struct DiskPolygon {
  std::array<Vec2, kDiskPolygonSides> unit;
  double area_radius;
};
const DiskPolygon& disk_polygon();

}  // namespace sb
