// Convex solids rasterised for one texel (blocker_rasteriser.h): whole, through their
// silhouette from the texel's ray origin, one convex polygon; or, where the silhouette cannot
// stand for the solid (it reaches past the light's plane or behind the origin, or the origin lies
// on it), face by face or cut to the slab between the light and the origin.
#include <algorithm>
#include <cmath>
#include <limits>

#include "methods/backprojection/blocker_rasteriser.h"
#include "occluders/blocker_solids.h"

namespace sb {

// A convex solid by its silhouette: seen from the origin, the edges between a face that faces
// it and one that does not outline the solid's projection, one convex polygon, whose chord in a
// row runs between the outline's leftmost and rightmost crossings of it.
void Rasteriser::add_solid(const BlockerSolidRef& ref) {
  thread_local std::vector<std::int8_t> front;  // per face: -1 not yet known, else 0 or 1
  thread_local std::vector<Vec2> at;
  thread_local std::vector<std::uint8_t> known;
  const BlockerSolid& solid = *ref.solid;
  const double gap = std::max(gap_to(solid.bounds.lo, solid.bounds.hi), ref.distance);
  if (gap < light_offset) return solid_by_faces(ref, gap);
  // Its box between the light's plane and the origin's height: every corner is, else each
  // silhouette corner must be (a ball resting on the floor reaches below a floor texel's
  // origin, but from most of the floor not on its silhouette: a ray from the origin inside the
  // tangent cone meets the ball at once, however low the ball's bottom).
  bool box_within = true;
  for (int k = 0; k < 8 && box_within; ++k) {
    const Vec3 c = solid.bounds.corner(k);
    const double height = f.normal.dot(c - f.centre);
    box_within = height >= f.clip_height && height <= h_top;
  }
  front.assign(solid.faces.size(), -1);
  known.assign(solid.corners.size(), 0);
  at.resize(solid.corners.size());
  const auto facing = [&](int face) {
    std::int8_t& v = front[std::size_t(face)];
    if (v < 0)
      v = solid.normals[std::size_t(face)].dot(
              origin - solid.corners[std::size_t(solid.faces[std::size_t(face)][0])]) > 0;
    return v;
  };
  double t_lo = kInfinity, t_hi = -kInfinity, s_lo = kInfinity, s_hi = -kInfinity;
  bool corners_within = true;
  const auto corner = [&](int c) -> const Vec2& {
    if (!known[std::size_t(c)]) {
      const Vec3& point = solid.corners[std::size_t(c)];
      if (!box_within) {
        const double height = f.normal.dot(point - f.centre);
        corners_within = corners_within && height >= f.clip_height && height <= h_top;
      }
      at[std::size_t(c)] = project(point);
      known[std::size_t(c)] = 1;
      const Vec2& p = at[std::size_t(c)];
      t_lo = std::min(t_lo, p.y());
      t_hi = std::max(t_hi, p.y());
      s_lo = std::min(s_lo, p.x());
      s_hi = std::max(s_hi, p.x());
    }
    return at[std::size_t(c)];
  };
  const int edge_count = ref.edges ? ref.edge_count : int(solid.edges.size());
  thread_local std::vector<int> silhouette;
  silhouette.clear();
  for (int k = 0; k < edge_count; ++k) {
    const int e = ref.edges ? ref.edges[k] : k;
    const auto& edge_faces = solid.edges[std::size_t(e)];
    if (facing(edge_faces[2]) == facing(edge_faces[3])) continue;
    silhouette.push_back(e);
    corner(edge_faces[0]);
    corner(edge_faces[1]);
  }
  if (!corners_within) return solid_cut_to_slab(ref, gap, silhouette);
  if (silhouette.empty() || t_hi < t_first || t_lo > t_last || s_hi < extent_lo || s_lo > extent_hi)
    return;
  begin(t_lo, t_hi);
  bool corner_in_light = false;
  double edge_distance = kInfinity;  // of the silhouette's edges that cross the light's box
  for (const int e : silhouette) {
    const auto& ends = solid.edges[std::size_t(e)];
    const Vec2& p = at[std::size_t(ends[0])];
    const Vec2& q = at[std::size_t(ends[1])];
    edge(p, q);
    corner_in_light = corner_in_light || in_light(p);
    near_edge(p, q, solid.corners[std::size_t(ends[0])], solid.corners[std::size_t(ends[1])],
              edge_distance);
  }
  settle(ref, commit(nullptr) || corner_in_light, gap, edge_distance);
}

// Face by face (those facing the origin), each cut where it must be: where the silhouette would
// reach past the light's plane or behind the origin, or the origin lies on the solid.
void Rasteriser::solid_by_faces(const BlockerSolidRef& ref, double gap) {
  const BlockerSolid& solid = *ref.solid;
  bool reaches = false;
  if (ref.faces) {
    for (int k = 0; k < ref.face_count; ++k) {
      const BlockerPolygon& face = ref.faces[k];
      if (face.normal.dot(origin - face.v[0]) < 0 && gap > 0) continue;
      reaches = add_blocker(face.v, face.count, face.normal, gap) || reaches;
    }
  } else {
    for (std::size_t k = 0; k < solid.faces.size(); ++k) {
      const Vec3 corners[3] = {solid.corners[std::size_t(solid.faces[k][0])],
                               solid.corners[std::size_t(solid.faces[k][1])],
                               solid.corners[std::size_t(solid.faces[k][2])]};
      if (solid.normals[k].dot(origin - corners[0]) < 0 && gap > 0) continue;
      reaches = add_blocker(corners, 3, solid.normals[k], gap) || reaches;
    }
  }
  found(reaches, gap, ref.key);
}

// A solid reaching past the slab (a crate on the floor a texel is on, a wall up to the ceiling):
// its part within the slab is convex, outlined by its silhouette edges cut to the slab and by
// the cuts of its faces across the slab's planes (those the tile says may cross them, or all): a
// ray inside that outline enters the part.
void Rasteriser::solid_cut_to_slab(const BlockerSolidRef& ref, double gap,
                                   const std::vector<int>& silhouette) {
  const BlockerSolid& solid = *ref.solid;
  thread_local std::vector<std::pair<Vec2, Vec2>> outline;
  outline.clear();
  // How near the outline's segments that cross the light's box lie (as for a silhouette,
  // below): a crate beside a texel on the floor is near, but its outline's edges that hide
  // some of the light may not be.
  double edge_distance = kInfinity;
  const auto add_segment = [&](const Vec3& a, const Vec3& b) {
    const Vec2 p = project(a), q = project(b);
    outline.emplace_back(p, q);
    near_edge(p, q, a, b, edge_distance);
  };
  const auto levels = {f.clip_height, h_top};
  for (const int e : silhouette) {
    Vec3 a = solid.corners[std::size_t(solid.edges[std::size_t(e)][0])];
    Vec3 b = solid.corners[std::size_t(solid.edges[std::size_t(e)][1])];
    double ha = f.normal.dot(a - f.centre), hb = f.normal.dot(b - f.centre);
    if ((ha < f.clip_height && hb < f.clip_height) || (ha > h_top && hb > h_top)) continue;
    for (const double level : levels) {
      if ((ha - level) * (hb - level) >= 0) continue;
      const Vec3 cut = a + (b - a) * ((level - ha) / (hb - ha));
      // Keep the part on the slab's side of this level.
      if ((level == h_top) == (ha > level)) {
        a = cut, ha = level;
      } else {
        b = cut, hb = level;
      }
    }
    add_segment(a, b);
  }
  const int cuts = ref.cut_faces ? ref.cut_count : int(solid.faces.size());
  for (int k = 0; k < cuts; ++k) {
    const auto& face = solid.faces[std::size_t(ref.cut_faces ? ref.cut_faces[k] : k)];
    std::array<double, 3> h;
    for (int j = 0; j < 3; ++j)
      h[std::size_t(j)] = f.normal.dot(solid.corners[std::size_t(face[std::size_t(j)])] - f.centre);
    for (const double level : levels) {
      Vec3 ends[2];
      int found_ends = 0;
      for (int j = 0; j < 3 && found_ends < 2; ++j) {
        const double ha = h[std::size_t(j)], hb = h[std::size_t((j + 1) % 3)];
        if ((ha - level) * (hb - level) >= 0) continue;
        const Vec3& a = solid.corners[std::size_t(face[std::size_t(j)])];
        const Vec3& b = solid.corners[std::size_t(face[std::size_t((j + 1) % 3)])];
        ends[found_ends++] = a + (b - a) * ((level - ha) / (hb - ha));
      }
      if (found_ends == 2) add_segment(ends[0], ends[1]);
    }
  }
  if (outline.empty()) return;
  double lo_t = kInfinity, hi_t = -kInfinity, lo_s = kInfinity, hi_s = -kInfinity;
  bool outline_in_light = false;
  for (const auto& [p, q] : outline)
    for (const Vec2& x : {p, q}) {
      lo_t = std::min(lo_t, x.y()), hi_t = std::max(hi_t, x.y());
      lo_s = std::min(lo_s, x.x()), hi_s = std::max(hi_s, x.x());
      outline_in_light = outline_in_light || in_light(x);
    }
  if (hi_t < t_first || lo_t > t_last || hi_s < extent_lo || lo_s > extent_hi) return;
  begin(lo_t, hi_t);
  for (const auto& [p, q] : outline) edge(p, q);
  const bool reaches = commit(nullptr) || outline_in_light;
  settle(ref, reaches, gap, edge_distance);
}

// An outline edge a → b, projected p → q, that crosses the light's box: how near the origin it
// passes, into `distance` (its nearest, not the solid's: a ball's contact with the floor is not
// where V changes fastest here).
void Rasteriser::near_edge(const Vec2& p, const Vec2& q, const Vec3& a, const Vec3& b,
                           double& distance) const {
  if (std::max(p.y(), q.y()) < t_first || std::min(p.y(), q.y()) > t_last ||
      std::max(p.x(), q.x()) < extent_lo || std::min(p.x(), q.x()) > extent_hi)
    return;
  const Vec3 ab = b - a;
  const double along =
      std::clamp((origin - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
  distance = std::min(distance, (a + along * ab - origin).norm());
}

// The solid rasterised: whether it reaches the light, and its umbra where it covers it.
void Rasteriser::settle(const BlockerSolidRef& ref, bool reaches, double gap,
                        double edge_distance) {
  if (covers) {
    out.umbra = ref.key;
    found(reaches, gap, ref.key);
  } else {
    found(reaches, std::max(gap, std::isfinite(edge_distance) ? edge_distance : gap), ref.key);
  }
}

}  // namespace sb
