// The `backprojection` method's registry entry (backprojection_method.cpp).
#pragma once

#include "methods/method.h"

namespace sb {

// The default method: exact soft shadows by back-projection (texel_routes.h), with settings
// light_rows, max_polygons, max_cell, interpolation_tolerance, and samples and seed for a
// textured light's traced texels.
MethodEntry backprojection_method();

}  // namespace sb
