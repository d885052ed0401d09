// Stage 2's preparation of a listed tile (tile_blockers.h): its candidates sorted into
// triangles, whole convex solids and dense meshes' outlines, in steps.
#include "methods/backprojection/tile_blockers.h"

#include <algorithm>
#include <array>
#include <limits>

#include "occluders/blocker_solids.h"

namespace sb {

namespace {

// The solid's edges that may lie on its silhouette from some point of the box `origins`: those
// between faces that do not face the same way from all of it.
std::vector<int> edges_on_some_silhouette(const BlockerSolid& solid, const Bounds3& origins) {
  const Vec3 centre = origins.centre(), half = 0.5 * (origins.hi - origins.lo);
  // Each face's side of the whole box: 1 facing it from all of it, -1 from none, 0 mixed.
  std::vector<std::int8_t> side(solid.faces.size());
  for (std::size_t f = 0; f < solid.faces.size(); ++f) {
    const Vec3& n = solid.normals[f];
    const double mid = n.dot(centre - solid.corners[std::size_t(solid.faces[f][0])]);
    const double spread = half.dot(n.cwiseAbs());
    side[f] = mid - spread > 0 ? 1 : mid + spread < 0 ? -1 : 0;
  }
  std::vector<int> edges;
  for (std::size_t e = 0; e < solid.edges.size(); ++e) {
    const std::int8_t a = side[std::size_t(solid.edges[e][2])];
    const std::int8_t b = side[std::size_t(solid.edges[e][3])];
    if (a == 0 || b == 0 || a != b) edges.push_back(int(e));
  }
  return edges;
}

// The solid's faces that may cross the light's plane (at the rays' offset) or the height of some
// origin of the box `origins`: those that cut the outline of the solid's part in a texel's slab.
std::vector<int> faces_across_slab(const Light& light, const BlockerSolid& solid,
                                   const Bounds3& origins, double offset) {
  std::vector<int> cuts;
  double h_lo = std::numeric_limits<double>::infinity(), h_hi = -h_lo;
  for (int c = 0; c < 8; ++c) {
    const Vec3 p = origins.corner(c);
    const double h = light.normal().dot(p - light.centre());
    h_lo = std::min(h_lo, h * (1 - 1e-9)), h_hi = std::max(h_hi, h);
  }
  for (std::size_t f = 0; f < solid.faces.size(); ++f) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int j = 0; j < 3; ++j) {
      const double h = light.normal().dot(
          solid.corners[std::size_t(solid.faces[f][std::size_t(j)])] - light.centre());
      lo = std::min(lo, h), hi = std::max(hi, h);
    }
    if ((lo < offset && hi > offset) || (lo < h_hi && hi > h_lo)) cuts.push_back(int(f));
  }
  return cuts;
}

// Each convex solid among the candidates once (`keys`), with how far the whole tile lies in
// front of its farthest face plane (`distances`): a lower bound on its distance to the solid,
// positive where every texel lies outside it.
void solids_and_distances(const ShaftCuller& culler, const std::vector<std::uint32_t>& candidates,
                          const Bounds3& origins, std::vector<std::uint32_t>& keys,
                          std::vector<double>& distances) {
  const Vec3 centre = origins.centre(), half = 0.5 * (origins.hi - origins.lo);
  for (std::uint32_t i : candidates) {
    const std::uint32_t key = culler.blocker_key(i);
    if (!(key & ShaftCuller::kSolidKey) || std::find(keys.begin(), keys.end(), key) != keys.end())
      continue;
    const BlockerSolid& solid = culler.solid_of_key(key);
    double distance = -std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < solid.faces.size(); ++k) {
      const Vec3& n = solid.normals[k];
      distance = std::max(distance, n.dot(centre - solid.corners[std::size_t(solid.faces[k][0])]) -
                                        half.dot(n.cwiseAbs()));
    }
    keys.push_back(key);
    distances.push_back(distance);
  }
}

// Which of the solids `keys` are taken whole. A solid the tile's texels lie outside of (by more
// than the rays' offset) is taken whole; the texels on or in one (its own surface, a floor under
// a box) take its triangles one by one. So do a dense mesh's triangles, but through the outline
// of their union where the tile holds enough of them for that to pay. A triangle through the
// light's ball goes as its parts outside it, and its solid, if any, as triangles.
std::vector<std::uint8_t> whole_solids(const ShaftCuller& culler,
                                       const std::vector<std::uint32_t>& candidates,
                                       const std::vector<std::uint32_t>& keys,
                                       const std::vector<double>& distances, double offset,
                                       const PiercingBlockers& piercing) {
  std::vector<std::uint8_t> whole(keys.size());
  for (std::size_t k = 0; k < keys.size(); ++k) whole[k] = distances[k] > offset;
  for (std::uint32_t i : candidates) {
    if (!piercing.pierces(i)) continue;
    const auto at = std::find(keys.begin(), keys.end(), culler.blocker_key(i));
    if (at != keys.end()) whole[std::size_t(at - keys.begin())] = 0;
  }
  return whole;
}

// Dense meshes' triangles among the candidates, by mesh in order of first candidate.
struct DenseMeshes {
  std::vector<std::uint32_t> keys;
  std::vector<std::vector<std::uint32_t>> triangles;
};

// Each candidate to where it goes: a piercing triangle's parts and the triangles of solids not
// taken whole to `out.polygons`, dense meshes' triangles to the list returned.
DenseMeshes sort_candidates(const ShaftCuller& culler, const std::vector<std::uint32_t>& candidates,
                            const std::vector<std::uint32_t>& keys,
                            const std::vector<std::uint8_t>& whole,
                            const PiercingBlockers& piercing, TileBlockers& out) {
  DenseMeshes dense;
  for (std::uint32_t i : candidates) {
    const std::uint32_t key = culler.blocker_key(i);
    if (piercing.pierces(i)) {
      add_parts(piercing, i, key, culler.triangle_normal(i), out.polygons);
      continue;
    }
    if (key & ShaftCuller::kMeshKey) {
      auto at = std::find(dense.keys.begin(), dense.keys.end(), key);
      if (at == dense.keys.end()) {
        dense.keys.push_back(key);
        dense.triangles.emplace_back();
        at = dense.keys.end() - 1;
      }
      dense.triangles[std::size_t(at - dense.keys.begin())].push_back(i);
      continue;
    }
    const auto at = std::find(keys.begin(), keys.end(), key);
    if (at == keys.end() || !whole[std::size_t(at - keys.begin())])
      out.polygons.push_back({culler.triangle_corners(i), 3, culler.triangle_normal(i), key});
  }
  return dense;
}

// Each dense mesh's triangles through their outline, or one by one where they are few or large.
void add_dense_meshes(const ShaftCuller& culler, const Light& light, const DenseMeshes& dense,
                      const Bounds3& origins, double offset, TileBlockers& out) {
  for (std::size_t k = 0; k < dense.keys.size(); ++k) {
    const std::vector<std::uint32_t>& list = dense.triangles[k];
    // A sphere light's outline is made anew per texel (penumbra_estimator.h): it pays where the
    // mesh's triangles are small beside the tile (a knot's), not where they are as large as a
    // level's walls and floors (OpenArena's oacmpctf3: the evaluations took 11 % longer so).
    double sizes = 0;
    if (light.shape() == LightShape::sphere)
      for (std::uint32_t i : list) sizes += culler.triangle_bounds(i).diagonal();
    const bool large = sizes > double(list.size()) * origins.diagonal();
    if (list.size() < kOutlineTriangles || large) {
      for (std::uint32_t i : list)
        out.polygons.push_back(
            {culler.triangle_corners(i), 3, culler.triangle_normal(i), dense.keys[k], i});
      continue;
    }
    out.outlines.push_back(prepare_outline(culler, light, list, dense.keys[k], origins, offset));
  }
}

// The solids taken whole, each with its silhouette's edges, the faces across the slab and its
// candidate triangles. A whole solid that reaches past the light's plane or below the tile's
// origins (a wall up to the ceiling a panel hangs from, a ball resting on the floor) has no
// silhouette every texel can take: with many faces in the tile, they go through the outline of
// their union instead.
void add_whole_solids(const ShaftCuller& culler, const Light& light,
                      const std::vector<std::uint32_t>& candidates,
                      const std::vector<std::uint32_t>& keys, const std::vector<double>& distances,
                      const std::vector<std::uint8_t>& whole, const Bounds3& origins, double offset,
                      TileBlockers& out) {
  double h_top = std::numeric_limits<double>::infinity();
  for (int c = 0; c < 8; ++c) {
    const Vec3 p = origins.corner(c);
    h_top = std::min(h_top, light.normal().dot(p - light.centre()) * (1 - 1e-9));
  }
  const auto within_slab = [&](const Bounds3& b) {
    if (light.shape() == LightShape::sphere) return true;  // decided per texel
    for (int c = 0; c < 8; ++c) {
      const Vec3 p = b.corner(c);
      const double height = light.normal().dot(p - light.centre());
      if (height < offset || height > h_top) return false;
    }
    return true;
  };
  for (std::size_t k = 0; k < keys.size(); ++k) {
    if (!whole[k]) continue;
    const BlockerSolid& solid = culler.solid_of_key(keys[k]);
    if (!within_slab(solid.bounds)) {
      std::vector<std::uint32_t> faces;
      for (std::uint32_t i : candidates)
        if (culler.blocker_key(i) == keys[k]) faces.push_back(i);
      if (faces.size() >= kOutlineTriangles) {
        out.outlines.push_back(prepare_outline(culler, light, faces, keys[k], origins, offset));
        continue;
      }
    }
    out.edges.push_back(edges_on_some_silhouette(solid, origins));
    out.cut_faces.push_back(light.shape() != LightShape::sphere
                                ? faces_across_slab(light, solid, origins, offset)
                                : std::vector<int>());
    std::vector<BlockerPolygon> faces;
    for (std::uint32_t i : candidates)
      if (culler.blocker_key(i) == keys[k])
        faces.push_back({culler.triangle_corners(i), 3, culler.triangle_normal(i), i});
    // (A whole solid has no triangle through the ball: see whole_solids.)
    out.faces.push_back(std::move(faces));
    out.solids.push_back({&solid, keys[k], nullptr, 0, distances[k]});
  }
}

// Each solid's references to its edges and faces, once their lists no longer move.
void link_solids(const Light& light, TileBlockers& out) {
  for (std::size_t k = 0; k < out.solids.size(); ++k) {
    out.solids[k].edges = out.edges[k].data();
    out.solids[k].edge_count = int(out.edges[k].size());
    out.solids[k].faces = out.faces[k].data();
    out.solids[k].face_count = int(out.faces[k].size());
    if (light.shape() != LightShape::sphere) {
      out.solids[k].cut_faces = out.cut_faces[k].data();
      out.solids[k].cut_count = int(out.cut_faces[k].size());
    }
  }
}

}  // namespace

void add_parts(const PiercingBlockers& piercing, std::uint32_t triangle, std::uint32_t key,
               const Vec3& normal, std::vector<BlockerPolygon>& out) {
  const auto parts = piercing.parts_of(triangle);
  for (const std::array<Vec3, 3>& part : parts)
    out.push_back({part.data(), 3, normal, key,
                   PiercingBlockers::kPartUmbra | std::uint32_t(&part - piercing.parts.data())});
}

TileBlockers tile_blockers(const ShaftCuller& culler, const Light& light,
                           const std::vector<std::uint32_t>& candidates, const Bounds3& origins,
                           double offset, const PiercingBlockers& piercing) {
  TileBlockers out;
  std::vector<std::uint32_t> keys;
  std::vector<double> distances;
  solids_and_distances(culler, candidates, origins, keys, distances);
  const std::vector<std::uint8_t> whole =
      whole_solids(culler, candidates, keys, distances, offset, piercing);
  const DenseMeshes dense = sort_candidates(culler, candidates, keys, whole, piercing, out);
  add_dense_meshes(culler, light, dense, origins, offset, out);
  add_whole_solids(culler, light, candidates, keys, distances, whole, origins, offset, out);
  link_solids(light, out);
  return out;
}

}  // namespace sb
