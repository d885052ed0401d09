// Closed and convex solids among the blocker triangles (blocker_solids.h).
//
// A component is closed when every directed edge (by welded corners) occurs exactly once and its
// reverse occurs too: a two-manifold surface, consistently oriented, with no border. Its
// normals point out when the volume it encloses (the divergence theorem: Σ v0·(v1 × v2) / 6) is
// positive. It is convex when, besides, every edge is convex: the far corner of the face across
// each edge lies on or behind the plane of the face on this side. A closed, connected surface
// that is convex at every edge bounds a convex body (a locally convex compact surface is
// globally convex), so the test is linear in the edges rather than quadratic in faces and
// corners. Written by hand: CGAL's clusters (clusters.cpp) serve the convolution's planner and
// come with its compile time; this needs a hash of welded corners and a pass over edges.
#include "occluders/blocker_solids.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <unordered_map>

#include "core/nearest_point.h"

namespace sb {

namespace {

struct Key {
  std::int64_t x, y, z;
  bool operator==(const Key&) const = default;
};
struct KeyHash {
  std::size_t operator()(const Key& k) const {
    std::uint64_t h = std::uint64_t(k.x) * 0x9E3779B97F4A7C15ull;
    h ^= std::uint64_t(k.y) + 0x7F4A7C159E3779B9ull + (h << 6) + (h >> 2);
    h ^= std::uint64_t(k.z) + 0x94D049BB133111EBull + (h << 6) + (h >> 2);
    return std::size_t(h);
  }
};

int find(std::vector<int>& parent, int i) {
  while (parent[std::size_t(i)] != i) {
    parent[std::size_t(i)] = parent[std::size_t(parent[std::size_t(i)])];
    i = parent[std::size_t(i)];
  }
  return i;
}

std::uint64_t edge_key(int a, int b) {
  return (std::uint64_t(std::uint32_t(a)) << 32) | std::uint32_t(b);
}

// The solid angle triangle t subtends at p, signed (positive where p lies behind its normal's
// side, as the centre of a solid whose normals point out does): Van Oosterom and Strackee's
// formula.
double solid_angle(const std::array<Vec3, 3>& t, const Vec3& p) {
  const Vec3 a = t[0] - p, b = t[1] - p, c = t[2] - p;
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  const double numerator = a.dot(b.cross(c));
  const double denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
  return 2 * std::atan2(numerator, denominator);
}

// The ball of a closed solid whose normals point out (BlockerSolid::inner_centre): centred on
// its volume's centroid when that lies inside it, as large as its nearest triangle allows.
void find_inner_ball(const std::vector<std::array<Vec3, 3>>& triangles, std::size_t first,
                     const std::vector<std::size_t>& list, BlockerSolid& solid) {
  const Vec3 origin = solid.bounds.centre();
  double volume = 0;
  Vec3 moment = Vec3::Zero();
  for (std::size_t i : list) {
    const auto& t = triangles[first + i];
    const double v = (t[0] - origin).dot((t[1] - origin).cross(t[2] - origin));
    volume += v;
    moment += v * (t[0] + t[1] + t[2] - 3 * origin) / 4;
  }
  if (!(volume > 0)) return;
  const Vec3 centre = origin + moment / volume;
  double winding = 0, nearest = std::numeric_limits<double>::infinity(), farthest = 0;
  for (std::size_t i : list) {
    const auto& t = triangles[first + i];
    winding += solid_angle(t, centre);
    double bary[3];
    nearest = std::min(nearest, std::sqrt(nearest_point(t[0], t[1], t[2], centre, bary)));
    for (const Vec3& v : t) farthest = std::max(farthest, (v - centre).norm());
  }
  // The winding number is an integer off the surface: 1 inside, 0 outside.
  if (!(std::abs(winding / (4 * std::numbers::pi) - 1) < 0.25) || !(nearest > 0)) return;
  solid.inner_centre = centre;
  // A millionth short of the nearest triangle, against rounding (the corners were welded on a
  // grid of a millionth of the mesh's size).
  solid.inner_radius = nearest - 2e-6 * solid.bounds.diagonal();
  solid.outer_radius = farthest;
  if (!(solid.inner_radius > 0)) solid.inner_radius = 0;
}

// One mesh's part of the search, as steps over what they share: its triangles from `first` on,
// their corners welded on the mesh's grid, each triangle's three, and its directed edges.
struct MeshSolids {
  MeshSolids(const std::vector<std::array<Vec3, 3>>& triangles, std::size_t first,
             std::size_t count, BlockerSolids& out)
      : triangles(triangles), first(first), count(count), out(out), position(count, -1) {}

  const std::vector<std::array<Vec3, 3>>& triangles;
  const std::size_t first, count;
  BlockerSolids& out;
  std::vector<Vec3> corners;
  std::vector<std::array<int, 3>> tri;
  std::vector<std::uint8_t> usable;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> directed;
  std::vector<std::uint8_t> repeated;  // a directed edge held twice: not closed
  std::vector<int> position;           // a triangle's place in its component's list

  // Welds the corners, gives each triangle its three, and marks the triangles with area.
  void weld_corners() {
    const std::size_t end = first + count;
    // Corners welded on the mesh's grid, and each triangle's three.
    Bounds3 box;
    for (std::size_t i = first; i < end; ++i)
      for (const Vec3& v : triangles[i]) box.extend(v);
    const double cell = std::max(box.diagonal(), 1e-300) * 1e-6;
    std::unordered_map<Key, int, KeyHash> index;
    index.reserve(3 * count);
    tri.resize(count);
    usable.assign(count, 1);
    for (std::size_t i = 0; i < count; ++i) {
      for (int k = 0; k < 3; ++k) {
        const Vec3 q = (triangles[first + i][std::size_t(k)] - box.lo) / cell;
        const Key key{std::llround(q.x()), std::llround(q.y()), std::llround(q.z())};
        const auto [it, added] = index.try_emplace(key, int(corners.size()));
        if (added) corners.push_back(triangles[first + i][std::size_t(k)]);
        tri[i][std::size_t(k)] = it->second;
      }
      const auto& t = triangles[first + i];
      usable[i] = tri[i][0] != tri[i][1] && tri[i][1] != tri[i][2] && tri[i][0] != tri[i][2] &&
                  (t[1] - t[0]).cross(t[2] - t[0]).squaredNorm() > 0;
    }
  }

  // Sorts the directed edges, sets each triangle's neighbours across its edges in `out.across`,
  // and marks the triangles that hold a repeated directed edge.
  void link_edges() {
    // Directed edges (a, b) sorted, each with its triangle and side: an edge's neighbour is the
    // one triangle holding it the other way round, where neither direction is repeated.
    directed.resize(3 * count);
    for (std::size_t i = 0; i < count; ++i)
      for (int k = 0; k < 3; ++k)
        directed[3 * i + std::size_t(k)] = {
            edge_key(tri[i][std::size_t(k)], tri[i][std::size_t((k + 1) % 3)]),
            std::uint32_t(3 * i + std::size_t(k))};
    std::sort(directed.begin(), directed.end());
    const auto unique_holder = [&](std::uint64_t key) -> int {
      const auto it = std::lower_bound(directed.begin(), directed.end(),
                                       std::pair<std::uint64_t, std::uint32_t>(key, 0));
      if (it == directed.end() || it->first != key) return -1;
      if (std::next(it) != directed.end() && std::next(it)->first == key) return -2;
      return int(it->second);
    };
    repeated.assign(count, 0);
    for (std::size_t i = 0; i < count; ++i)
      for (int k = 0; k < 3; ++k) {
        const int a = tri[i][std::size_t(k)], b = tri[i][std::size_t((k + 1) % 3)];
        const int own = unique_holder(edge_key(a, b)), other = unique_holder(edge_key(b, a));
        if (own == -2) repeated[i] = 1;
        if (own >= 0 && other >= 0) out.across[first + i][std::size_t(k)] = int(first) + other / 3;
      }
  }

  // Each component's triangles, listed under its root (the component's smallest triangle).
  std::vector<std::vector<std::size_t>> components() const {
    // Components: triangles joined through shared edges (not corners alone: boxes that touch
    // at a corner are two solids, and only a surface joined edge to edge is convex where it is
    // convex at every edge), whichever way the edge runs in each.
    std::vector<int> parent(count);
    std::iota(parent.begin(), parent.end(), 0);
    {
      std::vector<std::pair<std::uint64_t, std::uint32_t>> undirected(directed);
      for (auto& [key, at] : undirected) {
        const int a = int(key >> 32), b = int(key & 0xffffffffu);
        key = edge_key(std::min(a, b), std::max(a, b));
      }
      std::sort(undirected.begin(), undirected.end());
      for (std::size_t j = 1; j < undirected.size(); ++j) {
        if (undirected[j].first != undirected[j - 1].first) continue;
        const int x = find(parent, int(undirected[j].second / 3)),
                  y = find(parent, int(undirected[j - 1].second / 3));
        if (x != y) parent[std::size_t(std::max(x, y))] = std::min(x, y);
      }
    }
    std::vector<std::vector<std::size_t>> members(count);
    for (std::size_t i = 0; i < count; ++i) members[std::size_t(find(parent, int(i)))].push_back(i);
    return members;
  }

  // Whether the component `list` is convex at every edge within `tolerance`; its edges, each
  // once as (a, b, face, face across), in `edges` as far as the test went.
  bool convex_edges(const std::vector<std::size_t>& list, const std::vector<Vec3>& normals,
                    double tolerance, std::vector<std::array<int, 4>>& edges) const {
    bool convex = true;
    for (std::size_t j = 0; j < list.size() && convex; ++j)
      for (int k = 0; k < 3; ++k) {
        const std::size_t i = list[j];
        const int a = tri[i][std::size_t(k)], b = tri[i][std::size_t((k + 1) % 3)];
        if (a > b) continue;  // each undirected edge once, from its (a < b) direction
        const std::size_t across = std::size_t(out.across[first + i][std::size_t(k)]) - first;
        const int other = position[across];
        const auto& far = tri[across];
        const int c = far[0] != a && far[0] != b   ? far[0]
                      : far[1] != a && far[1] != b ? far[1]
                                                   : far[2];
        if (normals[j].dot(corners[std::size_t(c)] - corners[std::size_t(a)]) > tolerance) {
          convex = false;
          break;
        }
        edges.push_back({a, b, int(j), other});
      }
    return convex;
  }

  // Gives a convex solid its own corners, renumbered from 0, with its faces, normals and edges.
  void describe_convex(const std::vector<std::size_t>& list, const std::vector<Vec3>& normals,
                       std::vector<std::array<int, 4>>& edges, BlockerSolid& solid) const {
    solid.convex = true;
    // The solid's own corners, renumbered from 0, with its faces and edges.
    std::unordered_map<int, int> local;
    const auto corner = [&](int c) {
      const auto [it, added] = local.try_emplace(c, int(solid.corners.size()));
      if (added) solid.corners.push_back(corners[std::size_t(c)]);
      return it->second;
    };
    for (std::size_t j = 0; j < list.size(); ++j) {
      const auto& t = tri[list[j]];
      solid.faces.push_back({corner(t[0]), corner(t[1]), corner(t[2])});
      solid.normals.push_back(normals[j]);
    }
    std::sort(edges.begin(), edges.end());
    for (const auto& e : edges) solid.edges.push_back({corner(e[0]), corner(e[1]), e[2], e[3]});
  }

  // Adds the component `list` to `out.solids` when it is a closed solid whose normals point out.
  void add_solid(const std::vector<std::size_t>& list) {
    if (list.size() < 4) return;
    // Closed and consistently oriented: each directed edge once, its reverse present (then
    // in the same component).
    bool closed = true;
    double volume = 0;
    for (std::size_t j = 0; j < list.size() && closed; ++j) {
      const std::size_t i = list[j];
      closed = usable[i] && !repeated[i];
      for (int k = 0; k < 3 && closed; ++k) closed = out.across[first + i][std::size_t(k)] >= 0;
      const auto& t = triangles[first + i];
      volume += t[0].dot(t[1].cross(t[2]));
      position[i] = int(j);
    }
    if (!closed || !(volume > 0)) return;
    BlockerSolid solid;
    for (std::size_t i : list)
      for (const Vec3& v : triangles[first + i]) solid.bounds.extend(v);
    // Convex: the far corner across each edge on or behind this side's plane, within 0.1 % of
    // the solid's size (bevelled boxes as Blender exports them dent by about 0.3 mm in 0.4 m:
    // taken whole, such a solid hides what its convex hull does, at most that much more).
    const double tolerance = 1e-3 * std::max(solid.bounds.diagonal(), 1e-300);
    std::vector<Vec3> normals(list.size());
    for (std::size_t j = 0; j < list.size(); ++j) {
      const auto& t = triangles[first + list[j]];
      normals[j] = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
    }
    std::vector<std::array<int, 4>> edges;
    const bool convex = convex_edges(list, normals, tolerance, edges);
    const int id = int(out.solids.size());
    for (std::size_t i : list) out.solid_of[first + i] = id;
    find_inner_ball(triangles, first, list, solid);
    if (convex) describe_convex(list, normals, edges, solid);
    out.solids.push_back(std::move(solid));
  }
};

}  // namespace

BlockerSolids find_solids(const std::vector<std::array<Vec3, 3>>& triangles,
                          const std::vector<std::size_t>& mesh_ends) {
  BlockerSolids out;
  out.solid_of.assign(triangles.size(), -1);
  out.across.assign(triangles.size(), {-1, -1, -1});
  std::size_t first = 0;
  for (const std::size_t end : mesh_ends) {
    const std::size_t count = end - first;
    if (count == 0) continue;
    MeshSolids mesh(triangles, first, count, out);
    mesh.weld_corners();
    mesh.link_edges();
    const std::vector<std::vector<std::size_t>> members = mesh.components();
    for (std::size_t root = 0; root < count; ++root)  // in a fixed order
      mesh.add_solid(members[root]);
    first = end;
  }
  return out;
}

}  // namespace sb
