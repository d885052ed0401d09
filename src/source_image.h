// The source image of design-notes §2, scaled and mirrored into the convolution kernel
// (source_image.cpp).
#pragma once

#include <array>
#include <vector>

#include "lights.h"
#include "virtual_configuration.h"

namespace sb {

struct SourceKernel {
  int width = 1, height = 1;  // odd; pixel (width/2, height/2) is the origin
  // Per colour channel, normalised to sum 1 (all zero for a channel the light does not emit).
  std::array<std::vector<float>, 3> channels;
  bool grey = true;  // the three channels are equal: one convolution serves them all
};

// The kernel K(u) = S(−u / k) on a grid of `pixel` tangent units, where S is the light's source
// image (its emission seen along the frame's axis, Light::source_image) and
// k = 1/d* − 1/r* (tangent units per metre on the source plane) maps a source offset to the
// blocker-image offset it occludes through. Anti-aliased with n × n samples per pixel.
SourceKernel source_kernel(const Light& light, const ProjectionFrame& frame,
                           double tangent_per_metre, double pixel);

}  // namespace sb
