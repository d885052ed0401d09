// Tests of plane_hides_light (plane_occlusion.cpp): a wall of many triangles between a box of
// points and a light hides it where it covers every crossing, and not where a hole, a gap at its
// edge or a light that reaches around it lets a segment through; each answer checked by rays.
#include <gtest/gtest.h>

#include <vector>

#include "core/sampling.h"
#include "occluders/plane_occlusion.h"
#include "occluders/ray_scene.h"
#include "occluders/shaft_culling.h"
#include "scene/lights.h"
#include "scene/mesh.h"

namespace sb {
namespace {

// A wall in the plane x = 0 of `cells` × `cells` squares of `side` metres, each two triangles,
// centred on the origin in (y, z); the squares listed in `holes` (row · cells + column) left out.
Mesh wall(int cells, double side, const std::vector<int>& holes = {}) {
  Mesh m;
  m.name = "wall";
  TriMesh& mesh = m.mesh;
  const double half = 0.5 * cells * side;
  std::vector<TriMesh::VertexHandle> v;
  for (int r = 0; r <= cells; ++r)
    for (int c = 0; c <= cells; ++c)
      v.push_back(mesh.add_vertex(TriMesh::Point(0, c * side - half, r * side - half)));
  for (int r = 0; r < cells; ++r)
    for (int c = 0; c < cells; ++c) {
      if (std::find(holes.begin(), holes.end(), r * cells + c) != holes.end()) continue;
      const auto at = [&](int rr, int cc) { return v[std::size_t(rr * (cells + 1) + cc)]; };
      mesh.add_face(at(r, c), at(r, c + 1), at(r + 1, c + 1));
      mesh.add_face(at(r, c), at(r + 1, c + 1), at(r + 1, c));
    }
  mesh.update_face_normals();
  return m;
}

Light bulb(const Vec3& at, double radius) {
  LightDesc d;
  d.name = "bulb";
  d.shape = LightShape::sphere;
  d.position = at;
  d.radius = radius;
  d.power = 10;
  return Light(d);
}

// Whether some of `samples` random segments from the box to the light's ball misses every
// triangle (a ray finds no hit): light gets through.
bool rays_get_through(const RayScene& rays, const Light& light, const Bounds3& box, int samples) {
  Rng rng(7);
  for (int i = 0; i < samples; ++i) {
    const Vec3 from =
        box.lo +
        Vec3(rng.next_double(), rng.next_double(), rng.next_double()).cwiseProduct(box.hi - box.lo);
    Vec3 d;
    do {
      d = Vec3(2 * rng.next_double() - 1, 2 * rng.next_double() - 1, 2 * rng.next_double() - 1);
    } while (d.squaredNorm() > 1);
    const Vec3 to = light.centre() + light.desc().radius * d;
    if (rays.first_hit_face(from, to - from, 1.0).face < 0) return true;
  }
  return false;
}

struct Case {
  const char* what;
  Mesh mesh;
  Bounds3 box;
  bool dark;  // what plane_hides_light must say
};

TEST(PlaneOcclusion, AWallOfManyTrianglesHidesALightOnlyWhereItCoversEveryCrossing) {
  Bounds3 near_box;  // 2 m behind the wall, 0.6 m across
  near_box.extend(Vec3(-2.3, -0.3, -0.3));
  near_box.extend(Vec3(-1.7, 0.3, 0.3));
  Bounds3 wide_box;  // 10 m across: segments from its edges pass beside the 4 m wall
  wide_box.extend(Vec3(-2.1, -5, -5));
  wide_box.extend(Vec3(-1.9, 5, 5));
  std::vector<Case> cases;
  cases.push_back({"a whole wall of 32 triangles", wall(4, 1.0), near_box, true});
  cases.push_back({"a hole in the middle", wall(4, 1.0, {5}), near_box, false});
  cases.push_back({"a hole at a corner the crossings miss", wall(4, 1.0, {0}), near_box, true});
  cases.push_back({"a box wider than the wall", wall(4, 1.0), wide_box, false});
  const Light light = bulb(Vec3(2, 0.2, -0.1), 0.25);
  for (const Case& c : cases) {
    const std::vector<const Mesh*> blockers = {&c.mesh};
    auto rays = RayScene::build(blockers);
    ASSERT_TRUE(rays) << rays.error().message;
    const ShaftCuller culler(blockers);
    EXPECT_EQ(plane_hides_light(culler, *rays, light, c.box), c.dark) << c.what;
    EXPECT_EQ(rays_get_through(*rays, light, c.box, 20000), !c.dark) << c.what;
  }
  // A light that straddles the wall's plane is never hidden by it, nor one on the box's side.
  const Mesh whole = wall(4, 1.0);
  const std::vector<const Mesh*> blockers = {&whole};
  auto rays = RayScene::build(blockers);
  ASSERT_TRUE(rays);
  const ShaftCuller culler(blockers);
  EXPECT_FALSE(plane_hides_light(culler, *rays, bulb(Vec3(0.1, 0, 0), 0.25), near_box));
  EXPECT_FALSE(plane_hides_light(culler, *rays, bulb(Vec3(-4, 0, 0), 0.25), near_box));
}

}  // namespace
}  // namespace sb
