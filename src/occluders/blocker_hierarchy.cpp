// BlockerHierarchy (blocker_hierarchy.h).
#include "occluders/blocker_hierarchy.h"

#include <tbb/parallel_invoke.h>

#include <algorithm>

#include "core/nearest_point.h"

namespace sb {

namespace {

using Box = BlockerHierarchy::Box;
using Tri = BlockerHierarchy::Tri;

constexpr int kLeafSize = 4;
// The hierarchy's build: bins of the surface area heuristic, and the depth past which it splits
// at the median (the traversal's stack holds kStack nodes; a balanced split adds one a level).
constexpr int kBins = 16;
constexpr int kMaxDepth = 48;
static_assert(kMaxDepth < BlockerHierarchy::kStack);

Vec3 centroid(const Tri& t) { return (t.v[0] + t.v[1] + t.v[2]) / 3.0; }

double area(const Box& b) {
  if (!(b.hi.x() >= b.lo.x())) return 0;
  const Vec3 e = b.hi - b.lo;
  return 2 * (e.x() * e.y() + e.y() * e.z() + e.z() * e.x());
}

int bin_of(double c, double lo, double extent) {
  return std::clamp(int(kBins * (c - lo) / extent), 0, kBins - 1);
}

}  // namespace

BlockerHierarchy::BlockerHierarchy(const std::vector<const Mesh*>& blockers) {
  std::vector<std::array<Vec3, 3>> corners;
  std::vector<std::size_t> mesh_ends;
  for (const Mesh* m : blockers) {
    for (const auto f : m->mesh.faces()) {
      const Triangle tri = triangle(m->mesh, f);
      Tri t;
      t.mesh = int(mesh_ends.size());
      t.source = int(tris.size());
      for (int k = 0; k < 3; ++k) t.v[k] = tri.p[k];
      const Vec3 cross = (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]);
      const double len = cross.norm();
      t.normal = len > 0 ? Vec3(cross / len) : Vec3::Zero();
      t.lo = t.v[0].cwiseMin(t.v[1]).cwiseMin(t.v[2]);
      t.hi = t.v[0].cwiseMax(t.v[1]).cwiseMax(t.v[2]);
      tris.push_back(t);
      corners.push_back({t.v[0], t.v[1], t.v[2]});
    }
    mesh_ends.push_back(tris.size());
  }
  // The solids and the tree do not depend on each other: found side by side (a dense mesh's
  // 100,000 triangles take a tenth of a second each), the solids then given to each triangle
  // by its index in the input.
  BlockerSolids found;
  tbb::parallel_invoke([&] { found = find_solids(corners, mesh_ends); },
                       [&] {
                         if (tris.empty()) return;
                         nodes.reserve(2 * tris.size() / kLeafSize + 2);
                         build(0, int(tris.size()));
                       });
  for (Tri& t : tris) t.solid = found.solid_of[std::size_t(t.source)];
  solids = std::move(found.solids);
  // Neighbours across edges, renumbered to where the build put each triangle.
  std::vector<int> where(tris.size());
  for (std::size_t i = 0; i < tris.size(); ++i) where[std::size_t(tris[i].source)] = int(i);
  of_face.assign(where.begin(), where.end());
  for (Tri& t : tris)
    for (int k = 0; k < 3; ++k) {
      const int n = found.across[std::size_t(t.source)][std::size_t(k)];
      t.across[std::size_t(k)] = n < 0 ? -1 : where[std::size_t(n)];
    }
  meshes.resize(mesh_ends.size());
  for (const Tri& t : tris) {
    MeshInfo& m = meshes[std::size_t(t.mesh)];
    for (const Vec3& v : t.v) m.bounds.extend(v);
    ++m.count;
  }
}

// Builds the subtree over tris[first, first + count): split where the surface area heuristic
// says (binned, Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies", 2007):
// a shaft visits a node in proportion to its area, and a level's long floors and walls make a
// median split's boxes overlap everywhere. Past kMaxDepth, or where no bin separates the
// centroids, the median along the widest axis (a balanced tree within the traversal's stack).
int BlockerHierarchy::build(int first, int count, int depth) {
  Node node;
  Box centroids;
  for (int i = first; i < first + count; ++i) {
    node.box.extend(Box{tris[std::size_t(i)].lo, tris[std::size_t(i)].hi});
    centroids.extend(centroid(tris[std::size_t(i)]));
  }
  node.first = first;
  node.count = count;
  node.size = count;
  const int index = int(nodes.size());
  nodes.push_back(node);
  if (count <= kLeafSize) return index;
  const Vec3 extent = centroids.hi - centroids.lo;
  int axis = 0;
  if (extent.y() > extent[axis]) axis = 1;
  if (extent.z() > extent[axis]) axis = 2;
  int half = -1;
  if (depth < kMaxDepth) {
    double best = std::numeric_limits<double>::infinity();
    int best_axis = -1, best_split = 0;
    for (int a = 0; a < 3; ++a) {
      if (!(extent[a] > 0)) continue;
      std::array<Box, kBins> boxes;
      std::array<int, kBins> counts{};
      for (int i = first; i < first + count; ++i) {
        const int b = bin_of(centroid(tris[std::size_t(i)])[a], centroids.lo[a], extent[a]);
        boxes[std::size_t(b)].extend(Box{tris[std::size_t(i)].lo, tris[std::size_t(i)].hi});
        ++counts[std::size_t(b)];
      }
      // Areas and counts left of each split, then right of it, summed up.
      std::array<double, kBins> left_cost{};
      Box grown;
      int n = 0;
      for (int b = 0; b < kBins - 1; ++b) {
        grown.extend(boxes[std::size_t(b)]);
        n += counts[std::size_t(b)];
        left_cost[std::size_t(b)] = n > 0 ? area(grown) * n : 0;
      }
      grown = Box();
      n = 0;
      for (int b = kBins - 1; b > 0; --b) {
        grown.extend(boxes[std::size_t(b)]);
        n += counts[std::size_t(b)];
        const double cost = left_cost[std::size_t(b - 1)] + (n > 0 ? area(grown) * n : 0);
        if (n > 0 && n < count && cost < best) best = cost, best_axis = a, best_split = b;
      }
    }
    if (best_axis >= 0) {
      const double lo = centroids.lo[best_axis], ext = extent[best_axis];
      const auto middle = std::partition(
          tris.begin() + first, tris.begin() + first + count,
          [&](const Tri& t) { return bin_of(centroid(t)[best_axis], lo, ext) < best_split; });
      half = int(middle - (tris.begin() + first));
    }
  }
  if (half <= 0 || half >= count) {
    half = count / 2;
    std::nth_element(
        tris.begin() + first, tris.begin() + first + half, tris.begin() + first + count,
        [axis](const Tri& a, const Tri& b) { return centroid(a)[axis] < centroid(b)[axis]; });
  }
  const int left = build(first, half, depth + 1);
  const int right = build(first + half, count - half, depth + 1);
  nodes[std::size_t(index)].left = left;
  nodes[std::size_t(index)].right = right;
  nodes[std::size_t(index)].count = 0;
  return index;
}

void BlockerHierarchy::triangles_in_box(const Bounds3& box, std::vector<std::uint32_t>& out) const {
  out.clear();
  if (nodes.empty() || box.empty()) return;
  const auto meets = [&](const Vec3& lo, const Vec3& hi) {
    return (lo.array() <= box.hi.array()).all() && (box.lo.array() <= hi.array()).all();
  };
  thread_local std::vector<int> stack;
  stack.assign(1, 0);
  while (!stack.empty()) {
    const Node& node = nodes[std::size_t(stack.back())];
    stack.pop_back();
    if (!meets(node.box.lo, node.box.hi)) continue;
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i)
        if (meets(tris[std::size_t(i)].lo, tris[std::size_t(i)].hi))
          out.push_back(std::uint32_t(i));
      continue;
    }
    stack.push_back(node.left);
    stack.push_back(node.right);
  }
  std::sort(out.begin(), out.end());
}

std::vector<std::uint32_t> BlockerHierarchy::triangles_within(const Vec3& centre,
                                                              double radius) const {
  std::vector<std::uint32_t> found;
  if (nodes.empty()) return found;
  const auto near = [&](const Vec3& lo, const Vec3& hi) {
    return (centre.cwiseMax(lo).cwiseMin(hi) - centre).norm() < radius;
  };
  std::vector<int> stack = {0};
  while (!stack.empty()) {
    const Node& node = nodes[std::size_t(stack.back())];
    stack.pop_back();
    if (!near(node.box.lo, node.box.hi)) continue;
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const Tri& t = tris[std::size_t(i)];
        double bary[3];
        if (near(t.lo, t.hi) &&
            nearest_point(t.v[0], t.v[1], t.v[2], centre, bary) < radius * radius)
          found.push_back(std::uint32_t(i));
      }
      continue;
    }
    stack.push_back(node.left);
    stack.push_back(node.right);
  }
  std::sort(found.begin(), found.end());
  return found;
}

}  // namespace sb
