// Tests of generated lightmap UVs (src/texels/auto_uv.cpp): a cylinder unrolled without stretch,
// every receiver of the corpus packed with no overlap and its charts the margin apart, the side a
// density gives, the mesh's faces and texture UVs kept, and a side too small for the charts.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "pipeline/bake.h"
#include "scene/mesh.h"
#include "texels/auto_uv.h"
#include "texels/lightmap_sizes.h"
#include "texels/texel_space.h"
#include "texels/uv_checks.h"

namespace sb {
namespace {

// A corpus mesh as a receiver whose lightmap UVs the bake makes.
Mesh corpus_mesh(const std::string& file) {
  ObjectDesc obj;
  obj.name = "m";
  obj.mesh = std::string(SB_SOURCE_DIR) + "/scenes/" + file;
  obj.auto_uv = true;
  auto mesh = import_mesh(obj, std::string(SB_SOURCE_DIR) + "/scenes/scene.toml");
  EXPECT_TRUE(mesh) << mesh.error().message;
  return mesh ? std::move(*mesh) : Mesh{};
}

// Pairs of lightmap-UV triangles whose interiors overlap by more than `eps` (UV units) across
// every separating axis (their six edge normals): the layout judged without uv_checks.cpp, whose
// texel counts the other checks use. Triangles sharing an edge or a corner touch, and are apart.
int overlapping_uv_triangles(const Mesh& mesh, double eps = 1e-7) {
  std::vector<std::array<Vec2, 3>> tris;
  for (const auto f : mesh.mesh.faces()) {
    const Triangle t = triangle(mesh.mesh, f);
    tris.push_back({t.uv[0], t.uv[1], t.uv[2]});
  }
  const auto apart = [&](const std::array<Vec2, 3>& a, const std::array<Vec2, 3>& b) {
    for (const auto* t : {&a, &b})
      for (int e = 0; e < 3; ++e) {
        const Vec2 d = (*t)[(e + 1) % 3] - (*t)[e];
        const Vec2 n = Vec2(-d.y(), d.x());
        if (n.norm() == 0) return true;  // a degenerate triangle covers nothing
        double a_lo = 1e300, a_hi = -1e300, b_lo = 1e300, b_hi = -1e300;
        for (const Vec2& p : a)
          a_lo = std::min(a_lo, n.dot(p) / n.norm()), a_hi = std::max(a_hi, n.dot(p) / n.norm());
        for (const Vec2& p : b)
          b_lo = std::min(b_lo, n.dot(p) / n.norm()), b_hi = std::max(b_hi, n.dot(p) / n.norm());
        if (a_hi - b_lo < eps || b_hi - a_lo < eps) return true;
      }
    return false;
  };
  // A grid of 64² cells over [0, 1]²; a pair is tested in the cell of its boxes' overlap's
  // lower corner only.
  constexpr int kGrid = 64;
  const auto cell = [](double x) { return std::clamp(int(x * kGrid), 0, kGrid - 1); };
  std::vector<std::vector<std::size_t>> grid(kGrid * kGrid);
  std::vector<std::array<double, 4>> boxes;  // u_lo, v_lo, u_hi, v_hi
  for (std::size_t i = 0; i < tris.size(); ++i) {
    std::array<double, 4> box = {1e300, 1e300, -1e300, -1e300};
    for (const Vec2& p : tris[i])
      box = {std::min(box[0], p.x()), std::min(box[1], p.y()), std::max(box[2], p.x()),
             std::max(box[3], p.y())};
    boxes.push_back(box);
    for (int y = cell(box[1]); y <= cell(box[3]); ++y)
      for (int x = cell(box[0]); x <= cell(box[2]); ++x)
        grid[std::size_t(y * kGrid + x)].push_back(i);
  }
  int overlaps = 0;
  for (int c = 0; c < kGrid * kGrid; ++c)
    for (std::size_t k = 0; k < grid[std::size_t(c)].size(); ++k)
      for (std::size_t l = k + 1; l < grid[std::size_t(c)].size(); ++l) {
        const std::size_t i = grid[std::size_t(c)][k], j = grid[std::size_t(c)][l];
        const double lo_u = std::max(boxes[i][0], boxes[j][0]),
                     lo_v = std::max(boxes[i][1], boxes[j][1]);
        if (lo_u > std::min(boxes[i][2], boxes[j][2]) || lo_v > std::min(boxes[i][3], boxes[j][3]))
          continue;                                          // the boxes are apart
        if (cell(lo_v) * kGrid + cell(lo_u) != c) continue;  // tested in another cell
        overlaps += !apart(tris[i], tris[j]);
      }
  return overlaps;
}

// The check above finds what it is for: two triangles laid over each other in UV, and not two
// that share an edge.
TEST(AutoUv, TheIndependentOverlapCheckFindsAnOverlap) {
  for (const bool folded : {true, false}) {
    Mesh m;
    m.name = "pair";
    const auto vertex = [&](double x, double y, double u, double v) {
      const auto h = m.mesh.add_vertex(TriMesh::Point(x, y, 0));
      m.mesh.set_normal(h, TriMesh::Normal(0, 0, 1));
      m.mesh.set_texcoord2D(h, TriMesh::TexCoord2D(u, v));
      return h;
    };
    std::vector<Vec2> unused;
    const auto a = vertex(0, 0, 0.1, 0.1), b = vertex(1, 0, 0.6, 0.1), c = vertex(0, 1, 0.1, 0.6);
    const auto d = folded ? vertex(1, 1, 0.05, 0.05) : vertex(1, 1, 0.6, 0.6);
    add_triangle(m.mesh, a, b, c, unused);
    add_triangle(m.mesh, b, d, c, unused);
    m.has_uv = true;
    EXPECT_EQ(overlapping_uv_triangles(m), folded ? 1 : 0) << folded;
  }
}

AutoUvTarget side_target(int side, int margin = 4) {
  AutoUvTarget target;
  target.side = side;
  target.max_side = side;
  target.margin = margin;
  return target;
}

TEST(AutoUv, CylinderUnrollsWithoutStretchAndKeepsItsFaces) {
  Mesh mesh = corpus_mesh("seams/cylinder.glb");
  ASSERT_FALSE(mesh.has_uv);
  ASSERT_FALSE(mesh.texture_uv.empty());
  const Mesh before = mesh;
  auto made = generate_lightmap_uvs(mesh, side_target(256));
  ASSERT_TRUE(made) << made.error().message;
  EXPECT_TRUE(mesh.has_uv);
  EXPECT_TRUE(mesh.uv_generated);
  EXPECT_EQ(made->side, 256);
  // The side (32 segments) in four charts, none wider than 120° of arc (normals within 60° of
  // their mean), and the two flat caps.
  EXPECT_EQ(made->charts, 6);
  EXPECT_EQ(made->conformal_charts, 4);

  // The same faces in the same order, each corner with its position, normal and texture UV.
  ASSERT_EQ(mesh.mesh.n_faces(), before.mesh.n_faces());
  ASSERT_EQ(mesh.texture_uv.size(), mesh.mesh.n_vertices());
  for (auto f : mesh.mesh.faces()) {
    const auto g = before.mesh.face_handle(f.idx());
    auto v = mesh.mesh.fv_begin(f);
    auto w = before.mesh.cfv_begin(g);
    for (int k = 0; k < 3; ++k, ++v, ++w) {
      EXPECT_EQ(mesh.mesh.point(*v), before.mesh.point(*w));
      EXPECT_EQ(mesh.mesh.normal(*v), before.mesh.normal(*w));
      EXPECT_EQ(mesh.texture_uv[std::size_t(v->idx())], before.texture_uv[std::size_t(w->idx())]);
      const auto& uv = mesh.mesh.texcoord2D(*v);
      EXPECT_TRUE(uv[0] > 0 && uv[0] < 1 && uv[1] > 0 && uv[1] < 1) << uv;
    }
  }

  // A cylinder and its caps are developable: no stretch, an even density.
  const TexelSpace space = rasterise_texels(mesh, 256, 256);
  const UvLayoutReport layout = check_uv_layout(mesh, space, 4);
  EXPECT_EQ(layout.charts, 6);
  EXPECT_NEAR(layout.stretch, 1.0, 1e-6);
  EXPECT_NEAR(layout.density_spread, 1.0, 1e-6);
  EXPECT_EQ(layout.overlapping_texels, 0);
  EXPECT_EQ(layout.texels_near_other_charts, 0);
  EXPECT_TRUE(layout.generated);
}

// Every receiver mesh of the corpus's scenes, its own lightmap UVs set aside: no texel two charts
// claim, no covered texel within the 4-texel margin of another chart, nothing outside [0, 1]²,
// and little stretch (Smart UV Project's layouts of the same meshes reach 1.036 and a density
// spread of 1.34).
TEST(AutoUv, EveryCorpusReceiverPacksApartWithoutOverlap) {
  const std::vector<std::string> files = {
      "room/floor.glb",     "room/back_wall.glb",  "room/chair.glb",
      "room/ball.glb",      "atrium/column_1.glb", "atrium/bench.glb",
      "atrium/suzanne.glb", "atrium/blob.glb",     "shelf/shelf.glb",
      "shelf/books.glb",    "hall/table_1.glb",    "hall/sphere_1.glb",
      "seams/box.glb",      "seams/cylinder.glb",  "seams/box_lightmap_pack.glb"};
  for (const std::string& file : files) {
    SCOPED_TRACE(file);
    Mesh mesh = corpus_mesh(file);
    auto made = generate_lightmap_uvs(mesh, side_target(256));
    ASSERT_TRUE(made) << made.error().message;
    const TexelSpace space = rasterise_texels(mesh, 256, 256);
    const UvLayoutReport layout = check_uv_layout(mesh, space, 4);
    EXPECT_EQ(layout.charts, made->charts);
    EXPECT_EQ(layout.overlapping_texels, 0);
    EXPECT_EQ(overlapping_uv_triangles(mesh), 0);
    EXPECT_EQ(layout.texels_near_other_charts, 0);
    EXPECT_LT(layout.uv_area_outside, 1e-12);  // rounding of the area clipped to [0, 1]²
    EXPECT_LT(layout.stretch, 1.02);
    EXPECT_LT(layout.density_spread, 1.35);
    // Packed tightly enough that a texel's share of the surface is at least a third of the best.
    EXPECT_GT(double(space.texels.size()), 0.3 * 256 * 256) << space.texels.size();
  }
}

TEST(AutoUv, ADensityGivesTheSideTheBakeSizesTheLightmapBy) {
  Mesh mesh = corpus_mesh("room/chair.glb");
  AutoUvTarget target;
  target.texels_per_metre = 200;
  target.max_side = kMaxLightmapSide;
  auto made = generate_lightmap_uvs(mesh, target);
  ASSERT_TRUE(made) << made.error().message;
  EXPECT_EQ(made->texels_per_metre, 200);
  EXPECT_GT(made->side, kMinLightmapSide);
  // The smallest side that holds the charts, and the side lightmap_sides then gives the mesh.
  EXPECT_EQ(lightmap_side(mesh, 200, kMaxLightmapSide).side, made->side);
  Mesh smaller = corpus_mesh("room/chair.glb");
  auto tight = generate_lightmap_uvs(smaller, side_target(made->side - 1));
  ASSERT_TRUE(tight);
  EXPECT_LT(tight->texels_per_metre, 200);

  // Capped: the largest side, filled at a lower density.
  Mesh capped = corpus_mesh("room/chair.glb");
  target.max_side = made->side / 2;
  auto clamped = generate_lightmap_uvs(capped, target);
  ASSERT_TRUE(clamped);
  EXPECT_EQ(clamped->side, made->side / 2);
  EXPECT_LT(clamped->texels_per_metre, 110);
}

// A flat sheet of 2 × 3 unit quads whose two columns are not welded along x = 1 from y = 0 to 2
// (the right column's vertices there lie 1 nm off the plane, as an unwelded panel's do): a crack
// whose two lips fall on one another in UV. One chart: the lips touch in space, so the chart does
// not fold.
TEST(AutoUv, ACrackIsNotAFold) {
  Mesh m;
  m.name = "sheet";
  auto vertex = [&](double x, double y, double z) {
    const auto h = m.mesh.add_vertex(TriMesh::Point(x, y, z));
    m.mesh.set_normal(h, TriMesh::Normal(0, 0, 1));
    return h;
  };
  std::vector<Vec2> unused;
  auto quad = [&](TriMesh::VertexHandle a, TriMesh::VertexHandle b, TriMesh::VertexHandle c,
                  TriMesh::VertexHandle d) {
    add_triangle(m.mesh, a, b, c, unused);
    add_triangle(m.mesh, a, c, d, unused);
  };
  for (int row = 0; row < 3; ++row) {
    const double z = row < 2 ? 1e-9 : 0.0;  // the right column's lip, below y = 2
    const double y0 = row, y1 = row + 1;
    quad(vertex(0, y0, 0), vertex(1, y0, 0), vertex(1, y1, 0), vertex(0, y1, 0));
    quad(vertex(1, y0, z), vertex(2, y0, 0), vertex(2, y1, 0), vertex(1, y1, row < 1 ? z : 0.0));
  }
  m.mesh.update_face_normals();
  auto made = generate_lightmap_uvs(m, side_target(64));
  ASSERT_TRUE(made) << made.error().message;
  EXPECT_EQ(made->charts, 1);
}

// A ramp winding `turns` turns (a helicoid, radii 0.3 to 1 m, rising `rise` m a turn), 72
// segments a turn: its normals stay within 6° of up, so it grows as one smooth chart.
Mesh helical_ramp(double turns, double rise_per_turn = 0.2) {
  Mesh m;
  m.name = "ramp";
  const int around = int(72 * turns), across = 4;
  std::vector<TriMesh::VertexHandle> v;
  for (int i = 0; i <= around; ++i) {
    const double angle = 2 * std::numbers::pi * turns * i / around;
    const double rise = 0.2 * angle / (2 * std::numbers::pi);
    for (int j = 0; j <= across; ++j) {
      const double r = 0.3 + 0.7 * j / across;
      v.push_back(
          m.mesh.add_vertex(TriMesh::Point(r * std::cos(angle), r * std::sin(angle), rise)));
      // The helicoid's normal: across the radial and tangential directions.
      const Vec3 radial(std::cos(angle), std::sin(angle), 0);
      const Vec3 along(-r * std::sin(angle), r * std::cos(angle),
                       rise_per_turn / (2 * std::numbers::pi));
      const Vec3 n = radial.cross(along).normalized();
      m.mesh.set_normal(v.back(), TriMesh::Normal(n.x(), n.y(), n.z()));
    }
  }
  std::vector<Vec2> unused;
  const auto at = [&](int i, int j) { return v[std::size_t(i * (across + 1) + j)]; };
  for (int i = 0; i < around; ++i)
    for (int j = 0; j < across; ++j) {
      add_triangle(m.mesh, at(i, j), at(i, j + 1), at(i + 1, j + 1), unused);
      add_triangle(m.mesh, at(i, j), at(i + 1, j + 1), at(i + 1, j), unused);
    }
  m.mesh.update_face_normals();
  return m;
}

// Flattened, the ramp laps over itself once it winds more than a turn: at 0.9 turns it stays one
// chart, at 1.5 the chart folds and is cut where it does (in two, not shattered), and the layout
// has no texel two charts claim.
TEST(AutoUv, AChartThatFoldsIsCut) {
  Mesh short_ramp = helical_ramp(0.9);
  auto one = generate_lightmap_uvs(short_ramp, side_target(256));
  ASSERT_TRUE(one) << one.error().message;
  EXPECT_EQ(one->charts, 1);
  Mesh m = helical_ramp(1.5);
  auto made = generate_lightmap_uvs(m, side_target(256));
  ASSERT_TRUE(made) << made.error().message;
  EXPECT_EQ(made->charts, 2);
  const TexelSpace space = rasterise_texels(m, 256, 256);
  const UvLayoutReport layout = check_uv_layout(m, space, 4);
  EXPECT_EQ(layout.overlapping_texels, 0);
  EXPECT_EQ(layout.texels_near_other_charts, 0);
  EXPECT_LT(layout.stretch, 1.05);
}

// A flat fan around one vertex whose wedges add up to more than a turn (405°): its last triangle
// lies on its first, coplanar, as brushwork's overlapping faces do (zdm2's among them), so its
// border edges cross where they also touch in space, as a crack's lips do. The triangles' overlap
// cuts it all the same: no texel is claimed twice.
TEST(AutoUv, CoplanarFacesThatOverlapAreCutApart) {
  Mesh m;
  m.name = "fan";
  std::vector<Vec2> unused;
  auto vertex = [&](double x, double y) {
    const auto h = m.mesh.add_vertex(TriMesh::Point(x, y, 0));
    m.mesh.set_normal(h, TriMesh::Normal(0, 0, 1));
    return h;
  };
  const auto centre = vertex(0, 0);
  std::vector<TriMesh::VertexHandle> rim;
  for (const double degrees : {0.0, 90.0, 180.0, 270.0, 405.0}) {
    const double a = degrees * std::numbers::pi / 180, r = degrees > 360 ? 0.5 : 1.0;
    rim.push_back(vertex(r * std::cos(a), r * std::sin(a)));
  }
  for (std::size_t k = 0; k + 1 < rim.size(); ++k)
    add_triangle(m.mesh, centre, rim[k], rim[k + 1], unused);
  m.mesh.update_face_normals();
  auto made = generate_lightmap_uvs(m, side_target(64));
  ASSERT_TRUE(made) << made.error().message;
  EXPECT_GE(made->charts, 2);
  const TexelSpace space = rasterise_texels(m, 64, 64);
  EXPECT_EQ(check_uv_layout(m, space, 4).overlapping_texels, 0);
}

TEST(AutoUv, ChartsThatCannotFitTheSideAreAnError) {
  Mesh mesh = corpus_mesh("shelf/books.glb");  // 522 charts
  auto made = generate_lightmap_uvs(mesh, side_target(32));
  ASSERT_FALSE(made);
  EXPECT_NE(made.error().message.find("do not fit a 32² lightmap"), std::string::npos)
      << made.error().message;
}

// Charts that fit the side only as texel-less points (at density 0 each takes 1 + margin texels a
// side, at any density above 0 one more): an error, found at once, where the density's search
// used to halve towards 0 for ever (a chair of six boxes at 32², found by the Blender add-on).
TEST(AutoUv, ChartsThatFitOnlyAsTexellessPointsAreAnError) {
  Mesh m;
  m.name = "tiles";
  std::vector<Vec2> unused;
  // Six squares 1 m apart, each facing its own way, so that no two join into one chart: at
  // margin 4 a 16² side holds nine 5 × 5 points but only four 6 × 6 ones.
  const std::array<Vec3, 6> normals = {Vec3(0, 0, 1),  Vec3(0, 0, -1), Vec3(0, 1, 0),
                                       Vec3(0, -1, 0), Vec3(1, 0, 0),  Vec3(-1, 0, 0)};
  for (std::size_t k = 0; k < normals.size(); ++k) {
    const Vec3 n = normals[k];
    const Vec3 u = (std::abs(n.x()) < 0.5 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
    const Vec3 v = n.cross(u);
    const Vec3 c(3.0 * double(k), 0, 0);
    std::array<TriMesh::VertexHandle, 4> corner;
    for (int j = 0; j < 4; ++j) {
      const Vec3 p = c + 0.1 * ((j & 1 ? 1.0 : -1.0) * u + (j & 2 ? 1.0 : -1.0) * v);
      corner[std::size_t(j)] = m.mesh.add_vertex(TriMesh::Point(p.x(), p.y(), p.z()));
      m.mesh.set_normal(corner[std::size_t(j)], TriMesh::Normal(n.x(), n.y(), n.z()));
    }
    add_triangle(m.mesh, corner[0], corner[1], corner[3], unused);
    add_triangle(m.mesh, corner[0], corner[3], corner[2], unused);
  }
  m.mesh.update_face_normals();
  Mesh larger = m;
  auto made = generate_lightmap_uvs(m, side_target(16));
  ASSERT_FALSE(made);
  EXPECT_NE(made.error().message.find("do not fit a 16² lightmap"), std::string::npos)
      << made.error().message;
  // A 32² side holds them at a density above 0.
  auto fits = generate_lightmap_uvs(larger, side_target(32));
  ASSERT_TRUE(fits) << fits.error().message;
  EXPECT_GT(fits->texels_per_metre, 0);
}

// A bake of scenes/seams with uv = "auto" on every receiver: generated, reported so, no UV
// warning, and stitching still finds and closes the seams between its charts.
TEST(AutoUv, BakeOfTheSeamsSceneWithGeneratedUvs) {
  auto loaded = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/seams/scene.toml");
  ASSERT_TRUE(loaded) << loaded.error().message;
  Scene scene = *loaded;
  scene.bake.method = "backprojection";
  scene.bake.resolution = 128;
  for (ObjectDesc& obj : scene.objects) obj.auto_uv = true;
  auto baked = bake(scene, {});
  ASSERT_TRUE(baked) << baked.error().message;
  EXPECT_TRUE(baked->warnings.empty()) << baked->warnings.front();
  for (const ReceiverBake& r : baked->receivers) {
    SCOPED_TRACE(r.name);
    EXPECT_TRUE(r.uv_layout.generated);
    EXPECT_EQ(r.uv_channel, 1);
    EXPECT_GT(r.covered_texels, 0.3 * 128 * 128);
    if (r.name == "cylinder") {
      EXPECT_GT(r.seams.edges, 0);
      EXPECT_LT(r.seams.after.largest, 1.0 / 255);
    }
  }
}

}  // namespace
}  // namespace sb
