// Blocker clusters (docs/design.md §5, "blocker subdivision"; Soler & Sillion,
// docs/design.md [S1]). Splits every blocker mesh into its connected
// components and each component into a binary tree of spatially coherent clusters, each with the
// vertices of its convex hull, so that a cluster's depth range along any direction is exact and
// cheap; marks the convex components (they cannot shadow themselves); and culls the tree against
// the shaft between a light and a receiver part.
//
// Why CGAL: connected components run directly on the OpenMesh mesh through CGAL's graph traits,
// and convex_hull_3 / extreme_points_3 decide orientations with exact predicates (Epick), so
// coplanar and nearly degenerate point sets still give the right hull. This is the only
// translation unit that includes CGAL; CMakeLists.txt compiles it apart, because CGAL::CGAL adds
// -frounding-math, which the rest of the library must not get.
#include "occluders/clusters.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/boost/graph/graph_traits_TriMesh_ArrayKernelT.h>
#include <CGAL/convex_hull_3.h>

#include <boost/property_map/vector_property_map.hpp>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <limits>
#include <map>
#include <numeric>

namespace sb {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point3 = Kernel::Point_3;

Vec3 to_vec(const Point3& p) { return Vec3(p.x(), p.y(), p.z()); }
Vec3 to_vec(const TriMesh::Point& p) { return Vec3(p[0], p[1], p[2]); }

// Tolerances, as fractions of the size (bounding-box diagonal) of what is compared.
// kConvexTolerance: a component's faces against its vertices. Not tighter: meshes stored with six
// decimals tilt the small faces near a cone's apex by 4e-6 of its size (scenes/showcase/cone.obj),
// and a dent of 1e-4 of an object's size shadows less than a texel.
constexpr double kConvexTolerance = 1e-4;
constexpr double kShaftTolerance = 1e-6;  // points against the shaft's planes; box thickness

// The vertices of the convex hull of `points` (a subset of them, so depth ranges stay exact).
// extreme_points_3 gives the 3-D hull's vertices, or the 2-D hull's for coplanar points. Its
// collinear case in CGAL 5.5 returns the first point and the one farthest from it, which misses
// an end when the first point lies inside the segment, so fewer than three extreme points fall
// back to all the points (only degenerate input is collinear: faces have non-zero area).
std::vector<Vec3> convex_hull_vertices(const std::vector<Vec3>& points) {
  std::vector<Point3> input;
  input.reserve(points.size());
  for (const Vec3& p : points) input.emplace_back(p.x(), p.y(), p.z());
  std::vector<Point3> extreme;
  CGAL::extreme_points_3(input, std::back_inserter(extreme));
  if (extreme.size() < 3) return points;
  std::vector<Vec3> hull;
  hull.reserve(extreme.size());
  for (const Point3& p : extreme) hull.push_back(to_vec(p));
  return hull;
}

// An edge by the positions of its ends, lower first, on a grid of `quantum` metres: the same for
// both halfedges, and for the copies of an edge on either side of a seam of split vertices,
// whose positions may differ in the last bits (a sphere's seam at longitude 0 and 2π).
using EdgeKey = std::array<std::int64_t, 6>;
EdgeKey edge_key(const TriMesh& mesh, OpenMesh::HalfedgeHandle h, double quantum) {
  const auto& p = mesh.point(mesh.from_vertex_handle(h));
  const auto& q = mesh.point(mesh.to_vertex_handle(h));
  std::array<std::int64_t, 3> a, b;
  for (int k = 0; k < 3; ++k) {
    a[k] = std::llround(p[k] / quantum);
    b[k] = std::llround(q[k] / quantum);
  }
  if (b < a) std::swap(a, b);
  return {a[0], a[1], a[2], b[0], b[1], b[2]};
}

// The grid for edge_key: a millionth of the mesh's bounding-box diagonal.
double weld_quantum(const TriMesh& mesh) {
  Bounds3 box;
  for (auto v : mesh.vertices()) box.extend(to_vec(mesh.point(v)));
  return std::max(1e-6 * box.diagonal(), 1e-12);
}

// Per face (by idx()), its connected component: CGAL's components, where faces meet when they
// share an edge, then joined across seams. Imported meshes split vertices wherever UVs or
// normals jump (a box's six sides, a sphere's UV seam), which cuts one object into pieces that
// touch edge to edge; pieces with an edge at the same two positions are one component. Pieces
// that touch at a vertex only (a table's legs under its top) stay apart.
std::vector<int> face_components(const TriMesh& mesh, int* count) {
  using FaceIndexMap = boost::property_map<TriMesh, CGAL::face_index_t>::const_type;
  const FaceIndexMap face_index = get(CGAL::face_index, mesh);
  boost::vector_property_map<std::size_t, FaceIndexMap> component(
      static_cast<unsigned>(mesh.n_faces()), face_index);
  const auto pieces = CGAL::Polygon_mesh_processing::connected_components(mesh, component);

  std::vector<std::size_t> parent(pieces);
  std::iota(parent.begin(), parent.end(), std::size_t{0});
  auto find = [&](std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  std::map<EdgeKey, std::size_t> piece_of_edge;
  const double quantum = weld_quantum(mesh);
  for (auto h : mesh.halfedges()) {
    if (mesh.is_boundary(h)) continue;
    const EdgeKey key = edge_key(mesh, h, quantum);
    const std::size_t piece = component[mesh.face_handle(h)];
    const auto [it, inserted] = piece_of_edge.emplace(key, piece);
    if (!inserted) parent[find(piece)] = find(it->second);
  }
  // Components numbered in the order of their first face.
  std::vector<int> number(pieces, -1);
  std::vector<int> out(mesh.n_faces(), -1);
  *count = 0;
  for (auto f : mesh.faces()) {
    int& n = number[find(component[f])];
    if (n < 0) n = (*count)++;
    out[f.idx()] = n;
  }
  return out;
}

// Builds one component's subtree: bounds and hull per node, children split at the median centroid.
class TreeBuilder {
 public:
  TreeBuilder(ClusterTree& tree, const TriMesh& mesh, int mesh_index, int leaf_faces)
      : tree_(tree), mesh_(mesh), mesh_index_(mesh_index), leaf_faces_(std::max(leaf_faces, 1)) {
    centroids_.resize(mesh.n_faces());
    for (auto f : mesh.faces()) {
      Vec3 sum = Vec3::Zero();
      int n = 0;
      for (auto v : mesh.fv_range(f)) {
        sum += to_vec(mesh.point(v));
        ++n;
      }
      centroids_[f.idx()] = sum / std::max(n, 1);
    }
  }

  // Returns the new node's index; the subtree's nodes follow it in tree.nodes.
  int build(int component, std::vector<int> faces) {
    const int index = static_cast<int>(tree_.nodes.size());
    tree_.nodes.emplace_back();
    Bounds3 bounds;
    std::vector<int> vertices;
    for (int f : faces) {
      for (auto v : mesh_.fv_range(mesh_.face_handle(f))) {
        bounds.extend(to_vec(mesh_.point(v)));
        vertices.push_back(v.idx());
      }
    }
    std::vector<Vec3> hull_input;
    int children[2] = {-1, -1};
    if (static_cast<int>(faces.size()) <= leaf_faces_) {
      std::sort(vertices.begin(), vertices.end());
      vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
      for (int v : vertices) hull_input.push_back(to_vec(mesh_.point(mesh_.vertex_handle(v))));
    } else {
      int axis = 0;
      (bounds.hi - bounds.lo).maxCoeff(&axis);
      const auto middle = faces.begin() + static_cast<std::ptrdiff_t>(faces.size() / 2);
      std::nth_element(faces.begin(), middle, faces.end(),
                       [&](int a, int b) { return centroids_[a][axis] < centroids_[b][axis]; });
      children[0] = build(component, std::vector<int>(faces.begin(), middle));
      children[1] = build(component, std::vector<int>(middle, faces.end()));
      // The hull of a union is the hull of the parts' hulls.
      for (int child : children) {
        const auto& part = tree_.nodes[child].hull;
        hull_input.insert(hull_input.end(), part.begin(), part.end());
      }
    }
    Cluster& node = tree_.nodes[index];
    node.mesh = mesh_index_;
    node.component = component;
    node.faces = std::move(faces);
    node.bounds = bounds;
    node.hull = convex_hull_vertices(hull_input);
    node.children[0] = children[0];
    node.children[1] = children[1];
    return index;
  }

 private:
  ClusterTree& tree_;
  const TriMesh& mesh_;
  int mesh_index_;
  int leaf_faces_;
  std::vector<Vec3> centroids_;  // per face
};

// True when the subtree's geometry lies on or behind the plane normal·x = offset (+ tolerance).
// Bounding boxes prune: far parts of a convex component are behind a face's plane by a margin.
bool subtree_behind(const ClusterTree& tree, int node, const Vec3& normal, double offset,
                    double tolerance) {
  const Cluster& cluster = tree.nodes[node];
  Vec3 farthest_corner;
  for (int k = 0; k < 3; ++k) {
    farthest_corner[k] = normal[k] >= 0 ? cluster.bounds.hi[k] : cluster.bounds.lo[k];
  }
  if (normal.dot(farthest_corner) <= offset + tolerance) return true;
  if (cluster.leaf()) {
    return std::all_of(cluster.hull.begin(), cluster.hull.end(),
                       [&](const Vec3& p) { return normal.dot(p) <= offset + tolerance; });
  }
  return subtree_behind(tree, cluster.children[0], normal, offset, tolerance) &&
         subtree_behind(tree, cluster.children[1], normal, offset, tolerance);
}

// Convex when every face's plane (normal from the face's winding) has the whole component
// on or behind it. Zero-area faces have no plane and are skipped.
bool component_is_convex(const ClusterTree& tree, int root, const TriMesh& mesh) {
  const Cluster& cluster = tree.nodes[root];
  const double tolerance = kConvexTolerance * cluster.bounds.diagonal();
  for (int f : cluster.faces) {
    std::array<Vec3, 3> p;
    int i = 0;
    for (auto v : mesh.fv_range(mesh.face_handle(f))) {
      if (i < 3) p[i] = to_vec(mesh.point(v));
      ++i;
    }
    const Vec3 cross = (p[1] - p[0]).cross(p[2] - p[0]);
    const double length = cross.norm();
    if (!(length > 0)) continue;
    const Vec3 normal = cross / length;
    if (!subtree_behind(tree, root, normal, normal.dot(p[0]), tolerance)) return false;
  }
  return true;
}

// Closed when every edge, keyed by its end positions (seams of split vertices join), borders
// exactly two of the component's faces.
bool component_is_closed(const TriMesh& mesh, const std::vector<int>& faces, double quantum) {
  std::map<EdgeKey, int> edge_faces;
  for (int f : faces) {
    for (auto h : mesh.fh_range(mesh.face_handle(f))) ++edge_faces[edge_key(mesh, h, quantum)];
  }
  return !edge_faces.empty() && std::all_of(edge_faces.begin(), edge_faces.end(),
                                            [](const auto& e) { return e.second == 2; });
}

}  // namespace

void Cluster::depth_range(const Vec3& origin, const Vec3& axis, double* lo, double* hi) const {
  double smallest = std::numeric_limits<double>::infinity();
  double largest = -std::numeric_limits<double>::infinity();
  for (const Vec3& p : hull) {
    const double depth = (p - origin).dot(axis);
    smallest = std::min(smallest, depth);
    largest = std::max(largest, depth);
  }
  *lo = smallest;
  *hi = largest;
}

ClusterTree build_clusters(const std::vector<const Mesh*>& meshes, int leaf_faces) {
  ClusterTree tree;
  tree.face_component.resize(meshes.size());
  tree.component_convex.resize(meshes.size());
  tree.component_closed.resize(meshes.size());
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    assert(meshes[m] != nullptr);
    const TriMesh& mesh = meshes[m]->mesh;
    int count = 0;
    tree.face_component[m] = face_components(mesh, &count);
    std::vector<std::vector<int>> component_faces(static_cast<std::size_t>(count));
    for (auto f : mesh.faces()) component_faces[tree.face_component[m][f.idx()]].push_back(f.idx());

    TreeBuilder builder(tree, mesh, static_cast<int>(m), leaf_faces);
    const double quantum = weld_quantum(mesh);
    for (int c = 0; c < count; ++c) {
      tree.component_closed[m].push_back(
          component_is_closed(mesh, component_faces[c], quantum) ? 1 : 0);
      const int root = builder.build(c, std::move(component_faces[c]));
      tree.roots.push_back(root);
      tree.component_convex[m].push_back(component_is_convex(tree, root, mesh) ? 1 : 0);
    }
  }
  return tree;
}

Shaft::Shaft(const std::vector<Vec3>& light_points, const Bounds3& receiver) {
  Bounds3 extent = receiver;
  for (const Vec3& p : light_points) extent.extend(p);
  if (extent.empty()) return;  // nothing to bound: no planes, so nothing is ever culled
  const double size = std::max(extent.diagonal(), 1e-9);
  tolerance_ = kShaftTolerance * size;

  // A flat (or empty) receiver box gets a little thickness so the hull is always a solid.
  Bounds3 box = receiver.empty() ? Bounds3{extent.centre(), extent.centre()} : receiver;
  for (int k = 0; k < 3; ++k) {
    if (box.hi[k] - box.lo[k] < tolerance_) {
      const double middle = 0.5 * (box.lo[k] + box.hi[k]);
      box.lo[k] = middle - 0.5 * tolerance_;
      box.hi[k] = middle + 0.5 * tolerance_;
    }
  }
  std::vector<Vec3> points;
  for (int corner = 0; corner < 8; ++corner) {
    points.emplace_back(corner & 1 ? box.hi.x() : box.lo.x(), corner & 2 ? box.hi.y() : box.lo.y(),
                        corner & 4 ? box.hi.z() : box.lo.z());
  }
  points.insert(points.end(), light_points.begin(), light_points.end());

  // The hull's face planes, found by brute force over the points' triples rather than by
  // CGAL::convex_hull_3: its facets of these degenerate inputs (a box 1e-6 thick, coplanar light
  // outlines) depend on the order it meets vertices in, which follows their memory addresses, so
  // two runs (two threads planning two halves of a light) got different shafts and plans. A
  // triple spans a face plane when no point lies beyond its plane by more than the tolerance;
  // each such plane is kept through the farthest point (so it never cuts the hull), in the order
  // the triples come: a function of the points alone. At most 24 points: ~2000 triples, most
  // refused after a few points.
  const std::size_t n = points.size();
  const double min_cross = 1e-12 * size * size;
  const auto add = [&](const Vec3& normal, double offset) {
    for (std::size_t i = 0; i < normals_.size(); ++i)
      if (normals_[i].dot(normal) > 1 - 1e-12 && std::abs(offsets_[i] - offset) <= tolerance_)
        return;
    normals_.push_back(normal);
    offsets_.push_back(offset);
  };
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      for (std::size_t k = j + 1; k < n; ++k) {
        Vec3 normal = (points[j] - points[i]).cross(points[k] - points[i]);
        const double length = normal.norm();
        if (!(length > min_cross)) continue;
        normal /= length;
        const double on = normal.dot(points[i]);
        // Which sides the other points lie on, beyond the tolerance; stop once both.
        bool above = false, below = false;
        double hi = on, lo = on;
        for (std::size_t m = 0; m < n && !(above && below); ++m) {
          const double d = normal.dot(points[m]);
          hi = std::max(hi, d);
          lo = std::min(lo, d);
          above = above || d > on + tolerance_;
          below = below || d < on - tolerance_;
        }
        if (!above) add(normal, hi);
        if (!below) add(-normal, -lo);
      }
}

bool Shaft::may_contain_any(const std::vector<Vec3>& points) const {
  if (points.empty()) return false;
  for (std::size_t i = 0; i < normals_.size(); ++i) {
    const bool all_outside = std::all_of(points.begin(), points.end(), [&](const Vec3& p) {
      return normals_[i].dot(p) > offsets_[i] + tolerance_;
    });
    if (all_outside) return false;
  }
  return true;
}

bool Shaft::contains_all(const std::vector<Vec3>& points) const {
  for (std::size_t i = 0; i < normals_.size(); ++i) {
    for (const Vec3& p : points) {
      if (normals_[i].dot(p) > offsets_[i] + tolerance_) return false;
    }
  }
  return true;
}

std::vector<int> clusters_in_shaft(const ClusterTree& tree, const Shaft& shaft) {
  std::vector<int> kept;
  std::vector<int> pending(tree.roots.rbegin(), tree.roots.rend());
  while (!pending.empty()) {
    const int index = pending.back();
    pending.pop_back();
    const Cluster& cluster = tree.nodes[index];
    if (!shaft.may_contain_any(cluster.hull)) continue;
    if (cluster.leaf() || shaft.contains_all(cluster.hull)) {
      kept.push_back(index);
      continue;
    }
    pending.push_back(cluster.children[1]);
    pending.push_back(cluster.children[0]);
  }
  return kept;
}

}  // namespace sb
