// The source image of docs/design.md §2, scaled and mirrored into the convolution kernel
// (source_image.cpp).
#pragma once

#include <array>
#include <vector>

#include "methods/convolution/virtual_configuration.h"
#include "scene/lights.h"

namespace sb {

struct SourceKernel {
  int width = 1, height = 1;  // odd; pixel (width/2, height/2) is the origin
  // Per colour channel, normalised to sum 1 (all zero for a channel the light does not emit).
  std::array<std::vector<float>, 3> channels;
  bool grey = true;  // the three channels are equal: one convolution serves them all
  // First moments for the irradiance weighting (docs/design.md §6), grey rectangles and disks
  // only (empty otherwise): the emission times the light point's offset along the light's
  // right and up axes (metres), normalised by the same sum as `channels`; and the kernel's
  // centroid along those axes.
  std::array<std::vector<float>, 2> moments;
  Vec2 centroid = Vec2::Zero();
};

// Half extents along the frame's e1, e2 of the kernel at k = 1 (source_kernel), metres: the
// light's outline seen from receiver points at `receiver_depth` along tangent direction `view`.
Vec2 projected_half_extents(const Light& light, const ProjectionFrame& frame, const Vec2& view,
                            double receiver_depth);

// How far the light's points lie off its centre's plane across the frame's axis, metres: 0 for a
// light facing along the axis, and for a sphere (seen as its silhouette disk from anywhere).
double depth_half_spread(const Light& light, const ProjectionFrame& frame);

// The kernel for blocker-to-receiver factor k (`tangent_per_metre`, 1/d* − 1/r*) on a grid of
// `pixel` tangent units, exact for receiver points at depth `receiver_depth` seen along tangent
// direction `view` from the light's centre (source_image.cpp derives it): the light's emission
// mapped by u = −k·r/(r − z)·(s − z·view) for its points at lateral offset s and depth z,
// normalised to sum 1 per channel.
SourceKernel source_kernel(const Light& light, const ProjectionFrame& frame,
                           double tangent_per_metre, double pixel, const Vec2& view,
                           double receiver_depth);

}  // namespace sb
