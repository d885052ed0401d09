// The blockers' triangles in a bounding-volume hierarchy, with what shaft culling
// (shaft_culling.h) asks of each: its closed solid (blocker_solids.h), its neighbours across its
// edges, its mesh; per mesh its box and triangle count. Built once per bake by the surface area
// heuristic; searched by boxes and balls here, by shafts in shaft_culling.cpp.
// Written by hand: Embree's hierarchy answers rays, and its nodes cannot be walked by a query of
// planes (a shaft) or a box.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/geometry.h"
#include "occluders/blocker_solids.h"
#include "scene/mesh.h"

namespace sb {

struct BlockerHierarchy {
  using Box = Bounds3;

  struct Node {
    Box box;
    int first = 0, count = 0;  // leaf: triangles [first, first + count)
    int left = -1, right = -1;
    int size = 0;  // triangles under it: [first, first + size)
  };

  struct Tri {
    Vec3 v[3];
    Vec3 normal;  // unit (zero for a degenerate triangle, which blocks nothing)
    Vec3 lo, hi;  // bounding box
    // Of a closed component whose normals point out (its index in solids), or -1: from a
    // point outside the solid's box, a triangle facing away is never the first thing a ray meets.
    int solid = -1;
    int mesh = 0;                 // which blocker mesh it is of
    std::array<int, 3> across{};  // the triangle across edge (v[k], v[k+1]), or -1
    int source = 0;               // its index before the hierarchy's build reordered them
  };

  struct MeshInfo {
    Bounds3 bounds;
    std::size_t count = 0;
  };

  // The most nodes a traversal's stack holds: the build keeps its depth within it (past a
  // depth, blocker_hierarchy.cpp, it splits at the median, halving a node a level).
  static constexpr int kStack = 128;

  BlockerHierarchy() = default;
  explicit BlockerHierarchy(const std::vector<const Mesh*>& blockers);

  // The triangles (ascending indices) whose boxes meet `box`.
  void triangles_in_box(const Bounds3& box, std::vector<std::uint32_t>& out) const;
  // The triangles (ascending) nearer than `radius` to `centre`.
  std::vector<std::uint32_t> triangles_within(const Vec3& centre, double radius) const;

  std::vector<Tri> tris;               // in the hierarchy's order
  std::vector<Node> nodes;             // nodes[0] the root; none without triangles
  std::vector<BlockerSolid> solids;    // the closed, outward components (blocker_solids.h)
  std::vector<MeshInfo> meshes;        // per blocker mesh
  std::vector<std::uint32_t> of_face;  // per face of the blockers: its triangle's index

 private:
  int build(int first, int count, int depth = 0);
};

}  // namespace sb
