// The blocker image of docs/design.md §2–3: blocker geometry projected from the light's centre onto
// the blocker plane, as anti-aliased coverage on a regular grid (blocker_image.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "core/geometry.h"
#include "methods/convolution/virtual_configuration.h"
#include "scene/mesh.h"

namespace sb {

// A regular grid over the tangent plane of a ProjectionFrame: pixel (i, j) covers
// [origin + (i, j)·pixel, origin + (i + 1, j + 1)·pixel]; i runs along e1, j along e2.
struct TangentGrid {
  Vec2 origin = Vec2::Zero();
  double pixel = 1;
  int width = 0, height = 0;
  // Continuous pixel coordinates of a tangent point (pixel centres at integers).
  Vec2 to_pixel(const Vec2& t) const { return (t - origin) / pixel - Vec2::Constant(0.5); }
};

// Blocker triangles clipped to a slab of depth and projected: convex polygons in tangent
// coordinates with their depth range.
struct ProjectedBlockers {
  struct Polygon {
    std::vector<Vec2> points;  // tangent coordinates, counter-clockwise
    Vec2 lo, hi;               // bounding box
    double depth_lo = 0, depth_hi = 0;
    int source = -1;  // index of the face it came from in the list given to project_faces
    // The face's plane as inverse depth, affine in tangent coordinates (a plane seen from a
    // point): 1/depth = x·t1 + y·t2 + z.
    Vec3 inverse_depth = Vec3::Zero();
  };
  std::vector<Polygon> polygons;
};

// Which blocker triangles can shadow a receiver: a triangle whose plane has the whole light
// (a sphere of light_radius around the frame's origin) and the whole receiver (its bounding box)
// on one side cannot lie between them, since a segment never leaves a half-space that holds both
// its ends. Exact in what it rejects; it keeps the floor under a box out of the box's shadows.
struct ShadowCaster {
  double light_radius = 0;
  Bounds3 receiver;
};

// One triangle of one mesh.
struct FaceRef {
  const Mesh* mesh = nullptr;
  int face = -1;
};

// Clips every face of `faces` that may shadow the receiver (ShadowCaster) to
// near <= depth <= far along the frame's axis, and projects what remains from the frame's
// origin. Blocker parts behind the light or beyond the receiver cannot shadow it, and projecting
// a point at depth ≈ 0 would throw it to infinity.
ProjectedBlockers project_faces(const std::vector<FaceRef>& faces, const ProjectionFrame& frame,
                                double near, double far, const ShadowCaster& caster);

// The nearest-layer blocker image of one cluster: the fraction of each pixel's 4 × 4 sample
// points at which the blocker nearest the light's centre, among all polygons of `layer`, is one
// of the cluster's (mine[i] for polygon i) and lies at depth in [depth_lo, depth_hi). The
// clusters of one hierarchy thus have disjoint images that add up to the whole layer's coverage:
// each part of the hard shadow from the light's centre belongs to the cluster that casts it.
std::vector<float> nearest_layer_coverage(const ProjectedBlockers& layer,
                                          const std::vector<std::uint8_t>& mine, double depth_lo,
                                          double depth_hi, const TangentGrid& grid);

// Fraction of each grid pixel covered by the union of the polygons, from 4 × 4 sample points per
// pixel (exact where a pixel is wholly inside or outside a polygon). Row-major, width × height.
// With `section`, the union also takes the section of a closed solid at one depth: the samples
// whose ray from the light's centre crosses the section's polygons (the solid's whole surface
// clipped to depths before it, unculled) an odd number of times, i.e. enters the solid and has
// not left it. A slab of a solid then projects as the solid, not as the open shell of its faces
// (its far cap is never needed: from the light, a slab's inside is seen through its near cap or
// its faces).
std::vector<float> blocker_coverage(const ProjectedBlockers& blockers, const TangentGrid& grid,
                                    const ProjectedBlockers* section = nullptr);

}  // namespace sb
