// A sun: a light at infinity of small angular diameter, made of the shape every method already
// knows exactly. A disk of radius D·tan(α/2) at distance D from the scene, facing it, subtends
// the sun's angle α from every point of the scene to within the scene's size over D; its
// closed-form form factor (Light::form_factor) is then the sun's, sin²(α/2)·cos θ where the whole
// disk is above the horizon, clipped exactly where the horizon cuts it; its penumbrae widen with
// distance from the blocker as the sun's do. So the reference, the noise-free estimator, the
// convolution and the baselines bake a sun with no code of their own, and docs/methods.md's
// accuracy figures for disks hold for it.
//
// D is 10⁴ times the scene's extent (its diagonal plus its centre's distance from the origin),
// between 10⁴ and 10⁵ m (every coordinate must stay within 10⁶ m): the direction to the sun then
// varies across a scene of up to 10 m by at most 10⁻⁴ rad, 1/90 of Blender's default sun
// diameter (across a 100 m one, by 10⁻³ rad).
#pragma once

#include "core/geometry.h"
#include "scene/scene.h"

namespace sb {

// Blender's default sun angle, degrees (the Sun's angular diameter seen from the Earth).
inline constexpr double kSunAngleDeg = 0.526;

// The disk light of a sun shining along `direction` (unit), of angular diameter `angle_deg`
// and irradiance `irradiance` W/m² on a surface facing it, for a scene within `bounds`. Its name,
// colour and line are the caller's to set.
LightDesc sun_light(const Vec3& direction, double angle_deg, double irradiance,
                    const Bounds3& bounds);

// Gives a sun made by sun_light another angular diameter, keeping its distance, direction and
// irradiance.
void set_sun_angle(LightDesc& sun, double angle_deg);

// Places a sun made by sun_light for a scene within `bounds` (its distance and centre as
// sun_light puts them), keeping its direction, angle and irradiance. The bake places every sun
// for its meshes' bounds: a scene file's sun is read before any mesh (placed for the origin).
void place_sun(LightDesc& sun, const Bounds3& bounds);

// The distance at which sun_light puts the disk for a scene within `bounds`, metres.
double sun_distance(const Bounds3& bounds);

}  // namespace sb
