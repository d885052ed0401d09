// A proof that a wall hides a light from a whole box of points: occluder fusion on one plane.
//
// A room behind a wall sees none of a light in the next room, but no single triangle of the wall
// hides the light (a wall is many triangles), so a test of one triangle at a time (a triangle's
// umbra, tile_shafts.h) leaves every texel of the room to be proven dark on its own. Here the
// triangles of one plane are taken together: where the plane separates the box from the light,
// every segment from a point of the box to a point of the light crosses it inside the convex
// polygon of the crossings of the segments between the box's corners and the corners of a
// polytope bounding the light (the crossing point of a convex combination is a convex
// combination of the corners' crossings), and where the plane's blocker triangles cover that
// polygon every segment meets one of them. The exact counterpart, for one plane, of q3map2's cut
// of a light's envelope by the level's precomputed visibility (docs/many-lights.md), found from
// the triangles alone; the cover is decided by subtracting triangles from the polygon (convex
// pieces, Sutherland–Hodgman), with what is left under a ten-millionth of its area taken for
// the rounding of shared edges.
#pragma once

#include <cstdint>

#include "core/geometry.h"
#include "occluders/ray_scene.h"
#include "occluders/shaft_culling.h"
#include "scene/lights.h"

namespace sb {

// Whether blocker triangles lying in one plane hide all of `light` from every point of the box
// `origins` (ray origins, whose shadow rays skip their first `rays.surface_offset()` metres, as
// the triangles must lie farther than that from the box and from the light). The planes tried
// are those of the first triangles the ray from the box's centre to the light's centre meets;
// a plane's triangles are those of the culler whose boxes meet the crossings' polygon's.
// Rectangles, disks, polygons and spheres; false for the others, and false where it cannot
// tell. `first`, when given, is that ray's first hit, found already.
bool plane_hides_light(const ShaftCuller& culler, const RayScene& rays, const Light& light,
                       const Bounds3& origins, const RayScene::Hit* first = nullptr);

}  // namespace sb
