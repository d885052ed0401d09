// The cluster hierarchy of the scene's blocker geometry (docs/design.md §5; Soler & Sillion's
// "blocker subdivision", docs/design.md [S1]), built with CGAL on the
// OpenMesh meshes in clusters.cpp, the one translation unit that includes CGAL.
//
// Each mesh is split into its connected components; each component into a binary tree of
// spatially coherent clusters. A cluster keeps its triangles, its bounding box and the vertices
// of its convex hull, so its depth range along any projection direction D is exact and cheap
// (the extremes of a linear function over a point set lie on its hull).
#pragma once

#include <cstdint>
#include <vector>

#include "core/geometry.h"
#include "scene/mesh.h"

namespace sb {

struct Cluster {
  int mesh = -1;               // index into the meshes given to build_clusters
  int component = -1;          // connected component of that mesh
  std::vector<int> faces;      // face indices (OpenMesh idx()) of the mesh, all of the subtree
  Bounds3 bounds;              // of the faces' vertices
  std::vector<Vec3> hull;      // vertices of the convex hull of the faces' vertices
  int children[2] = {-1, -1};  // node indices; both -1 for a leaf

  bool leaf() const { return children[0] < 0; }
  // Smallest and largest (p − origin)·axis over the cluster's geometry, metres.
  void depth_range(const Vec3& origin, const Vec3& axis, double* lo, double* hi) const;
};

struct ClusterTree {
  std::vector<Cluster> nodes;
  std::vector<int> roots;  // one node per connected component of every mesh, in mesh order
  // Per mesh, per face: its connected component. Faces sharing an edge, or an edge's two
  // positions across a seam of split vertices (UV or normal seams), are connected; faces meeting
  // at a vertex only are not.
  std::vector<std::vector<int>> face_component;
  // Per mesh, per component: whether the component is convex (every face's plane has all of the
  // component on or behind it, within 1e-4 of its bounding-box diagonal). A convex component cannot
  // shadow itself beyond its own horizon, which H0 already accounts for; a single planar patch is
  // convex.
  std::vector<std::vector<std::uint8_t>> component_convex;
  // Per mesh, per component: whether it is closed (watertight): every edge, by its two end
  // positions so that seams of split vertices count as joined, has exactly two faces. A closed
  // component bounds a solid, so a slab of it can be capped (convolution_plan.cpp).
  std::vector<std::vector<std::uint8_t>> component_closed;
};

// Builds the hierarchy. Leaves hold at most `leaf_faces` faces; an inner node splits its faces
// in two at the median of their centroids along the longest axis of its bounding box.
ClusterTree build_clusters(const std::vector<const Mesh*>& meshes, int leaf_faces = 64);

// The shaft between a light and a receiver part: the convex hull of the light's outline points
// and the receiver part's bounding box corners, kept as its face planes (found by brute force
// over the points' triples, so that they depend on the points alone: clusters.cpp).
// A flat receiver box gets a tiny thickness (1e-6 of the shaft's size), so the shaft is always a
// solid; points within that same tolerance outside a plane count as inside.
class Shaft {
 public:
  Shaft(const std::vector<Vec3>& light_points, const Bounds3& receiver);
  // False only when the points certainly lie outside the shaft (all strictly outside one of its
  // face planes); conservative otherwise.
  bool may_contain_any(const std::vector<Vec3>& points) const;
  // True when every point lies inside (or on) the shaft.
  bool contains_all(const std::vector<Vec3>& points) const;

 private:
  std::vector<Vec3> normals_;    // outward, unit
  std::vector<double> offsets_;  // plane: normal·x = offset
  double tolerance_ = 0;         // metres; points this close outside a plane count as inside
};

// The faces (per mesh, as (mesh, face) pairs grouped by cluster) that may lie in the shaft:
// walks the tree from the roots, drops subtrees outside the shaft, keeps whole subtrees inside
// it, and descends into the others down to the leaves. Returns node indices whose faces are the
// candidate blockers: depth first in root order, none an ancestor of another, so every face
// appears at most once. Never drops a face that meets the shaft.
std::vector<int> clusters_in_shaft(const ClusterTree& tree, const Shaft& shaft);

}  // namespace sb
