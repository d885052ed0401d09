// Exact shaft culling per texel (shaft_culling.h): Haines & Wallace, "Shaft Culling for Efficient
// Ray-Cast Radiosity" (Eurographics Rendering Workshop 1991) bound the volume between a patch and
// a light by planes and test a hierarchy of boxes against them; here the patch is a single point
// (the texel's shadow origin), so the shaft is a pyramid:
//
// - its apex is the origin p; its base is the light's outline: a rectangle's corners, a disk's
//   circumscribed octagon, or for a sphere the octagon circumscribing its silhouette disk as seen
//   from p (every visible point of a sphere lies between p and the silhouette's plane);
// - its planes are the sides through p and each edge of the base, the base's plane (nothing
//   beyond the light blocks it) and the texel's tangent plane (a ray to a point of the light that
//   contributes leaves the surface upwards).
//
// A box of the hierarchy outside one plane holds nothing of the shaft. A triangle whose plane has
// p and the whole light on one side cannot cut a segment between them (this drops the texel's own
// face and, on a convex surface, its neighbours); otherwise it is clipped by the pyramid's planes
// (Sutherland–Hodgman) and lies in the shaft when something remains. Both tests only ever keep
// too much, never too little: a texel called clear has no blocker in any of its rays.
//
// Written by hand: Embree answers rays, not volumes, and a cone or pyramid query is a few planes
// over a small hierarchy.
#include "occluders/shaft_culling.h"

#include "occluders/blocker_hierarchy.h"
#include "occluders/ray_scene.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace sb {

namespace {

using Box = BlockerHierarchy::Box;
using Node = BlockerHierarchy::Node;
using Tri = BlockerHierarchy::Tri;
constexpr int kStack = BlockerHierarchy::kStack;

struct Plane {
  Vec3 n;  // inside: n·x <= d
  double d = 0;
  double eval(const Vec3& x) const { return n.dot(x) - d; }
};

// A shaft's planes: at most 8 sides, the light's plane and the texel's horizon; and the box
// around the apex and the light's base, which holds every segment from the one to the other (a
// box's six compares reject most of a level's nodes before the planes' dot products).
struct Planes {
  std::array<Plane, 12> p;
  int n = 0;
  Vec3 lo, hi;  // the box
  bool misses(const Vec3& box_lo, const Vec3& box_hi) const {
    return (box_hi.array() < lo.array()).any() || (box_lo.array() > hi.array()).any();
  }
  void clear() { n = 0; }
  void push_back(const Plane& plane) { p[std::size_t(n++)] = plane; }
  const Plane* begin() const { return p.data(); }
  const Plane* end() const { return p.data() + n; }
};

// A convex polygon being clipped: a triangle cut by at most 13 planes keeps at most 16 corners.
struct Clip {
  std::array<Vec3, ShaftPolygon::kMaxVertices> v;
  int n = 0;
};

// Points within this distance (metres) of a triangle's plane count as on it.
constexpr double kPlaneTolerance = 1e-9;

// Sutherland–Hodgman: the part of a convex polygon inside one plane.
void clip(Clip& poly, Clip& scratch, const Plane& plane) {
  scratch.n = 0;
  for (int i = 0; i < poly.n; ++i) {
    const Vec3& a = poly.v[std::size_t(i)];
    const Vec3& b = poly.v[std::size_t((i + 1) % poly.n)];
    const double da = plane.eval(a), db = plane.eval(b);
    if (scratch.n + 2 > ShaftPolygon::kMaxVertices) break;  // cannot happen for ≤ 13 planes
    if (da <= 0) scratch.v[std::size_t(scratch.n++)] = a;
    if ((da < 0 && db > 0) || (da > 0 && db < 0))
      scratch.v[std::size_t(scratch.n++)] = a + (b - a) * (da / (da - db));
  }
  std::swap(poly, scratch);
}

}  // namespace

struct ShaftCuller::Impl {
  BlockerHierarchy h;
  // Per blocker mesh: its solids with an inner ball, as keys.
  std::vector<std::vector<std::uint32_t>> balls;
  std::vector<std::uint32_t> ball_key;  // per solid: kSolidKey | it, where it has a ball
  // How much of its start a shadow ray skips (RayScene::surface_offset), metres.
  double skip = 0;

  // The shaft between the apex and the light, as planes; false when the light cannot reach the
  // apex. The apex is a point (one texel's ray origin; with its surface point and normal, whose
  // horizon bounds the shaft too) or a box of several (a tile of texels, no horizon): for a box
  // the planes are those of its centre, each pushed out by the box's reach along its normal,
  // which holds every segment from a point of the box to the light (a point s·q + (1 − s)·b of
  // one, q in the box and b on the light, is at most s times that reach outside the plane).
  static bool shaft(const Box& apex, const Vec3* surface, const Vec3* n, const Light& light,
                    Planes& planes, std::array<Vec3, 8>& base, int& corners) {
    const Vec3 p = 0.5 * (apex.lo + apex.hi);
    const Vec3 half = 0.5 * (apex.hi - apex.lo);
    const bool point = half.isZero();
    const auto reach = [&](const Vec3& normal) { return half.dot(normal.cwiseAbs()); };
    const Vec3 c = light.centre();
    Vec3 e1 = Vec3::Zero(), e2 = Vec3::Zero(), base_normal = Vec3::UnitZ();  // base axes, normal
    Vec3 centre = c;
    double r = 0;
    switch (light.shape()) {
      case LightShape::rectangle:
      case LightShape::polygon: {
        if ((p - c).dot(light.normal()) - reach(light.normal()) <= 0) return false;
        std::array<Vec3, 4> outline;
        corners = light.outline(outline);
        for (int k = 0; k < corners; ++k) base[std::size_t(k)] = outline[std::size_t(k)];
        base_normal = light.normal();
        break;
      }
      case LightShape::mesh:
      case LightShape::sky:
        return false;  // baked as its parts
      case LightShape::disk:
      case LightShape::sphere: {
        if (light.shape() == LightShape::disk) {
          if ((p - c).dot(light.normal()) - reach(light.normal()) <= 0) return false;
          e1 = light.right();
          e2 = light.up();
          base_normal = light.normal();
          r = light.desc().radius;
        } else {
          const Vec3 to = c - p;
          const double dist = to.norm(), R = light.desc().radius;
          if (dist - half.norm() <= R * (1 + 1e-9)) return false;
          const Vec3 axis = to / dist;
          if (point) {
            // The silhouette: a circle of radius R·sqrt(L² − R²)/L at R²/L before the centre.
            centre = c - axis * (R * R / dist);
            r = R * std::sqrt(std::max(0.0, dist * dist - R * R)) / dist;
          } else {
            // From a box no one silhouette holds: the tangent cone from the box's centre,
            // which holds the whole sphere, cut beyond it.
            centre = c + axis * R;
            r = R * (dist + R) / std::sqrt(std::max(1e-300, dist * dist - R * R));
          }
          base_normal = -axis;
          e1 = std::abs(axis.x()) < 0.9 ? axis.cross(Vec3::UnitX()).normalized()
                                        : axis.cross(Vec3::UnitY()).normalized();
          e2 = axis.cross(e1);
        }
        // The octagon circumscribing the circle.
        static const std::array<Vec2, 8> octagon = [] {
          std::array<Vec2, 8> out;
          const double radius_scale = 1.0 / std::cos(std::numbers::pi / 8);
          for (int k = 0; k < 8; ++k) {
            const double a = (k + 0.5) * std::numbers::pi / 4;
            out[std::size_t(k)] = radius_scale * Vec2(std::cos(a), std::sin(a));
          }
          return out;
        }();
        for (int k = 0; k < 8; ++k) {
          const Vec2& o = octagon[std::size_t(k)];
          base[std::size_t(k)] = centre + r * (o.x() * e1 + o.y() * e2);
        }
        corners = 8;
        break;
      }
    }
    if (surface) {
      // The light must rise above the texel's horizon somewhere.
      double highest = -std::numeric_limits<double>::infinity();
      for (int k = 0; k < corners; ++k)
        highest = std::max(highest, n->dot(base[std::size_t(k)] - *surface));
      if (light.shape() == LightShape::sphere)
        highest = std::max(highest, n->dot(c - *surface) + light.desc().radius);
      if (highest <= 0) return false;
    }

    planes.clear();
    planes.lo = apex.lo, planes.hi = apex.hi;
    for (int k = 0; k < corners; ++k) {
      planes.lo = planes.lo.cwiseMin(base[std::size_t(k)]);
      planes.hi = planes.hi.cwiseMax(base[std::size_t(k)]);
    }
    if (light.shape() == LightShape::sphere) {
      planes.lo = planes.lo.cwiseMin(c - Vec3::Constant(light.desc().radius));
      planes.hi = planes.hi.cwiseMax(c + Vec3::Constant(light.desc().radius));
    }
    Vec3 mid = Vec3::Zero();
    for (int k = 0; k < corners; ++k) mid += base[std::size_t(k)];
    mid /= corners;
    for (int k = 0; k < corners; ++k) {
      const Vec3& a = base[std::size_t(k)];
      const Vec3& b = base[std::size_t((k + 1) % corners)];
      Vec3 normal = (a - p).cross(b - p);
      const double len = normal.norm();
      if (!(len > 0)) continue;
      normal /= len;
      if (normal.dot(mid - p) > 0) normal = -normal;
      planes.push_back({normal, normal.dot(p) + reach(normal)});
    }
    // Beyond the light's (or silhouette's) plane, and, for one texel, below the horizon of its
    // surface point (its rays start a little above it and end above it).
    planes.push_back({-base_normal, -base_normal.dot(base[0])});
    // Through the lower of the surface point and the ray origin along the normal: the origin is
    // lifted onto the smooth surface (uv_rasterizer.cpp), which may lie below the flat face's
    // horizon, and the segment starts there.
    if (surface) planes.push_back({-*n, -std::min(n->dot(*surface), n->dot(p))});
    return true;
  }

  // Whether the light lies wholly on one side of a triangle's plane as the whole apex does (or a
  // point apex lies on the plane): then the triangle cannot cut a segment from it to the light.
  static bool same_side(const Tri& t, const Box& apex, const std::array<Vec3, 8>& base, int corners,
                        const Light& light) {
    const Vec3 p = 0.5 * (apex.lo + apex.hi);
    const double spread = (0.5 * (apex.hi - apex.lo)).dot(t.normal.cwiseAbs());
    const double sp = t.normal.dot(p - t.v[0]);
    if (spread == 0 && std::abs(sp) <= kPlaneTolerance) return true;
    // The light's extent along the normal: its base polygon, and for a sphere the sphere itself.
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int k = 0; k < corners; ++k) {
      const double s = t.normal.dot(base[std::size_t(k)] - t.v[0]);
      lo = std::min(lo, s);
      hi = std::max(hi, s);
    }
    if (light.shape() == LightShape::sphere) {
      const double s = t.normal.dot(light.centre() - t.v[0]);
      lo = std::min(lo, s - light.desc().radius);
      hi = std::max(hi, s + light.desc().radius);
    }
    if (sp - spread > -kPlaneTolerance && sp - spread >= 0) return lo >= 0;
    if (sp + spread < 0) return hi <= 0;
    return false;
  }

  // Whether a triangle may lie in the shaft (planes, base) from `apex`, clipped to it in `poly`.
  // Unclipped (clip_it false: what a tile lists), it may keep a dense mesh's triangle near the
  // shaft that misses it.
  bool in_shaft(const Tri& t, const Box& apex, const Planes& planes,
                const std::array<Vec3, 8>& base, int corners, const Light& light, Clip& poly,
                Clip& scratch, bool clip_it = true, bool inside = false) const {
    if (t.normal.isZero()) return false;
    // The triangle's box wholly outside one plane: nothing of it is in the shaft.
    if (!inside && planes.misses(t.lo, t.hi)) return false;
    if (!inside)
      for (const Plane& pl : planes) {
        const Vec3 near(pl.n.x() >= 0 ? t.lo.x() : t.hi.x(), pl.n.y() >= 0 ? t.lo.y() : t.hi.y(),
                        pl.n.z() >= 0 ? t.lo.z() : t.hi.z());
        if (pl.eval(near) > 0) return false;
      }
    if (t.solid >= 0) {
      // Of a closed solid, seen from outside its box: a ray enters it through a triangle facing
      // the ray's origin before it meets one facing away, so those facing away add nothing. A
      // ray skips the first `skip` of its segment (it may step over the face it enters by), so
      // the origin must lie outside the box by that much.
      const Bounds3& solid = h.solids[std::size_t(t.solid)].bounds;
      const bool outside = ((apex.hi.array() + skip) < solid.lo.array()).any() ||
                           ((apex.lo.array() - skip) > solid.hi.array()).any();
      const Vec3 p = 0.5 * (apex.lo + apex.hi);
      const double spread = (0.5 * (apex.hi - apex.lo)).dot(t.normal.cwiseAbs());
      if (outside && t.normal.dot(p - t.v[0]) + spread < 0) return false;
    }
    if (same_side(t, apex, base, corners, light)) return false;
    if (inside && !clip_it) return true;  // within every plane: listed
    if (!clip_it && h.meshes[std::size_t(t.mesh)].count > ShaftCuller::kDenseMesh) {
      // Listed only, of a dense mesh (whose union's outline is taken, not its triangles): kept
      // unless its corners all lie outside one plane (conservative, and much cheaper).
      for (const Plane& pl : planes)
        if (pl.eval(t.v[0]) > 0 && pl.eval(t.v[1]) > 0 && pl.eval(t.v[2]) > 0) return false;
      return true;
    }
    poly.n = 3;
    for (int k = 0; k < 3; ++k) poly.v[std::size_t(k)] = t.v[k];
    for (const Plane& pl : planes) {
      clip(poly, scratch, pl);
      if (poly.n == 0) return false;
    }
    return true;
  }

  // Visits every triangle that may lie in the apex's shaft, clipped to it: visit(index, polygon)
  // returns false to stop. `among`, when given, restricts the search to those triangles (a
  // tile's candidates, for its texels). Returns kNone when the light cannot reach the apex,
  // kUndecided for a box of which some point it cannot reach (its texels must be tested one by
  // one, among every triangle), kStopped when a visit stopped it, and kDone otherwise.
  enum Outcome { kNone, kUndecided, kStopped, kDone };
  template <class Visit>
  Outcome visit_shaft(const Box& apex, const Vec3* surface, const Vec3* n, const Light& light,
                      const std::vector<std::uint32_t>* among, Visit&& visit,
                      bool clip_it = true) const {
    Planes planes;
    std::array<Vec3, 8> base;
    int corners = 0;
    if (!shaft(apex, surface, n, light, planes, base, corners))
      return apex.lo == apex.hi ? kNone : kUndecided;
    if (h.nodes.empty()) return kDone;
    Clip poly, scratch;
    if (among) {
      for (std::uint32_t i : *among)
        if (in_shaft(h.tris[i], apex, planes, base, corners, light, poly, scratch, clip_it) &&
            !visit(i, poly))
          return kStopped;
      return kDone;
    }
    int stack[kStack];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = h.nodes[std::size_t(stack[--top])];
      if (planes.misses(node.box.lo, node.box.hi)) continue;
      bool outside = false, inside = true;
      for (const Plane& pl : planes) {
        // The box's corner least far along the plane's normal, and the farthest.
        const Vec3 near(pl.n.x() >= 0 ? node.box.lo.x() : node.box.hi.x(),
                        pl.n.y() >= 0 ? node.box.lo.y() : node.box.hi.y(),
                        pl.n.z() >= 0 ? node.box.lo.z() : node.box.hi.z());
        if (pl.eval(near) > 0) {
          outside = true;
          break;
        }
        if (inside) inside = pl.eval(node.box.lo + node.box.hi - near) <= 0;
      }
      if (outside) continue;
      if (inside && !clip_it) {
        // Listing a tile's candidates: all of the node lies within the planes, so only the
        // tests of facing and side remain, triangle by triangle.
        for (int i = node.first; i < node.first + node.size; ++i)
          if (in_shaft(h.tris[std::size_t(i)], apex, planes, base, corners, light, poly, scratch,
                       clip_it, /*inside=*/true) &&
              !visit(std::uint32_t(i), poly))
            return kStopped;
        continue;
      }
      if (node.count == 0) {
        if (top + 2 > kStack) return kUndecided;  // deeper than any balanced tree: keep, to be safe
        stack[top++] = node.right;
        stack[top++] = node.left;  // first: triangles are visited in the order of their index
        continue;
      }
      for (int i = node.first; i < node.first + node.count; ++i)
        if (in_shaft(h.tris[std::size_t(i)], apex, planes, base, corners, light, poly, scratch,
                     clip_it) &&
            !visit(std::uint32_t(i), poly))
          return kStopped;
    }
    return kDone;
  }

  // Whether a blocker may lie in the apex's shaft. With `candidates`, every triangle that may
  // (by index) is collected instead of stopping at the first, up to `max` (beyond, or for a box
  // some point of which the light cannot reach, the list is {kAll}); `among` as in visit_shaft.
  bool query(const Box& apex, const Vec3* surface, const Vec3* n, const Light& light,
             std::vector<std::uint32_t>* candidates = nullptr,
             const std::vector<std::uint32_t>* among = nullptr,
             std::size_t max = kMaxCandidates) const {
    bool found = false;
    const Outcome outcome = visit_shaft(
        apex, surface, n, light, among,
        [&](std::uint32_t i, const auto&) {
          found = true;
          if (!candidates) return false;
          candidates->push_back(i);
          return candidates->size() <= max;
        },
        /*clip_it=*/candidates == nullptr);
    if (outcome == kNone) return false;
    if (outcome == kUndecided || (outcome == kStopped && candidates)) {
      // A busy tile, or one the light reaches only in part: search each texel afresh.
      if (candidates) candidates->assign(1, kAll);
      return true;
    }
    return found;
  }

  // In a candidate list: "search every triangle".
  static constexpr std::uint32_t kAll = 0xffffffffu;
  static constexpr std::size_t kMaxCandidates = 32;
};

ShaftCuller::ShaftCuller(const std::vector<const Mesh*>& blockers)
    : impl_(std::make_unique<Impl>()) {
  impl_->h = BlockerHierarchy(blockers);
  const BlockerHierarchy& h = impl_->h;
  Bounds3 all;
  for (const BlockerHierarchy::MeshInfo& m : h.meshes)
    if (!m.bounds.empty()) all.extend(m.bounds);
  impl_->skip = surface_offset_for(all);
  impl_->ball_key.resize(h.solids.size());
  for (std::size_t k = 0; k < h.solids.size(); ++k)
    impl_->ball_key[k] = kSolidKey | std::uint32_t(k);
  impl_->balls.resize(h.meshes.size());
  for (const Tri& t : h.tris) {
    if (t.solid < 0 || !(h.solids[std::size_t(t.solid)].inner_radius > 0)) continue;
    std::vector<std::uint32_t>& balls = impl_->balls[std::size_t(t.mesh)];
    const std::uint32_t key = kSolidKey | std::uint32_t(t.solid);
    if (std::find(balls.begin(), balls.end(), key) == balls.end()) balls.push_back(key);
  }
  keys_.reserve(h.tris.size());
  for (std::size_t i = 0; i < h.tris.size(); ++i) {
    const Tri& t = h.tris[i];
    keys_.push_back(
        t.solid >= 0 && h.solids[std::size_t(t.solid)].convex ? kSolidKey | std::uint32_t(t.solid)
        : h.meshes[std::size_t(t.mesh)].count > kDenseMesh    ? kMeshKey | std::uint32_t(t.mesh)
                                                              : std::uint32_t(i));
  }
}

ShaftCuller::ShaftCuller(ShaftCuller&&) noexcept = default;
ShaftCuller& ShaftCuller::operator=(ShaftCuller&&) noexcept = default;
ShaftCuller::~ShaftCuller() = default;

bool ShaftCuller::tile_candidates(const Bounds3& origins, const Light& light, std::size_t max,
                                  std::vector<std::uint32_t>& candidates,
                                  const std::vector<std::uint32_t>* among) const {
  candidates.clear();
  Box apex;
  apex.lo = origins.lo;
  apex.hi = origins.hi;
  if (!impl_->query(apex, nullptr, nullptr, light, &candidates, among, max)) return false;
  if (!candidates.empty() && candidates[0] == Impl::kAll) candidates.clear();
  return true;
}

ShaftCuller::Polygons ShaftCuller::shaft_polygons(const Vec3& origin, const Vec3& surface,
                                                  const Vec3& normal, const Light& light,
                                                  const std::vector<std::uint32_t>* among,
                                                  std::size_t max,
                                                  std::vector<ShaftPolygon>& out) const {
  out.clear();
  Box apex;
  apex.extend(origin);
  const Impl::Outcome outcome = impl_->visit_shaft(apex, &surface, &normal, light, among,
                                                   [&](std::uint32_t i, const Clip& poly) {
                                                     if (out.size() >= max) return false;
                                                     ShaftPolygon& p = out.emplace_back();
                                                     p.triangle = i;
                                                     p.normal = impl_->h.tris[i].normal;
                                                     p.count = poly.n;
                                                     for (int k = 0; k < p.count; ++k)
                                                       p.v[std::size_t(k)] = poly.v[std::size_t(k)];
                                                     return true;
                                                   });
  switch (outcome) {
    case Impl::kNone:
      out.clear();
      return Polygons::unreached;
    case Impl::kStopped:
      return Polygons::too_many;
    case Impl::kUndecided:  // a hierarchy deeper than its stack: cannot list what it holds
      return Polygons::too_many;
    case Impl::kDone:
      break;
  }
  return Polygons::listed;
}

bool ShaftCuller::maybe_blocked(const Vec3& origin, const Vec3& surface, const Vec3& normal,
                                const Light& light, const std::vector<std::uint32_t>* among,
                                const std::vector<std::uint32_t>* except) const {
  Box apex;
  apex.extend(origin);
  if (!except) return impl_->query(apex, &surface, &normal, light, nullptr, among);
  const Impl::Outcome outcome =
      impl_->visit_shaft(apex, &surface, &normal, light, among, [&](std::uint32_t i, const Clip&) {
        // go on past those listed
        return std::binary_search(except->begin(), except->end(), blocker_key(i));
      });
  return outcome == Impl::kStopped || outcome == Impl::kUndecided;
}

const BlockerSolid* ShaftCuller::solid(std::uint32_t triangle) const {
  const int s = impl_->h.tris[triangle].solid;
  return s < 0 ? nullptr : &impl_->h.solids[std::size_t(s)];
}

Bounds3 ShaftCuller::key_bounds(std::uint32_t key) const {
  if (key & kSolidKey) return solid_of_key(key).bounds;
  if (key & kMeshKey) return impl_->h.meshes[key & ~kMeshKey].bounds;
  return triangle_bounds(key);
}

const BlockerSolid& ShaftCuller::solid_of_key(std::uint32_t key) const {
  return impl_->h.solids[key & ~kSolidKey];
}

std::span<const std::uint32_t> ShaftCuller::solids_with_balls(std::uint32_t key) const {
  if (key & kSolidKey) return {};
  if (key & kMeshKey) return impl_->balls[key & ~kMeshKey];
  const int solid = impl_->h.tris[key].solid;
  if (solid < 0 || !(impl_->h.solids[std::size_t(solid)].inner_radius > 0)) return {};
  return {&impl_->ball_key[std::size_t(solid)], 1};
}

std::size_t ShaftCuller::triangle_count() const { return impl_->h.tris.size(); }

void ShaftCuller::triangles_in_box(const Bounds3& box, std::vector<std::uint32_t>& out) const {
  impl_->h.triangles_in_box(box, out);
}

std::vector<std::uint32_t> ShaftCuller::triangles_within(const Vec3& centre, double radius) const {
  return impl_->h.triangles_within(centre, radius);
}

std::uint32_t ShaftCuller::triangle_of_face(std::int64_t face) const {
  return impl_->h.of_face[std::size_t(face)];
}

int ShaftCuller::mesh_of(std::uint32_t triangle) const { return impl_->h.tris[triangle].mesh; }

int ShaftCuller::neighbour(std::uint32_t triangle, int edge) const {
  return impl_->h.tris[triangle].across[std::size_t(edge)];
}

const Vec3* ShaftCuller::triangle_corners(std::uint32_t triangle) const {
  return impl_->h.tris[triangle].v;
}

const Vec3& ShaftCuller::triangle_normal(std::uint32_t triangle) const {
  return impl_->h.tris[triangle].normal;
}

Bounds3 ShaftCuller::triangle_bounds(std::uint32_t triangle) const {
  const Tri& t = impl_->h.tris[triangle];
  Bounds3 b;
  b.lo = t.lo;
  b.hi = t.hi;
  return b;
}

std::vector<std::uint8_t> ShaftCuller::maybe_blocked(const TexelSpace& space, const Light& light,
                                                     double offset) const {
  // Tiles of kTile² texels (of the lightmap, so neighbours on the surface too, mostly) are
  // tested as one box first: most of a floor is clear of every blocker, and one query says so
  // for a whole tile. Only a tile that may be blocked is tested texel by texel.
  constexpr int kTile = 8;
  const int tiles_x = (space.width + kTile - 1) / kTile;
  const int tiles_y = (space.height + kTile - 1) / kTile;
  std::vector<std::vector<std::uint32_t>> tile_texels(std::size_t(tiles_x) * tiles_y);
  std::vector<Vec3> origin(space.texels.size());
  for (std::size_t i = 0; i < space.texels.size(); ++i) {
    const Texel& t = space.texels[i];
    origin[i] = space.ray_origin(i, offset);
    tile_texels[std::size_t(t.y / kTile) * tiles_x + std::size_t(t.x / kTile)].push_back(
        std::uint32_t(i));
  }
  std::vector<std::uint8_t> out(space.texels.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tile_texels.size(), 16), [&](const auto& r) {
    std::vector<std::uint32_t> candidates;
    for (std::size_t k = r.begin(); k != r.end(); ++k) {
      const std::vector<std::uint32_t>& members = tile_texels[k];
      if (members.empty()) continue;
      // The tile's own shaft first: clear, or the triangles its texels need to look at.
      candidates.clear();
      const bool tile = members.size() > 1;
      if (tile) {
        Box box;
        for (std::uint32_t i : members) box.extend(origin[i]);
        if (!impl_->query(box, nullptr, nullptr, light, &candidates)) continue;
      }
      const bool all = !tile || (!candidates.empty() && candidates[0] == Impl::kAll);
      for (std::uint32_t i : members) {
        const Texel& t = space.texels[i];
        Box apex;
        apex.extend(origin[i]);
        const Vec3 surface = t.position.cast<double>(), normal = t.normal.cast<double>();
        out[i] = impl_->query(apex, &surface, &normal, light, nullptr, all ? nullptr : &candidates);
      }
    }
  });
  return out;
}

}  // namespace sb
