// Many triangles at once, through the outline of their union (light_rows.h): what a dense,
// non-convex mesh (a sculpted head, a displaced rock, a knot of tubes) costs a texel whose
// shaft holds hundreds or thousands of its triangles.
//
// Projected from the texel's ray origin, a triangle that faces it turns one way in the light's
// plane and one that faces away the other, so that counting +1 inside each projected triangle
// whatever its turn is a sum, along a row, of ±1 at every crossing of a triangle's edge: the
// sign says whether the row enters or leaves that triangle. The union is where the count is
// above 0. Two triangles that share an edge (ShaftCuller::neighbour) and face the same way give
// that edge opposite crossings, which cancel: only the outline of each same-facing patch is
// crossed at all, its silhouettes and borders, a few hundred edges where the triangles number
// thousands (Laine et al., "Soft Shadow Volumes for Ray Tracing", SIGGRAPH 2005, count depth
// complexity across silhouette edges the same way). Each row adds its crossings' signs at the
// first cell centre past them and sums along the row: the cells whose centres are covered.
//
// A triangle reaching behind the origin or onto the light's plane, or passing within the rays'
// surface offset of the origin, is cut, and taken one by one (blocker_rasteriser.cpp) instead;
// its neighbours then keep the edge they share with it.
//
// What can be decided for a whole tile of texels is decided once (prepare_outline): which way
// each triangle faces from every ray origin of the tile (its plane has the tile's box on one
// side), and so which edges cancel for all of them and which bound the union for all of them;
// a texel then projects the edges that bound it and decides only those between triangles whose
// planes pass through the tile. For a sphere light, whose plane moves with the texel, every
// triangle is decided per texel.
#include <algorithm>
#include <cmath>

#include "methods/backprojection/light_rows.h"
#include "occluders/shaft_culling.h"

namespace sb {

namespace {

// Which way a triangle faces a point: 1 towards it, 0 away.
std::int8_t faces(const ShaftCuller& culler, std::uint32_t t, const Vec3& p) {
  return culler.triangle_normal(t).dot(p - culler.triangle_corners(t)[0]) > 0;
}

// Per-texel memo of the facing of triangles, by stamps (reset when the stamp wraps).
struct FacingMemo {
  std::vector<std::uint32_t> stamp;
  std::vector<std::int8_t> facing;
  std::uint32_t generation = 0;
  void begin(std::size_t triangles) {
    if (stamp.size() < triangles) {
      stamp.assign(triangles, 0);
      facing.assign(triangles, 0);
      generation = 0;
    }
    if (++generation == 0) {
      std::fill(stamp.begin(), stamp.end(), 0);
      generation = 1;
    }
  }
};

// The union's crossings of each row, as +1 or -1 at the first cell centre past them.
struct Crossings {
  std::array<std::array<std::int32_t, kCells + 1>, LightRows::kMaxRows> steps;
  std::uint64_t touched = 0;
  // Per row, cells per unit of s (0 for a row of no width); and the rows' extent in s: an edge
  // wholly past it crosses no row before a cell centre, one wholly before it crosses each row
  // before the first.
  std::array<double, LightRows::kMaxRows> cells_per_s{};
  double s_lo = 0, s_hi = 0;

  void begin(const LightRows& rows) {
    touched = 0;
    s_lo = kInfinity, s_hi = -kInfinity;
    for (int r = 0; r < rows.count; ++r) {
      const double enter = rows.enter[std::size_t(r)];
      const double width = rows.leave[std::size_t(r)] - enter;
      cells_per_s[std::size_t(r)] = width > 0 ? kCells / width : 0.0;
      if (!(width > 0)) continue;
      s_lo = std::min(s_lo, enter);
      s_hi = std::max(s_hi, rows.leave[std::size_t(r)]);
    }
  }

  void step(int r, int cell, int sign) {
    if (!(touched >> r & 1)) {
      steps[std::size_t(r)].fill(0);
      touched |= std::uint64_t(1) << r;
    }
    steps[std::size_t(r)][std::size_t(cell)] += sign;
  }

  // An edge p → q of a triangle turned `orient` (+1 counter-clockwise in (s, t)).
  void add(const LightRows& rows, Vec2 p, Vec2 q, int orient) {
    if (p.y() == q.y()) return;
    if (p.x() >= s_hi && q.x() >= s_hi) return;  // past every centre of every row
    const bool up = q.y() > p.y();
    if (!up) std::swap(p, q);
    const int sign = up ? -orient : orient;
    // Rows whose centre line lies in [p.t, q.t): each crossing counted once at a shared end.
    const int n = rows.count;
    const int a = int(std::clamp(std::ceil((p.y() - rows.first) / rows.pitch), 0.0, double(n)));
    const int b =
        int(std::clamp(std::ceil((q.y() - rows.first) / rows.pitch) - 1, -1.0, double(n - 1)));
    if (p.x() <= s_lo && q.x() <= s_lo) {  // before every row: at its first cell
      for (int r = a; r <= b; ++r)
        if (cells_per_s[std::size_t(r)] > 0) step(r, 0, sign);
      return;
    }
    const double slope = (q.x() - p.x()) / (q.y() - p.y());
    for (int r = a; r <= b; ++r) {
      const double per_s = cells_per_s[std::size_t(r)];
      if (!(per_s > 0)) continue;
      const double s = p.x() + (rows.first + r * rows.pitch - p.y()) * slope;
      const double cell = std::ceil((s - rows.enter[std::size_t(r)]) * per_s - 0.5);
      if (cell > kCells - 1) continue;  // past every centre of the row
      step(r, int(std::max(0.0, cell)), sign);
    }
  }

  // The covered cells of each row into `blocked`; whether any is.
  bool commit(const LightRows& rows, BlockedRows& blocked) const {
    bool any = false;
    for (int r = 0; r < rows.count; ++r) {
      if (!(touched >> r & 1)) continue;
      std::uint64_t covered = 0;
      std::int32_t count = 0;
      for (int k = 0; k < kCells; ++k) {
        count += steps[std::size_t(r)][std::size_t(k)];
        if (count > 0) covered |= std::uint64_t(1) << k;
      }
      if (covered == 0) continue;
      blocked.add_cells(rows, r, covered);
      any = true;
    }
    return any;
  }
};

}  // namespace

BlockerOutline prepare_outline(const ShaftCuller& culler, const Light& light,
                               const std::vector<std::uint32_t>& triangles, std::uint32_t key,
                               const Bounds3& origins, double offset) {
  BlockerOutline out;
  out.culler = &culler;
  out.key = key;
  out.distance = kInfinity;
  for (std::uint32_t t : triangles) {
    const Bounds3 b = culler.triangle_bounds(t);
    out.distance =
        std::min(out.distance,
                 (b.lo - origins.hi).cwiseMax(origins.lo - b.hi).cwiseMax(Vec3::Zero()).norm());
  }
  if (light.shape() == LightShape::sphere) {
    out.triangles = triangles;
    return out;
  }
  // Within the slab for every texel of the tile: above the light's plane by the offset, below the
  // lowest of the tile's origins, and not within the offset of any of them.
  const Vec3& n = light.normal();
  double h_top = kInfinity;
  for (int k = 0; k < 8; ++k) {
    const Vec3 c = origins.corner(k);
    h_top = std::min(h_top, n.dot(c - light.centre()) * (1 - 1e-9));
  }
  const Vec3 centre = origins.centre(), half = 0.5 * (origins.hi - origins.lo);
  // The triangles of the union and how each faces the tile (1, 0, -1 mixed), marked in a memo
  // by triangle index.
  thread_local FacingMemo memo;
  memo.begin(culler.triangle_count());
  thread_local std::vector<std::uint32_t> set;
  set.clear();
  for (std::uint32_t t : triangles) {
    const Vec3* c = culler.triangle_corners(t);
    bool within = true;
    for (int k = 0; k < 3; ++k) {
      const double height = n.dot(c[k] - light.centre());
      within = within && height >= offset && height <= h_top;
    }
    const Bounds3 b = culler.triangle_bounds(t);
    if (!within ||
        (b.lo - origins.hi).cwiseMax(origins.lo - b.hi).cwiseMax(Vec3::Zero()).norm() < offset) {
      out.apart.push_back({c, 3, culler.triangle_normal(t), key, t});
      continue;
    }
    const Vec3& normal = culler.triangle_normal(t);
    const double mid = normal.dot(centre - c[0]), spread = half.dot(normal.cwiseAbs());
    memo.stamp[t] = memo.generation;
    memo.facing[t] = std::int8_t(mid - spread > 0 ? 1 : mid + spread < 0 ? 0 : -1);
    set.push_back(t);
  }
  std::sort(set.begin(), set.end());  // edges in a fixed order, whatever the candidates' order
  for (const std::uint32_t t : set) {
    const std::int8_t facing = memo.facing[t];
    for (int k = 0; k < 3; ++k) {
      OutlineEdge e;
      e.triangle = t;
      e.facing = facing;
      const int across = culler.neighbour(t, k);
      if (across >= 0 && memo.stamp[std::size_t(across)] == memo.generation) {
        const std::int8_t other = memo.facing[std::size_t(across)];
        if (facing >= 0 && other >= 0) {
          if (facing == other) continue;  // cancelled for every texel of the tile
        } else {
          e.across = std::int32_t(across);
          e.across_facing = other;
        }
      }
      const Vec3* c = culler.triangle_corners(t);
      e.a = c[k];
      e.b = c[(k + 1) % 3];
      out.edges.push_back(e);
    }
  }
  return out;
}

void rasterise_outline(const RasterTarget& target, const BlockerOutline& outline) {
  const LightFrame& f = *target.frame;
  const LightRows& rows = *target.rows;
  const Vec3& origin = target.origin;
  const ShaftCuller& culler = *outline.culler;
  const int n = rows.count;
  const double h_origin = f.normal.dot(origin - f.centre);
  if (!(h_origin > f.clip_height) || n == 0) return;
  const double h_top = origin_ceiling(h_origin, target.light_offset);
  const double s_origin = f.s_axis.dot(origin - f.centre);
  const double t_origin = f.t_axis.dot(origin - f.centre);
  // Facing the origin turns counter-clockwise in (s, t) when the frame's axes do, seen from it.
  const int turn = f.s_axis.cross(f.t_axis).dot(f.normal) > 0 ? 1 : -1;
  const auto project = [&](const Vec3& point) {
    const Vec3 d = point - origin;
    const double scale = h_origin / std::max(-f.normal.dot(d), 1e-12 * h_origin);
    return Vec2(s_origin + scale * f.s_axis.dot(d), t_origin + scale * f.t_axis.dot(d));
  };
  thread_local FacingMemo memo;
  thread_local Crossings crossings;
  thread_local std::vector<BlockerPolygon> apart;
  memo.begin(culler.triangle_count());
  crossings.begin(rows);
  apart.assign(outline.apart.begin(), outline.apart.end());
  const auto facing_of = [&](std::uint32_t t) {
    if (memo.stamp[t] != memo.generation) {
      memo.stamp[t] = memo.generation;
      memo.facing[t] = faces(culler, t, origin);
    }
    return memo.facing[t];
  };

  if (!outline.triangles.empty()) {
    // Per texel: which triangles are within the slab (marked), and which way each faces.
    thread_local std::vector<std::uint32_t> in_set;
    in_set.clear();
    for (std::uint32_t t : outline.triangles) {
      const Vec3* c = culler.triangle_corners(t);
      bool within = true;
      Vec3 lo = c[0], hi = c[0];
      for (int k = 0; k < 3; ++k) {
        const double height = f.normal.dot(c[k] - f.centre);
        within = within && height >= f.clip_height && height <= h_top;
        lo = lo.cwiseMin(c[k]);
        hi = hi.cwiseMax(c[k]);
      }
      const double gap = (lo - origin).cwiseMax(origin - hi).cwiseMax(Vec3::Zero()).norm();
      if (!within || gap < target.light_offset) {
        apart.push_back({c, 3, culler.triangle_normal(t), outline.key, t});
        continue;
      }
      facing_of(t);  // marks it as one of the union's
      in_set.push_back(t);
    }
    for (std::uint32_t t : in_set) {
      const Vec3* c = culler.triangle_corners(t);
      const std::int8_t facing = memo.facing[t];
      for (int k = 0; k < 3; ++k) {
        const int across = culler.neighbour(t, k);
        if (across >= 0 && memo.stamp[std::size_t(across)] == memo.generation &&
            memo.facing[std::size_t(across)] == facing)
          continue;  // inside a same-facing patch: cancelled by its neighbour
        crossings.add(rows, project(c[k]), project(c[(k + 1) % 3]), facing ? turn : -turn);
      }
    }
  } else {
    for (const OutlineEdge& e : outline.edges) {
      const std::int8_t facing = e.facing >= 0 ? e.facing : facing_of(e.triangle);
      if (e.across >= 0) {
        const std::int8_t other =
            e.across_facing >= 0 ? e.across_facing : facing_of(std::uint32_t(e.across));
        if (other == facing) continue;
      }
      crossings.add(rows, project(e.a), project(e.b), facing ? turn : -turn);
    }
  }
  if (crossings.commit(rows, *target.blocked)) {
    target.out->nearest_blocker =
        std::min(target.out->nearest_blocker, std::max(outline.distance, target.light_offset));
    if (target.blocking) target.blocking->push_back(outline.key);
  }
  if (!apart.empty()) rasterise_polygons_and_solids(target, apart, {});
}

}  // namespace sb
