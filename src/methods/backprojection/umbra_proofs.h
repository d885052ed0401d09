// Proofs that one blocker hides all of a light from a point (umbra_proofs.cpp): what lets the
// tile shafts (tile_shafts.h) take a whole patch as 0, and the refinement (light_pairs.cpp) a
// whole cell, without evaluating their texels. A convex blocker's umbra under a convex light is
// convex, so a proof at a box's corners holds for every point of the box.
#pragma once

#include "core/geometry.h"
#include "scene/lights.h"

namespace sb {

// Whether the triangle `corners` hides all of `light` from `origin` (exactly: every segment from
// the origin to the light passes through it), clear of the origin and of the light's plane by
// `light_offset` as a shadow ray is (RayScene::surface_offset). Its umbra, the points from which
// it does, is convex under a convex light (the intersection of its shadows from each point of the
// light). Rectangles, disks, polygons and spheres; false for the others.
bool triangle_hides_light(const Light& light, const Vec3* corners, const Vec3& origin,
                          double light_offset);

// Whether the ball (centre, radius) hides all of a rectangle, disk or polygon `light` from
// `origin`: the ball between the origin and the light's plane, clear of the plane by
// `light_offset`, and every direction from the origin to the light inside the cone from the origin
// that touches the ball (a disk by the cone that holds its bounding sphere, as good as exact for
// a sun). Sufficient, not necessary; its umbra is convex under a convex light.
bool ball_hides_light(const Light& light, const Vec3& centre, double radius, const Vec3& origin,
                      double light_offset);

}  // namespace sb
