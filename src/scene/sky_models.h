// Analytic skies: a clear sky's radiance from the sun's position and the air's turbidity, by
// Preetham, Shirley and Smits, "A practical analytic model for daylight" (SIGGRAPH 1999), at
// the scale Blender's Sky Texture gives it (sky_type PREETHAM), so that a scene's sky of
// strength 1 is as bright as Blender's with Background Strength 1. The sun itself is not in it:
// it is its own light (sun_light.h). A sky light (sky.h) bakes one as the equirectangular map it
// fills, like any environment map.
#pragma once

#include "core/geometry.h"
#include "core/image.h"

namespace sb {

// The turbidities the model's fit covers (the paper fitted 2 to 10; below 2 its zenith luminance
// turns negative for a high sun).
constexpr double kMinTurbidity = 2, kMaxTurbidity = 10;
constexpr double kDefaultTurbidity = 2.2;  // Blender's default

// Linear Rec.709 RGB radiance arriving from unit direction `d` (Z up) under a clear sky whose sun
// lies towards unit `sun` (at or above the horizon) with `turbidity`. Below the horizon, as
// Blender's: the horizon's radiance (a level's ground is what hides it).
Vec3 preetham_radiance(const Vec3& sun, double turbidity, const Vec3& d);

// That sky as an equirectangular map of width × height (Z up, as sky.h maps a map: middle column
// +X, top row the zenith, u growing towards −Y), each pixel the radiance at its centre.
Image preetham_map(const Vec3& sun, double turbidity, int width, int height);

}  // namespace sb
