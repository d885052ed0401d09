// Texels buried in a blocker: a receiver's texels that lie inside (or on the surface of) a convex
// closed blocker other than their own component, such as a floor under a box standing on it.
// Such a point sees no light, as in the reference, whose shadow rays leave from inside the solid;
// the convolution's slabs approximate that only to within their plane error, which left nested
// outlines of the solid's sections lit under a box (convolution_bake.cpp sets these texels dark).
#pragma once

#include <cstdint>
#include <vector>

#include "occluders/clusters.h"
#include "scene/mesh.h"
#include "texels/texel_space.h"

namespace sb {

// Per texel of `space` (receiver `receiver`, one of `blockers` or none), 1 where the texel's
// position lies inside a convex closed component (ClusterTree::component_convex,
// component_closed) of a blocker, the receiver's own component at that texel excepted: at least
// `tolerance` metres behind every face plane, or within `tolerance` of a face that lies against
// the receiver's surface (opposite normals; the floor under a box's bottom face is buried, a
// floor texel on the plane of the box's side is not).
std::vector<std::uint8_t> buried_texels(const TexelSpace& space, const Mesh& receiver,
                                        const std::vector<const Mesh*>& blockers,
                                        const ClusterTree& clusters, double tolerance);

}  // namespace sb
