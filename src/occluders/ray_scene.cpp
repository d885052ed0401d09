// Shadow rays with Embree 3 (Wald et al., "Embree: a kernel framework for efficient CPU ray
// tracing", SIGGRAPH 2014). Shadow rays ask only occlusion (rtcOccluded, no hit data, the
// cheapest query); first_hit asks for the closest hit (rtcIntersect) where a method needs the
// blocker's distance. The scene is built once, at high quality, and queried by all threads.
//
// Robust offsets: a shadow ray starts on a triangle it must not hit, so its origin is pushed
// along the geometric normal by surface_offset(). Embree stores vertices in single precision,
// whose spacing at coordinate magnitude m is m·2⁻²³; the offset is 64 of those at the scene's
// largest coordinate, plus 1e-6 of its diagonal, which is 0.1 mm for a 10 m scene: far above
// the float error (no acne), far below any gap an artist means to cast a shadow through (no
// leaks under objects resting on a receiver, whose bottoms lie on or under the offset origin).
#include "occluders/ray_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace sb {

struct RayScene::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  Bounds3 bounds;
  double offset = 1e-4;
  std::vector<std::int64_t> first_face;  // per Embree geometry: its mesh's first face's index
  std::vector<const Mesh*> meshes;       // per Embree geometry: its mesh (blocker_index)

  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

RayScene::RayScene(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RayScene::RayScene(RayScene&&) noexcept = default;
RayScene& RayScene::operator=(RayScene&&) noexcept = default;
RayScene::~RayScene() = default;

Expected<RayScene> RayScene::build(const std::vector<const Mesh*>& blockers) {
  auto impl = std::make_unique<Impl>();
  impl->device = rtcNewDevice(nullptr);
  if (!impl->device) {
    return Error{ErrorKind::internal, "Embree: cannot create a device (error " +
                                          std::to_string(int(rtcGetDeviceError(nullptr))) + ")"};
  }
  impl->scene = rtcNewScene(impl->device);
  rtcSetSceneBuildQuality(impl->scene, RTC_BUILD_QUALITY_HIGH);
  // The context filter serves buried() alone; the other queries pass none.
  rtcSetSceneFlags(impl->scene, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);

  std::int64_t faces = 0;
  for (const Mesh* m : blockers) {
    const TriMesh& mesh = m->mesh;
    faces += std::int64_t(mesh.n_faces());
    if (mesh.n_faces() == 0) continue;
    impl->first_face.push_back(faces - std::int64_t(mesh.n_faces()));
    impl->meshes.push_back(m);
    RTCGeometry geom = rtcNewGeometry(impl->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.n_vertices()));
    auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), mesh.n_faces()));
    for (auto v : mesh.vertices()) {
      const auto& p = mesh.point(v);
      for (int k = 0; k < 3; ++k) vertices[3 * v.idx() + k] = float(p[k]);
      impl->bounds.extend(Vec3(p[0], p[1], p[2]));
    }
    for (auto f : mesh.faces()) {
      int k = 0;
      for (auto v : mesh.fv_range(f)) indices[3 * f.idx() + k++] = unsigned(v.idx());
    }
    rtcCommitGeometry(geom);
    rtcAttachGeometry(impl->scene, geom);
    rtcReleaseGeometry(geom);
  }
  rtcCommitScene(impl->scene);
  if (rtcGetDeviceError(impl->device) != RTC_ERROR_NONE) {
    return Error{ErrorKind::internal, "Embree: building the blocker scene failed"};
  }
  impl->offset = surface_offset_for(impl->bounds);
  return RayScene(std::move(impl));
}

double surface_offset_for(const Bounds3& bounds) {
  if (bounds.empty()) return 1e-4;
  const double largest = bounds.lo.cwiseAbs().cwiseMax(bounds.hi.cwiseAbs()).maxCoeff();
  return 64.0 * std::ldexp(std::max(largest, 1e-3), -23) + 1e-6 * bounds.diagonal();
}

const Bounds3& RayScene::bounds() const { return impl_->bounds; }
double RayScene::surface_offset() const { return impl_->offset; }

namespace {

// Fills lanes of an 8-wide ray packet from segments start.. (at most 8), repeating the last
// segment in the unused lanes, which `valid` switches off. Used by both queries so they agree
// on where a segment begins and ends.
void fill_packet(RTCRay8& rays, int* valid, int start, int n, const Vec3* origins,
                 const Vec3* directions, const double* lengths, double offset) {
  for (int i = 0; i < 8; ++i) {
    valid[i] = i < n ? -1 : 0;
    const int k = start + std::min(i, n - 1);
    rays.org_x[i] = float(origins[k].x());
    rays.org_y[i] = float(origins[k].y());
    rays.org_z[i] = float(origins[k].z());
    rays.dir_x[i] = float(directions[k].x());
    rays.dir_y[i] = float(directions[k].y());
    rays.dir_z[i] = float(directions[k].z());
    // Skip the first surface_offset of the segment as well: a point exactly on another
    // blocker's face (the bottom edge of a box standing on a floor) must not be shadowed by
    // that face at t = 0.
    rays.tnear[i] = float(offset / std::max(directions[k].norm(), 1e-30));
    rays.tfar[i] = float(lengths[k]);
    rays.time[i] = 0.0f;
    rays.mask[i] = 0xFFFFFFFFu;
    rays.id[i] = unsigned(i);
    rays.flags[i] = 0;
  }
}

// One segment origin + t·direction, t ∈ [tnear, tfar], as Embree's single ray.
RTCRay single_ray(const Vec3& origin, const Vec3& direction, double tnear, double tfar) {
  RTCRay ray;
  ray.org_x = float(origin.x());
  ray.org_y = float(origin.y());
  ray.org_z = float(origin.z());
  ray.dir_x = float(direction.x());
  ray.dir_y = float(direction.y());
  ray.dir_z = float(direction.z());
  ray.tnear = float(tnear);
  ray.tfar = float(tfar);
  ray.time = 0.0f;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
  return ray;
}

}  // namespace

double RayScene::first_hit(const Vec3& origin, const Vec3& direction, double length) const {
  double t = -1;
  first_hit(1, &origin, &direction, &length, &t);
  return t;
}

void RayScene::first_hit(int count, const Vec3* origins, const Vec3* directions,
                         const double* lengths, double* t_hit) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  constexpr int kPacket = 8;
  alignas(32) int valid[kPacket];
  RTCRayHit8 query;
  for (int start = 0; start < count; start += kPacket) {
    const int n = std::min(kPacket, count - start);
    fill_packet(query.ray, valid, start, n, origins, directions, lengths, impl_->offset);
    for (int i = 0; i < kPacket; ++i) {
      query.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      query.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(valid, impl_->scene, &context, &query);
    // Embree shortens tfar to the closest hit and sets geomID; a miss keeps RTC_INVALID.
    for (int i = 0; i < n; ++i) {
      t_hit[start + i] =
          query.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID ? double(query.ray.tfar[i]) : -1.0;
    }
  }
}

RayScene::Hit RayScene::first_hit_face(const Vec3& origin, const Vec3& direction,
                                       double length) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit query;
  // As fill_packet: the first surface_offset of the segment skipped.
  query.ray =
      single_ray(origin, direction, impl_->offset / std::max(direction.norm(), 1e-30), length);
  query.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  query.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &query);
  Hit hit;
  if (query.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
  hit.t = double(query.ray.tfar);
  hit.face = impl_->first_face[query.hit.geomID] + std::int64_t(query.hit.primID);
  return hit;
}

void RayScene::occluded(int count, const Vec3* origins, const Vec3* directions,
                        const double* lengths, std::uint8_t* hit) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  constexpr int kPacket = 8;
  alignas(32) int valid[kPacket];
  RTCRay8 rays;
  for (int start = 0; start < count; start += kPacket) {
    const int n = std::min(kPacket, count - start);
    fill_packet(rays, valid, start, n, origins, directions, lengths, impl_->offset);
    rtcOccluded8(valid, impl_->scene, &context, &rays);
    // Embree sets tfar to -inf for each occluded ray.
    for (int i = 0; i < n; ++i) hit[start + i] = rays.tfar[i] < 0.0f ? 1 : 0;
  }
}

namespace {

// buried()'s query: the intersection context Embree passes to the filter, and what the filter
// needs to tell a covering triangle from the point's own surface.
struct BuriedContext {
  RTCIntersectContext base;  // first: Embree hands the filter a pointer to it
  unsigned own_geometry = RTC_INVALID_GEOMETRY_ID;
  Vec3 n, own_winding;
};

// Keeps a hit only where its triangle faces against the point's normal (another blocker's), or
// against its own face's winding (its own mesh's).
void keep_covering(const RTCFilterFunctionNArguments* args) {
  const auto* context = reinterpret_cast<const BuriedContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const Vec3 ng(RTCHitN_Ng_x(args->hit, args->N, i), RTCHitN_Ng_y(args->hit, args->N, i),
                  RTCHitN_Ng_z(args->hit, args->N, i));
    const bool own = RTCHitN_geomID(args->hit, args->N, i) == context->own_geometry;
    const Vec3& against = own ? context->own_winding : context->n;
    // Facing against it within 60°: a side face that only touches the segment's line is no
    // cover.
    if (!(ng.dot(against) < -0.5 * ng.norm() * against.norm())) args->valid[i] = 0;
  }
}

// Whether the side of p that `side` (unit) points to is inside a closed surface: most of five
// rays into that side (along it and tilted 45° towards four perpendicular directions), starting
// beyond the cover and the point's own face, first meet a face from behind. `inverted`: the
// point's mesh is wound against its normals, and so, it is taken, is the scene.
bool enclosed(RTCScene scene, const Vec3& p, const Vec3& side, double skip, bool inverted) {
  const Vec3 u = side.unitOrthogonal(), v = side.cross(u);
  const Vec3 directions[5] = {side, (side + u).normalized(), (side - u).normalized(),
                              (side + v).normalized(), (side - v).normalized()};
  int behind = 0;
  for (const Vec3& d : directions) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit query;
    query.ray = single_ray(p, d, skip, std::numeric_limits<float>::infinity());
    query.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    query.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context, &query);
    if (query.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
    const Vec3 ng(query.hit.Ng_x, query.hit.Ng_y, query.hit.Ng_z);
    if ((ng.dot(d) > 0) != inverted) ++behind;
  }
  return behind >= 3;
}

}  // namespace

bool RayScene::inside_solid(const Vec3& p) const {
  // The 26 directions to a cube's face centres, edge midpoints and corners, turned a little off
  // the axes a level's walls and floors lie along (a ray along a wall meets nothing of it).
  const Eigen::Matrix3d turn =
      (Eigen::AngleAxisd(0.1, Vec3(0, 0, 1)) * Eigen::AngleAxisd(0.07, Vec3(1, 0, 0)))
          .toRotationMatrix();
  int hits = 0, behind = 0;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z) {
        if (x == 0 && y == 0 && z == 0) continue;
        const Vec3 d = turn * Vec3(x, y, z).normalized();
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRayHit query;
        query.ray = single_ray(p, d, 0.0, std::numeric_limits<float>::infinity());
        query.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        query.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(impl_->scene, &context, &query);
        if (query.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
        ++hits;
        // (Embree's geometric normal points to the counter-clockwise front, as enclosed() reads
        // it.)
        behind += Vec3(query.hit.Ng_x, query.hit.Ng_y, query.hit.Ng_z).dot(d) > 0;
      }
  return hits >= 13 && behind == hits;
}

int RayScene::blocker_index(const Mesh* mesh) const {
  const auto it = std::find(impl_->meshes.begin(), impl_->meshes.end(), mesh);
  return it == impl_->meshes.end() ? -1 : int(it - impl_->meshes.begin());
}

bool RayScene::buried(const Vec3& p, const Vec3& n, int own, const Vec3& own_winding) const {
  BuriedContext context;
  rtcInitIntersectContext(&context.base);
  context.base.filter = &keep_covering;
  context.own_geometry = own < 0 ? RTC_INVALID_GEOMETRY_ID : unsigned(own);
  context.n = n;
  context.own_winding = own_winding;
  const double offset = impl_->offset;
  RTCRay ray = single_ray(p + 2.0 * offset * n, -n, 0.0, 2.25 * offset);
  rtcOccluded1(impl_->scene, &context.base, &ray);
  if (!(ray.tfar < 0.0f)) return false;
  // A cover with open space on both sides of it is the other face of a two-sided sheet (a
  // level's thin wall or card, modelled as two coplanar faces back to back), not an object
  // resting on the point: the point is seen.
  const bool inverted = own_winding.dot(n) < 0;
  return enclosed(impl_->scene, p, n, 3.0 * offset, inverted) ||
         enclosed(impl_->scene, p, -n, 3.0 * offset, inverted);
}

}  // namespace sb
