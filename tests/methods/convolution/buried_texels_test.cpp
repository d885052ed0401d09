// Texels buried in convex closed blockers (buried_texels.cpp): on the showcase floor, the texels
// under the box and the cone's base, and no others; none of the box's own texels; and with the
// showcase baked by convolution, those texels dark as in the reference.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "methods/convolution/buried_texels.h"
#include "occluders/clusters.h"
#include "pipeline/bake.h"
#include "support/test_scenes.h"

namespace sb {
namespace {

struct Loaded {
  std::vector<Mesh> meshes;
  std::vector<const Mesh*> blockers;
  ClusterTree clusters;
};

Loaded load_meshes(const Scene& scene) {
  Loaded l;
  for (const auto& obj : scene.objects) l.meshes.push_back(*import_mesh(obj, scene.file));
  for (std::size_t i = 0; i < l.meshes.size(); ++i)
    if (scene.objects[i].blocker) l.blockers.push_back(&l.meshes[i]);
  l.clusters = build_clusters(l.blockers);
  return l;
}

std::size_t index_of(const Scene& scene, const std::string& name) {
  for (std::size_t i = 0; i < scene.objects.size(); ++i)
    if (scene.objects[i].name == name) return i;
  throw std::runtime_error("no object " + name);
}

// The showcase's meshes and one receiver's texels at `res`.
struct ShowcaseTexels {
  Scene scene;
  Loaded loaded;
  const Mesh* receiver = nullptr;
  TexelSpace space;
};

ShowcaseTexels showcase_texels(int res, const std::string& receiver) {
  ShowcaseTexels s{test_scenes::load("showcase", res, "convolution"), {}, nullptr, {}};
  s.loaded = load_meshes(s.scene);
  s.receiver = &s.loaded.meshes[index_of(s.scene, receiver)];
  s.space = rasterise_texels(*s.receiver, res, res);
  return s;
}

// A floor point in the showcase box's frame: the box is 0.5 x 0.4 m about (-0.8, 0.6), turned
// 25° about z.
Vec2 box_local(const Vec3& p) {
  const double a = 25 * std::numbers::pi / 180;
  return Vec2(std::cos(a) * (p.x() + 0.8) + std::sin(a) * (p.y() - 0.6),
              -std::sin(a) * (p.x() + 0.8) + std::cos(a) * (p.y() - 0.6));
}

TEST(BuriedTexels, FloorUnderTheBoxAndTheConeOnly) {
  const ShowcaseTexels s = showcase_texels(256, "floor");
  const Loaded& l = s.loaded;
  const TexelSpace& space = s.space;
  // The floor is 4 m square; its chart does not fill the whole texture.
  const double texel = std::sqrt(16.0 / double(space.texels.size()));
  const auto buried = buried_texels(space, *s.receiver, l.blockers, l.clusters, 1e-3 * texel);
  double area = 0, box_area = 0;
  for (std::size_t t = 0; t < buried.size(); ++t) {
    if (!buried[t]) continue;
    area += texel * texel;
    // Under the box or the cone (radius 0.2 m about (-0.5, -0.5)); the sphere touches the floor
    // at a point only.
    const Vec3 p = space.texels[t].position.cast<double>();
    const Vec2 local = box_local(p);
    const bool under_box = std::abs(local.x()) <= 0.25 + 1e-6 && std::abs(local.y()) <= 0.2 + 1e-6;
    const bool under_cone = std::hypot(p.x() + 0.5, p.y() + 0.5) <= 0.2 + 1e-6;
    EXPECT_TRUE(under_box || under_cone) << "texel at " << p.transpose();
    if (under_box) box_area += texel * texel;
  }
  // The box's 0.2 m² and the cone's base: a 48-gon of radius 0.2 m (cone.obj), within the texels
  // cut by their outlines.
  const double cone = 0.5 * 48 * 0.04 * std::sin(2 * std::numbers::pi / 48);
  EXPECT_NEAR(box_area, 0.2, 0.03 * 0.2);
  EXPECT_NEAR(area - box_area, cone, 0.05 * cone);
}

TEST(BuriedTexels, NoneOfTheReceiversOwnTexels) {
  const ShowcaseTexels s = showcase_texels(128, "box");
  const auto buried =
      buried_texels(s.space, *s.receiver, s.loaded.blockers, s.loaded.clusters, 1e-5);
  std::size_t count = 0;
  for (auto b : buried) count += b;
  EXPECT_EQ(count, 0u) << "of " << buried.size() << " texels of the box";
}

TEST(BuriedTexels, ShowcaseFloorIsDarkUnderTheBox) {
  const int res = 128;
  const Scene scene = test_scenes::load("showcase", res, "convolution");
  const auto result = bake(scene, BakeOptions{});
  ASSERT_TRUE(result) << result.error().message;
  const ReceiverBake* baked = nullptr;
  for (const auto& r : result->receivers)
    if (r.name == "floor") baked = &r;
  ASSERT_NE(baked, nullptr);
  const TexelSpace space = showcase_texels(res, "floor").space;
  // Every texel under the box, a texel in from its outline, is black; the slabs' counts alone
  // left outlines of their sections lit there.
  int under = 0, lit = 0;
  for (const Texel& t : space.texels) {
    const Vec2 local = box_local(t.position.cast<double>());
    const double inset = 4.0 / res;
    if (std::abs(local.x()) > 0.25 - inset || std::abs(local.y()) > 0.2 - inset) continue;
    ++under;
    const float* px = baked->image.at(t.x, t.y);
    if (px[0] != 0.0f || px[1] != 0.0f || px[2] != 0.0f) ++lit;
  }
  EXPECT_GT(under, 100);
  EXPECT_EQ(lit, 0) << "of " << under << " texels under the box";
}

}  // namespace
}  // namespace sb
