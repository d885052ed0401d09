// Area lights as the bake methods see them: emission, closed-form unoccluded irradiance H0
// (design-notes §1) and stratified sampling for the ray-traced reference.
#pragma once

#include <vector>

#include "geometry.h"
#include "scene.h"

namespace sb {

// A point on a light chosen for one shadow ray, with its weight in the ratio estimator
// V = Σ w·v / Σ w (lights.cpp says why that estimator).
struct LightSample {
  Vec3 point;
  double weight = 0;  // 0: the sample cannot contribute (behind the light or below the horizon)
};

class Light {
 public:
  explicit Light(const LightDesc& desc);

  const LightDesc& desc() const { return desc_; }
  LightShape shape() const { return desc_.shape; }
  Vec3 centre() const { return desc_.position; }
  // Emitting surface area in m² (a sphere's whole surface; a rectangle or disk's one side).
  double area() const;
  // Radiant exitance per channel, W/m²: color · power / area.
  Vec3 exitance() const { return exitance_; }
  // Unit axes of a rectangle or disk: right = up × normal; the normal is the emitting side.
  const Vec3& right() const { return right_; }
  const Vec3& up() const { return up_; }
  const Vec3& normal() const { return desc_.normal; }

  // Unoccluded irradiance H0 at point y with unit normal n, per channel, W/m², in closed form:
  // H0 = E · F where F is the form factor from the point to the light, clipped to the point's
  // horizon. Rectangle: Lambert's polygon formula (exact). Disk, and a sphere through the disk of
  // its silhouette: the elementary closed form when the disk is wholly above the horizon, and a
  // 128-gon of equal area, clipped, otherwise (relative error < 1e-4, tested).
  Vec3 unoccluded_irradiance(const Vec3& y, const Vec3& n) const;
  // The form factor F alone (dimensionless, H0 = E · F).
  double form_factor(const Vec3& y, const Vec3& n) const;

  // Maps a stratified point u ∈ [0,1)² to a light sample as seen from y with normal n.
  // Rectangle and disk: uniform in area, weight cosθ_light · cosθ_receiver / r².
  // Sphere: uniform in the solid angle of the cone it subtends, weight cosθ_receiver.
  // Either way Σ w·v / Σ w converges to V = H / H0.
  LightSample sample(const Vec3& y, const Vec3& n, const Vec2& u) const;

 private:
  LightDesc desc_;
  Vec3 right_, up_;
  Vec3 exitance_;
};

std::vector<Light> make_lights(const std::vector<LightDesc>& descs);

// Lambert's formula for the form factor of a planar polygon (vertices relative to the point,
// either winding) seen from a point with unit normal n, after clipping the polygon to the
// half-space n·x >= 0. Exposed for tests.
double polygon_form_factor(std::vector<Vec3> polygon, const Vec3& n);

}  // namespace sb
