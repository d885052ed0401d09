// Shadow-ray queries against the scene's blockers, with Embree 3. Embree's types stay in
// ray_scene.cpp; the methods see only this class.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/error.h"
#include "core/geometry.h"
#include "scene/mesh.h"

namespace sb {

// How far a shadow ray's origin is pushed off its surface, and how much of its start it skips,
// in metres, for blockers within `bounds` (RayScene::surface_offset; ray_scene.cpp says why).
double surface_offset_for(const Bounds3& bounds);

class RayScene {
 public:
  // Builds the acceleration structure over the given meshes (world space). Safe to query from
  // many threads at once.
  static Expected<RayScene> build(const std::vector<const Mesh*>& blockers);

  RayScene(RayScene&&) noexcept;
  RayScene& operator=(RayScene&&) noexcept;
  ~RayScene();

  // Whether a blocker triangle (either side) lies on each segment origin + t·direction,
  // t ∈ [surface_offset() / |direction|, length] (direction need not be unit; length is in
  // units of |direction|), for `count` segments at once: 1 for an occluded segment in hit[i],
  // 0 otherwise.
  void occluded(int count, const Vec3* origins, const Vec3* directions, const double* lengths,
                std::uint8_t* hit) const;

  // Where the segment origin + t·direction, t ∈ [surface_offset() / |direction|, length], first
  // meets a blocker triangle (either side): that t, in units of |direction|, or a negative value
  // when it meets none. The closest-hit counterpart of occluded(), for methods that need the
  // distance to the blocker (erosion's penumbra width) and not only whether there is one.
  double first_hit(const Vec3& origin, const Vec3& direction, double length) const;

  // Answers `count` segments at once, writing each first hit's t (or a negative value) into t_hit.
  void first_hit(int count, const Vec3* origins, const Vec3* directions, const double* lengths,
                 double* t_hit) const;

  // The same for one segment, with the triangle it meets: its index among every face of the
  // blockers, mesh after mesh in the order given to build (ShaftCuller counts them so too), or
  // -1 when it meets none.
  struct Hit {
    double t = -1;
    std::int64_t face = -1;
  };
  Hit first_hit_face(const Vec3& origin, const Vec3& direction, double length) const;

  // Whether the point p of a surface whose face normal, turned to the side it is seen from, is
  // n (unit) is pressed against a surface facing it: a triangle crossing the segment from
  // 2·surface_offset() in front of p along n to a quarter of it behind (the floats' error) and
  // facing against n. That is another blocker's triangle, or one of blocker `own`'s (the point's
  // mesh, blocker_index; -1 where it is none) whose winding faces against `own_winding` (its
  // face's normal from its corners' order): a chair's leg joined to its seat. Such a point is
  // buried, an object resting on it or it on one, where one side of it is inside a closed surface
  // (most of five rays into it meet a face from behind first): every ray leaving it would start
  // beyond the surface that covers it, which the skipped start steps over. Two surfaces facing
  // the same way (a decal on a wall) do not bury each other, nor do the two faces of a two-sided
  // sheet (open on both sides).
  bool buried(const Vec3& p, const Vec3& n, int own, const Vec3& own_winding) const;

  // Whether the point lies inside solid geometry: of 26 rays from it spread over the sphere, at
  // least half meet a blocker triangle, and every one that does meets it from behind (its
  // winding's normal turned away from the point). A light there (a level's light inside a wall's
  // brush) sees no surface's front: it reaches nothing.
  bool inside_solid(const Vec3& p) const;

  // A mesh's place among the blockers given to build that have faces (as buried() counts
  // them), or -1 for one that is not among them.
  int blocker_index(const Mesh* mesh) const;

  // The blockers' bounding box (empty when there are none).
  const Bounds3& bounds() const;

  // How far a shadow ray's origin is pushed off its surface, in metres: enough to step over
  // the single-precision error of a triangle position anywhere in the scene, small against any
  // gap that should cast a shadow (see ray_scene.cpp).
  double surface_offset() const;

 private:
  struct Impl;
  explicit RayScene(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace sb
