// What each of the default method's routes gives one texel of one light (a developer tool, for
// finding why a texel comes out wrong): the texel's record, the reference's estimate at several
// sample counts, the centre ray's first hit, the texel's own shaft's polygons from the whole
// hierarchy and the estimator's value over them, and the whole method's value for the texel.
//
// Run: build/shadowbake_texel_probe [--resolution N] SCENE RECEIVER LIGHT X Y [X Y ...] (SCENE: a
// scene file or a level; --resolution as the bake's, overriding the scene's sizes; LIGHT "*":
// every light that reaches the texel, the worst first)
#include <fmt/core.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "methods/backprojection/backprojection_bake.h"
#include "methods/backprojection/penumbra_estimator.h"
#include "occluders/shadow_rays.h"
#include "scene/level_file.h"
#include "support/built_scene.h"
#include "texels/lightmap_sizes.h"

namespace {

// Calls f(x, y, texel) for each X Y pair of `points` (count of them) that a texel covers; says
// so for the others.
template <class F>
void each_point(const sb::TexelGrid& grid, int count, char** points, F&& f) {
  for (int a = 0; a + 1 < count; a += 2) {
    const int x = std::atoi(points[a]), y = std::atoi(points[a + 1]);
    const std::int32_t t = grid.texel(x, y);
    if (t < 0)
      fmt::print("({}, {}): not covered\n", x, y);
    else
      f(x, y, std::size_t(t));
  }
}

// LIGHT "*": every light that reaches each texel, with its H0 (summed over channels), the
// method's V and the reference's at 4096 samples, the largest H0-weighted difference first.
int every_light(const sb::test_scenes::Built& built, const sb::TexelSpace& space, int count,
                char** points) {
  using namespace sb;
  BackprojectionInputs in;
  in.lights = &built.lights;
  in.culler = &*built.culler;
  in.rays = &*built.rays;
  const TexelGrid grid(space);
  std::vector<std::optional<LightField>> fields(built.lights.size());
  each_point(grid, count, points, [&](int x, int y, std::size_t t) {
    const Texel& tx = space.texels[t];
    const Vec3 p = tx.position.cast<double>(), n = tx.normal.cast<double>();
    struct Row {
      std::string name;
      double h0, method, reference;
    };
    std::vector<Row> rows;
    double h = 0, h_ref = 0, h0 = 0;
    for (std::size_t l = 0; l < built.lights.size(); ++l) {
      const Light& light = built.lights[l];
      if (!light.reaches(p, n)) continue;
      const double weight = light.unoccluded_irradiance(p, n).sum();
      if (!(weight > 0)) continue;
      if (!fields[l]) fields[l] = backprojection_light(space, in, l);
      ShadowRays batch(4096);
      std::vector<Vec2> strata;
      Vec3 v = Vec3::Zero();
      estimate_visibility(space, t, light, *built.rays, 4096, 3, 0, batch, strata, &v);
      rows.push_back({light.desc().name, weight, fields[l]->visibility_at(x, y), v.x()});
      h += weight * rows.back().method, h_ref += weight * v.x(), h0 += weight;
    }
    std::sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) {
      return a.h0 * std::abs(a.method - a.reference) > b.h0 * std::abs(b.method - b.reference);
    });
    fmt::print(
        "({}, {}) p ({:.4f} {:.4f} {:.4f}) n ({:.3f} {:.3f} {:.3f}): {} lights, V {:.4f}, "
        "reference 4096 {:.4f}\n",
        x, y, p.x(), p.y(), p.z(), n.x(), n.y(), n.z(), rows.size(), h / h0, h_ref / h0);
    for (std::size_t k = 0; k < std::min<std::size_t>(rows.size(), 8); ++k)
      fmt::print("  {}: H0 {:.4g}  V {:.4f}  reference {:.4f}\n", rows[k].name, rows[k].h0,
                 rows[k].method, rows[k].reference);
  });
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace sb;
  int resolution = 0;
  if (argc > 2 && std::string(argv[1]) == "--resolution") {
    resolution = std::atoi(argv[2]);
    argc -= 2;
    argv += 2;
  }
  if (argc < 6 || (argc - 4) % 2 != 0) {
    fmt::print(stderr, "usage: {} [--resolution N] SCENE RECEIVER LIGHT X Y [X Y ...]\n", argv[0]);
    return 2;
  }
  const std::filesystem::path file = argv[1];
  auto scene = file.extension() == ".toml" ? load_scene(file) : load_level_scene(file);
  if (!scene) {
    fmt::print(stderr, "{}\n", scene.error().message);
    return 1;
  }
  if (resolution > 0) {
    scene->bake.resolution = resolution;
    scene->bake.texels_per_metre = 0;
  }
  const test_scenes::Built built(*scene);
  const std::vector<int> sides = lightmap_sides(*scene, built.meshes, nullptr);
  std::size_t object = 0, receiver = 0;
  for (std::size_t i = 0, r = 0; i < scene->objects.size(); ++i) {
    if (!scene->objects[i].receiver) continue;
    if (scene->objects[i].name == argv[2]) object = i, receiver = r;
    ++r;
  }
  const int side = sides[receiver];
  const TexelSpace space = rasterise_texels(built.meshes[object], side, side);
  if (std::string(argv[3]) == "*") return every_light(built, space, argc - 4, argv + 4);
  std::size_t light = 0;
  for (std::size_t l = 0; l < built.lights.size(); ++l)
    if (built.lights[l].desc().name == argv[3]) light = l;
  const Light& L = built.lights[light];
  const double offset = built.rays->surface_offset();
  BackprojectionInputs in;
  in.lights = &built.lights;
  in.culler = &*built.culler;
  in.rays = &*built.rays;
  const LightField field = backprojection_light(space, in, light);
  const TexelGrid grid(space);
  each_point(grid, argc - 4, argv + 4, [&](int x, int y, std::size_t t) {
    const Texel& tx = space.texels[t];
    const Vec3 p = tx.position.cast<double>(), n = tx.normal.cast<double>();
    const Vec3 o = space.ray_origin(std::size_t(t), offset);
    fmt::print(
        "({}, {}) texel {} face {} p ({:.4f} {:.4f} {:.4f}) n ({:.3f} {:.3f} {:.3f}) "
        "origin-p ({:.2e} {:.2e} {:.2e}) F {:.3e}\n",
        x, y, t, tx.face, p.x(), p.y(), p.z(), n.x(), n.y(), n.z(), (o - p).x(), (o - p).y(),
        (o - p).z(), L.form_factor(p, n));
    fmt::print("  method: V {:.4f} route {}\n", field.visibility_at(x, y),
               to_string(field.route_at(x, y)));
    for (int samples : {64, 1024, 16384}) {
      ShadowRays batch(samples);
      std::vector<Vec2> strata;
      Vec3 v;
      if (estimate_visibility(space, t, L, *built.rays, samples, 3, 0, batch, strata, &v))
        fmt::print("  reference {}: V {:.4f}\n", samples, v.x());
    }
    const Vec3 dir = L.centre() - o;
    const RayScene::Hit hit = built.rays->first_hit_face(o, dir, 1.0);
    fmt::print("  centre ray: {}\n",
               hit.face < 0 ? std::string("clear")
                            : fmt::format("hit at {:.3g} m, triangle {}", hit.t * dir.norm(),
                                          built.culler->triangle_of_face(hit.face)));
    std::vector<ShaftPolygon> polygons;
    const auto listed = built.culler->shaft_polygons(o, p, n, L, nullptr, 100000, polygons);
    fmt::print("  own shaft: {} polygons ({})\n", polygons.size(),
               listed == ShaftCuller::Polygons::listed ? "listed" : "not all listed");
    std::vector<BlockerPolygon> blockers;
    for (const ShaftPolygon& poly : polygons) {
      blockers.push_back({poly.v.data(), poly.count, poly.normal, poly.triangle});
      if (polygons.size() <= 12) {
        fmt::print("    triangle {} key {:x} normal ({:.3f} {:.3f} {:.3f}) corners {}:",
                   poly.triangle, built.culler->blocker_key(poly.triangle), poly.normal.x(),
                   poly.normal.y(), poly.normal.z(), poly.count);
        for (const Vec3& c : std::span(built.culler->triangle_corners(poly.triangle), 3))
          fmt::print(" ({:.4f} {:.4f} {:.4f})", c.x(), c.y(), c.z());
        fmt::print("\n");
      }
    }
    std::vector<BlockerPolygon> whole;
    for (const ShaftPolygon& poly : polygons)
      whole.push_back(
          {built.culler->triangle_corners(poly.triangle), 3, poly.normal, poly.triangle});
    {
      const PenumbraEstimator estimator(L, 32, offset);
      const PenumbraSample s =
          estimator.visibility(p, n, o, Blockers{&whole, nullptr, nullptr}, 0, nullptr);
      fmt::print("  estimator over its shaft's whole triangles, 32 rows: V {:.4f}\n", s.visibility);
    }
    for (int rows : {32, 64}) {
      const PenumbraEstimator estimator(L, rows, offset);
      const PenumbraSample s =
          estimator.visibility(p, n, o, Blockers{&blockers, nullptr, nullptr}, 0, nullptr);
      fmt::print("  estimator over its own shaft, {} rows: V {:.4f} (contributes {})\n", rows,
                 s.visibility, s.contributes);
    }
  });
  return 0;
}
