// Sutherland–Hodgman clipping (Sutherland & Hodgman, "Reentrant polygon clipping", CACM 17(1),
// 1974) of a polygon against one plane of constant depth along a ProjectionFrame's axis, the cut
// that keeps blocker geometry away from the light's centre before it is projected from there:
// the blocker image (methods/convolution/blocker_image.cpp) keeps a slab near <= depth <= far,
// the shadow map (methods/shadow_map.cpp) keeps depth >= near. It sits in occluders beside
// projection_frame.h, whose frame defines the depth, so both methods may include it.
#pragma once

#include <vector>

#include "core/geometry.h"
#include "occluders/projection_frame.h"

namespace sb {

// Which side of the plane clip_to_depth keeps.
enum class KeepDepth { at_least, at_most };

// The part of `polygon` (vertices in order around it) whose depth along frame.axis is >= limit
// (at_least) or <= limit (at_most), in metres: the kept vertices in order, with a new vertex
// where each edge crosses the plane. Fewer than three vertices back: nothing of it is left.
std::vector<Vec3> clip_to_depth(const std::vector<Vec3>& polygon, const ProjectionFrame& frame,
                                double limit, KeepDepth keep);

}  // namespace sb
