// Which receiver texels a light reaches with nothing in the way, decided exactly (up to a
// conservative margin) instead of estimated: a texel's shaft is the convex hull of its shadow
// origin and the light; when no blocker triangle meets that hull, every shadow ray the texel
// could send reaches the light, and its visibility of that light is 1 without a ray or an image.
// On a scene as artists make them most (light, texel) pairs are such: a floor is in shadow only
// under and beside its furniture. The methods spend their work on the rest (shaft_culling.cpp).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/geometry.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "texels/texel_space.h"

namespace sb {

struct BlockerSolid;

// A blocker triangle clipped to one texel's shaft: a convex polygon in world space, every point
// of which lies between the texel's ray origin and the light.
struct ShaftPolygon {
  // A triangle clipped by at most 10 planes (8 sides of a disk's octagon, the light's plane, the
  // texel's horizon) has at most 13 corners.
  static constexpr int kMaxVertices = 16;
  std::array<Vec3, kMaxVertices> v;
  int count = 0;
  std::uint32_t triangle = 0;  // its index in the culler's hierarchy
  Vec3 normal = Vec3::Zero();  // the triangle's unit normal
};

class ShaftCuller {
 public:
  // A bounding volume hierarchy over every triangle of `blockers` (world space).
  explicit ShaftCuller(const std::vector<const Mesh*>& blockers);
  ShaftCuller(ShaftCuller&&) noexcept;
  ShaftCuller& operator=(ShaftCuller&&) noexcept;
  ~ShaftCuller();

  // Per texel of `space`: 1 where some blocker triangle may lie in the shaft between the texel's
  // shadow origin (lifted by `offset` along its face normal, as the reference's rays start) and
  // `light`, 0 where none can (or the light does not reach the texel). Parallel over texels; the
  // same result for any thread count.
  std::vector<std::uint8_t> maybe_blocked(const TexelSpace& space, const Light& light,
                                          double offset) const;

  // The triangles a tile of texels must look at for `light`: those that may lie in the shaft of
  // some point of `origins` (the box of the tile's ray origins). False when none may: every texel
  // of the tile is clear of the light. True with `candidates` listing them, or with `candidates`
  // empty when more than `max` may, or the light reaches only part of the box: then each texel
  // searches the whole hierarchy. With `among` (the candidates of a box holding `origins`), only
  // those are tested: a triangle in this box's shaft is in the larger box's, so it is among them.
  bool tile_candidates(const Bounds3& origins, const Light& light, std::size_t max,
                       std::vector<std::uint32_t>& candidates,
                       const std::vector<std::uint32_t>* among = nullptr) const;

  // Every blocker triangle in the shaft from the ray origin `origin` (above the surface point
  // `surface`, shading normal `normal`) to `light`, clipped to that shaft, into `out`; among
  // `among` when given (a tile's candidates), else the whole hierarchy. The same triangles, in
  // the same order, for the same inputs.
  enum class Polygons {
    listed,     // `out` holds them all (none: the shaft is clear)
    unreached,  // the light does not reach the point; `out` is empty
    too_many    // more than `max`: `out` holds the first `max` only
  };
  Polygons shaft_polygons(const Vec3& origin, const Vec3& surface, const Vec3& normal,
                          const Light& light, const std::vector<std::uint32_t>* among,
                          std::size_t max, std::vector<ShaftPolygon>& out) const;

  // The same for one ray origin, above the surface point `surface` whose shading normal is
  // `normal`: true when a blocker may lie in its shaft; among `among` when given, and counting
  // only triangles whose blocker_key is not in `except` (sorted) when given.
  bool maybe_blocked(const Vec3& origin, const Vec3& surface, const Vec3& normal,
                     const Light& light, const std::vector<std::uint32_t>* among = nullptr,
                     const std::vector<std::uint32_t>* except = nullptr) const;

  // The triangles that pass within `radius` of `centre` (a sphere light's ball), ascending.
  std::vector<std::uint32_t> triangles_within(const Vec3& centre, double radius) const;
  // The triangles whose bounding boxes meet `box`, into `out` (cleared), ascending.
  void triangles_in_box(const Bounds3& box, std::vector<std::uint32_t>& out) const;

  // A triangle's bounding box, its three corners and its unit normal (by its index in the
  // hierarchy, as ShaftPolygon::triangle and tile_candidates give it).
  Bounds3 triangle_bounds(std::uint32_t triangle) const;
  const Vec3* triangle_corners(std::uint32_t triangle) const;
  // The triangle across a triangle's edge (corners[edge], corners[edge + 1]) that has that edge
  // the other way round, or -1 (a border, or more than two triangles on it).
  int neighbour(std::uint32_t triangle, int edge) const;
  std::size_t triangle_count() const;
  // A triangle's index in the hierarchy from its index among every face of the blockers, mesh
  // after mesh in the order given (RayScene::Hit::face).
  std::uint32_t triangle_of_face(std::int64_t face) const;
  // The index, among the blockers it was built from, of the mesh a triangle is of.
  int mesh_of(std::uint32_t triangle) const;
  // The closed solid a triangle belongs to (blocker_solids.h), or null.
  const BlockerSolid* solid(std::uint32_t triangle) const;
  // What a triangle counts as where blockers are listed: its convex solid (kSolidKey | its
  // index) when it belongs to one; else its mesh (kMeshKey | its index) when that is dense (more
  // than kDenseMesh triangles, taken through their outline); else itself. And the bounds of
  // what a key stands for.
  static constexpr std::uint32_t kSolidKey = 0x80000000u;
  static constexpr std::uint32_t kMeshKey = 0x40000000u;
  static constexpr std::size_t kDenseMesh = 256;
  std::uint32_t blocker_key(std::uint32_t triangle) const { return keys_[triangle]; }
  Bounds3 key_bounds(std::uint32_t key) const;
  const BlockerSolid& solid_of_key(std::uint32_t key) const;
  // The solids with an inner ball (BlockerSolid::inner_radius) that a key's triangles belong
  // to, as keys (kSolidKey | index): a dense mesh's, or a single triangle's; none for a key that
  // is a convex solid's.
  std::span<const std::uint32_t> solids_with_balls(std::uint32_t key) const;
  const Vec3& triangle_normal(std::uint32_t triangle) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<std::uint32_t> keys_;  // per triangle, its blocker_key (read in inner loops)
};

}  // namespace sb
