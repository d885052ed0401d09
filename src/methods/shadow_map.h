// Shadow maps for the filtering baselines (docs/design.md §7): a perspective depth image of the
// blockers seen from a light's centre, the frusta that cover a receiver's lit texels, and the
// depth test of a receiver point against the image (shadow_map.cpp). The filters that read it
// (PCF, PCSS, adaptive PCF, Chun–Oh) are in shadow_map_bake.cpp.
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

#include "core/geometry.h"
#include "methods/baselines.h"
#include "occluders/projection_frame.h"
#include "scene/mesh.h"

namespace sb {

// Depth image of a frustum: pixel (x, y) holds the depth along frame.axis (metres) of the
// nearest blocker on the ray from the frame's origin through the tangent point of its centre,
// +infinity where the ray meets no blocker. Tangent coordinates are those of ProjectionFrame;
// pixel (x, y) covers tangent [−h + x·pixel, −h + (x + 1)·pixel] along e1 (y along e2).
struct ShadowMap {
  ProjectionFrame frame;
  double half_extent = 1;  // h, tangent units: the map covers [−h, h]²
  int size = 0;            // pixels per side
  double pixel = 0;        // tangent units per pixel, 2h / size
  double near = 0;         // metres along the axis; blocker parts nearer the light are clipped
  double nearest = std::numeric_limits<double>::infinity();  // smallest depth stored
  std::vector<float> depth;                                  // size², row-major

  // Continuous pixel coordinates of a tangent point (pixel centres at integers).
  Vec2 to_pixel(const Vec2& tangent) const {
    return (tangent + Vec2::Constant(half_extent)) / pixel - Vec2::Constant(0.5);
  }
  // The stored depth, +infinity outside the map (nothing known there counts as unoccluded).
  float at(int x, int y) const {
    if (x < 0 || y < 0 || x >= size || y >= size) return std::numeric_limits<float>::infinity();
    return depth[std::size_t(y) * size + x];
  }
};

// Rasterises every triangle of `blockers` (either side) into a size × size depth image of the
// frustum: clipped against depth >= near, projected, and z-buffered with 1/depth interpolated
// linearly in the image (exact under perspective). Parallel over bands of rows with oneTBB.
ShadowMap render_shadow_map(const std::vector<const Mesh*>& blockers, const ProjectionFrame& frame,
                            double half_extent, int size, double near);

// One frustum of a light: the receiver points (indices into the caller's list) it serves.
struct ShadowFrustum {
  ProjectionFrame frame;
  double half_extent = 1;  // tangent units, margin included
  double near = 0;         // metres
  std::vector<std::size_t> points;
  const char* part = "";  // "" for one frustum; "+x" … "-z" for a cube face
};

// The frusta that cover `points` (receiver positions lit by a light centred at `centre`), like
// the convolution method's (occluders/light_frusta.h): one frustum with its axis towards the
// middle of their bounding box when every point lies within kMaxFrustumHalfAngleDeg (60°) of
// that axis, otherwise the six faces of a cube around the light, each point to the face of its
// dominant direction. Each square frustum is fitted to its
// points' largest tangent coordinate and widened by `margin` (a fraction) so that the filters'
// footprints around the outermost points stay inside it.
std::vector<ShadowFrustum> fit_frusta(const Vec3& centre, const std::vector<Vec3>& points,
                                      double margin);

// A receiver point as the depth test sees it: where it falls in the map, its depth, and the
// plane of its triangle, whose depth on every ray through the map is known in closed form.
//
// Depth bias. The test at pixel (x, y) counts a blocker when the stored depth is less than
//   min(plane depth on that pixel's ray, d_r) − bias.
// - The plane term is the "receiver plane depth bias": the slope-scaled bias made exact for every
//   offset of a filter footprint, where a single slope term sized for the footprint's centre
//   cannot serve the tens of pixels of a PCSS footprint at a grazing angle. The receiver's own
//   surface, stored at that pixel, lies on that plane and passes.
// - d_r (the point's own depth) caps it: a blocker beyond the point's depth lies on no segment
//   from the light to the point. Where the plane recedes (a floor seen at a grazing angle) this
//   keeps a wall behind the point, met by a tap beyond the corner, from darkening the floor along
//   the wall (ShadowMap.ConcaveCornerDoesNotDarkenTheFloorAlongAWall); a ray that meets the plane
//   at no positive depth (beyond its horizon) has only this cap.
// - bias, a constant, is one shadow-map pixel's world footprint at the receiver (pixel · d_r):
//   what is left to cover is the difference between the surface stored at a pixel and the
//   receiver's plane there (float rounding, neighbouring triangles of a tessellated surface). A
//   blocker standing on the receiver starts to shadow it within a few millimetres of the contact
//   at 2048² (ShadowMap.BiasKeepsAThinWallsShadowAtItsBase, which 30 pixels fail). On a convex
//   surface the neighbouring triangles lie behind the tangent plane and pass whatever the bias.
struct ReceiverPoint {
  Vec2 at;           // continuous pixel coordinates of the point
  Vec2 tangent;      // its tangent coordinates
  double depth = 0;  // d_r: depth along the axis, metres
  double bias = 0;   // metres
  // The plane's depth on the ray through pixel (x, y) is plane_c / (plane_a + plane_bx·x +
  // plane_by·y).
  double plane_c = 0, plane_a = 0, plane_bx = 0, plane_by = 0;

  // The depth a blocker must be nearer than (less the bias) to shadow the point through pixel
  // (x, y): the plane's depth there, capped at the point's own.
  double limit(double x, double y) const {
    const double z = plane_c / (plane_a + plane_bx * x + plane_by * y);
    return z > 0 && z < depth ? z : depth;
  }
};

// The receiver's plane through `position` with unit `normal` (either side): the bake passes the
// texel's shadow_origin and shading normal, the triangle's own point and normal on flat faces.
ReceiverPoint receiver_point(const ShadowMap& map, const Vec3& position, const Vec3& normal);

// Whether pixel (x, y) holds a blocker in front of the receiver's plane, and its depth if so.
inline bool blocked(const ShadowMap& map, const ReceiverPoint& r, int x, int y, double* depth) {
  const float stored = map.at(x, y);
  if (stored == std::numeric_limits<float>::infinity()) return false;
  if (double(stored) >= r.limit(x, y) - r.bias) return false;
  if (depth) *depth = stored;
  return true;
}

// Percentage-closer lookup at continuous pixel coordinates: the four depth tests around `at`,
// weighted bilinearly (the hardware PCF of Uralsky's §17.2.3). The lit fraction, in [0, 1].
double lit_fraction(const ShadowMap& map, const ReceiverPoint& r, const Vec2& at);

// Options of the shadow-map baselines that scenes do not set; tests use them to compare a
// method with its own variants on identical samples. Implemented in shadow_map_bake.cpp.
struct ShadowFilterOptions {
  bool adaptive_always_full = false;  // adaptive-pcf takes its full sample set at every texel
};
MixedImages bake_shadow_map_filter(const TexelSpace& space, const BaselineInputs& in,
                                   MethodStats* stats, const ShadowFilterOptions& options);

}  // namespace sb
