// Tests of UV seam stitching (src/texels/seams.cpp): which edges are seams, the solve on a
// two-chart image against lookups the test makes itself, and the bake of scenes/seams (a smooth
// cylinder and bevelled boxes made in Blender) with seams stitched and not.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "pipeline/bake.h"
#include "scene/mesh.h"
#include "texels/seams.h"
#include "texels/texel_space.h"

namespace sb {
namespace {

// A bilinear lookup at (u, v) as an engine does it, clamped to the edge: texel centres at
// ((x + 0.5) / w, 1 − (y + 0.5) / h). The test's own, not the stitcher's.
double lookup(const Image& image, const Vec2& uv, int channel) {
  const double px = uv.x() * image.width - 0.5, py = (1 - uv.y()) * image.height - 0.5;
  const double fx = std::floor(px), fy = std::floor(py);
  double sum = 0;
  for (int dy = 0; dy < 2; ++dy)
    for (int dx = 0; dx < 2; ++dx) {
      const int x = std::clamp(int(fx) + dx, 0, image.width - 1);
      const int y = std::clamp(int(fy) + dy, 0, image.height - 1);
      const double w = (dx ? px - fx : 1 - (px - fx)) * (dy ? py - fy : 1 - (py - fy));
      sum += w * image.at(x, y)[channel];
    }
  return sum;
}

// The largest lookup difference across `seams`, at 8 points per texel of each edge's length,
// none of them where the stitcher samples (its ends and the crossings of texel rows).
double largest_seam_difference(const Image& image, const std::vector<SeamEdge>& seams) {
  double largest = 0;
  for (const SeamEdge& s : seams) {
    const double texels = std::max((s.a[1] - s.a[0]).norm(), (s.b[1] - s.b[0]).norm()) *
                          double(std::max(image.width, image.height));
    const int n = std::max(2, int(std::ceil(8 * texels)));
    for (int k = 0; k < n; ++k) {
      const double t = (k + 0.37) / n;
      const Vec2 a = s.a[0] + t * (s.a[1] - s.a[0]), b = s.b[0] + t * (s.b[1] - s.b[0]);
      for (int c = 0; c < image.channels; ++c)
        largest = std::max(largest, std::abs(lookup(image, a, c) - lookup(image, b, c)));
    }
  }
  return largest;
}

// The mesh's seams found the test's own way (the definition in seams.h, not find_seams' code):
// every pair of triangles with an edge whose end points are the same in space (compared as
// rounded coordinates, not bits) but whose UVs differ there, with vertex normals within 0.5° at
// both ends; edges of more than two triangles left out.
std::vector<SeamEdge> seams_by_definition(const Mesh& mesh) {
  struct Side {
    Vec2 uv[2];
    Vec3 n[2];
  };
  const auto key = [](const Vec3& p) {
    return std::array<long long, 3>{std::llround(p.x() * 1e6), std::llround(p.y() * 1e6),
                                    std::llround(p.z() * 1e6)};
  };
  using PointKey = std::array<long long, 3>;
  std::map<std::pair<PointKey, PointKey>, std::vector<Side>> edges;
  for (const auto f : mesh.mesh.faces()) {
    const Triangle t = triangle(mesh.mesh, f);
    for (int e = 0; e < 3; ++e) {
      int i = e, j = (e + 1) % 3;
      if (key(t.p[j]) < key(t.p[i])) std::swap(i, j);  // the edge's ends in one order
      edges[{key(t.p[i]), key(t.p[j])}].push_back({{t.uv[i], t.uv[j]}, {t.n[i], t.n[j]}});
    }
  }
  const double smooth = std::cos(kSmoothEdgeDegrees * std::numbers::pi / 180);
  std::vector<SeamEdge> seams;
  for (const auto& [ends, sides] : edges) {
    if (sides.size() != 2) continue;
    const Side &a = sides[0], &b = sides[1];
    if ((a.uv[0] - b.uv[0]).norm() < 1e-12 && (a.uv[1] - b.uv[1]).norm() < 1e-12) continue;
    if (a.n[0].normalized().dot(b.n[0].normalized()) < smooth ||
        a.n[1].normalized().dot(b.n[1].normalized()) < smooth)
      continue;
    seams.push_back({{a.uv[0], a.uv[1]}, {b.uv[0], b.uv[1]}});
  }
  return seams;
}

// Two flat quads side by side in space (x in [0, 1] and [1, 2], z = 0), sharing the edge x = 1,
// each its own chart in UV; `crease`: the second quad's normals tilted, a hard edge.
Mesh two_charts(bool crease) {
  Mesh m;
  m.has_uv = true;
  auto add = [&](double x, double y, double u, double v, const Vec3& n) {
    const auto h = m.mesh.add_vertex(TriMesh::Point(x, y, 0));
    m.mesh.set_texcoord2D(h, TriMesh::TexCoord2D(u, v));
    m.mesh.set_normal(h, TriMesh::Normal(n.x(), n.y(), n.z()));
    return h;
  };
  const Vec3 up(0, 0, 1), tilted = Vec3(0.2, 0, 1).normalized();
  const double u1 = 0.5;  // the second chart's offset in u
  const auto a0 = add(0, 0, 0.05, 0.1, up), a1 = add(1, 0, 0.45, 0.1, up);
  const auto a2 = add(1, 1, 0.45, 0.9, up), a3 = add(0, 1, 0.05, 0.9, up);
  const auto b0 = add(1, 0, 0.05 + u1, 0.1, crease ? tilted : up);
  const auto b1 = add(2, 0, 0.45 + u1, 0.1, crease ? tilted : up);
  const auto b2 = add(2, 1, 0.45 + u1, 0.9, crease ? tilted : up);
  const auto b3 = add(1, 1, 0.05 + u1, 0.9, crease ? tilted : up);
  m.mesh.add_face(a0, a1, a2);
  m.mesh.add_face(a0, a2, a3);
  m.mesh.add_face(b0, b1, b2);
  m.mesh.add_face(b0, b2, b3);
  return m;
}

TEST(Seams, FoundWhereTheSurfaceIsSmoothAndTheUvsPart) {
  const std::vector<SeamEdge> seams = find_seams(two_charts(false));
  ASSERT_EQ(seams.size(), 1u);
  // Side a's ends and side b's are the same points: the shared edge's ends at y = 0 and y = 1.
  for (int k = 0; k < 2; ++k) {
    EXPECT_DOUBLE_EQ(seams[0].a[k].y(), seams[0].b[k].y());
    EXPECT_NEAR(std::abs(seams[0].a[k].x() - seams[0].b[k].x()), 0.1, 1e-12);  // 0.45, 0.55
  }
  EXPECT_TRUE(find_seams(two_charts(true)).empty()) << "a hard edge is not a seam";
}

// Chart a (x in [8, 24)) holds 0.2 + 0.01 y, chart b (x in [40, 56)) 0.5 + 0.01 y: a seam from
// a's right border to b's left border whose sides differ by 0.3 before stitching.
// Two charts of a 64² lightmap, x in [8, 24) and [40, 56), rows 8 to 40, their values 0.3 apart
// and dilated by 4 texels, and the seam between their inner borders.
struct TwoCharts {
  static constexpr int side = 64;
  Image image{side, side, 1, 0.0f};
  std::vector<std::uint8_t> covered = std::vector<std::uint8_t>(std::size_t(side * side), 0);
  std::vector<SeamEdge> seams;
  TwoCharts() {
    for (int y = 8; y < 40; ++y)
      for (int x = 8; x < 56; ++x) {
        if (x >= 24 && x < 40) continue;
        covered[std::size_t(y * side + x)] = 1;
        image.at(x, y)[0] = float((x < 24 ? 0.2 : 0.5) + 0.01 * y);
      }
    dilate(image, covered, 4);
    const double top = 1 - 8.0 / side, bottom = 1 - 40.0 / side;
    seams = {{{Vec2(24.0 / side, top), Vec2(24.0 / side, bottom)},
              {Vec2(40.0 / side, top), Vec2(40.0 / side, bottom)}}};
  }
};

TEST(Seams, StitchingMakesBothSidesLookUpTheSame) {
  TwoCharts charts;
  const int side = TwoCharts::side;
  Image& image = charts.image;
  const std::vector<std::uint8_t>& covered = charts.covered;
  const Image baked = image;
  const std::vector<SeamEdge>& seams = charts.seams;
  ASSERT_GT(largest_seam_difference(image, seams), 0.1);

  const SeamReport report = stitch_seams(seams, covered, {{&image, {}}}, 1.0);
  EXPECT_EQ(report.edges, 1);
  EXPECT_GT(report.before.largest, 0.1);
  EXPECT_GT(report.before.visible, 0.9);
  EXPECT_LT(report.after.largest, 1e-4);
  EXPECT_EQ(report.after.visible, 0.0);
  EXPECT_LT(largest_seam_difference(image, seams), 1e-4) << "between the stitcher's samples too";
  // Nothing leaves the range of what was baked (0.2 + 0.01 · 8 to 0.5 + 0.01 · 39 along the
  // seam's rows), and texels no lookup reads are as baked, bit for bit.
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const float v = image.at(x, y)[0], v0 = baked.at(x, y)[0];
      if (y >= 8 && y < 40 && ((x > 20 && x < 27) || (x > 36 && x < 44))) {
        EXPECT_GE(v, 0.28f - 1e-6f);
        EXPECT_LE(v, 0.89f + 1e-6f);
      }
      if (x < 21 || (x > 26 && x < 38) || x > 42) {
        EXPECT_EQ(v, v0) << x << ", " << y;
      }
    }
}

// The conjugate gradients (what the bake uses where the factor would fill in) reach the
// factorisation's answer on the same two charts.
TEST(Seams, IterativeSolveAgreesWithTheFactorisation) {
  TwoCharts charts;
  Image& image = charts.image;
  const std::vector<std::uint8_t>& covered = charts.covered;
  const std::vector<SeamEdge>& seams = charts.seams;
  Image factorised = image, iterative = image;
  stitch_seams(seams, covered, {{&factorised, {}}}, 1.0, true, SeamSolver::factorised);
  const SeamReport report =
      stitch_seams(seams, covered, {{&iterative, {}}}, 1.0, true, SeamSolver::iterative);
  EXPECT_LT(report.after.largest, 1e-4);
  float largest = 0;
  for (std::size_t i = 0; i < image.pixels.size(); ++i)
    largest = std::max(largest, std::abs(factorised.pixels[i] - iterative.pixels[i]));
  EXPECT_LT(largest, 1e-5);
  EXPECT_GT(largest_seam_difference(image, seams), 0.1);  // there was something to stitch
}

TEST(Seams, MeasuredOnlyWhenNotSolved) {
  const int side = 32;
  Image image(side, side, 1, 0.0f);
  std::vector<std::uint8_t> covered(std::size_t(side * side), 1);
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) image.at(x, y)[0] = x < 16 ? 0.0f : 1.0f;
  const Image baked = image;
  const std::vector<SeamEdge> seams = {
      {{Vec2(0.25, 0.75), Vec2(0.25, 0.25)}, {Vec2(0.75, 0.75), Vec2(0.75, 0.25)}}};
  const SeamReport report = stitch_seams(seams, covered, {{&image, {}}}, 1.0, false);
  EXPECT_NEAR(report.before.largest, 1.0, 1e-12);
  EXPECT_EQ(report.after.largest, report.before.largest);
  EXPECT_EQ(report.texels, 0);
  EXPECT_EQ(image.pixels, baked.pixels);
}

// scenes/seams at 256²: the cylinder's side and the bevelled box (Smart UV Project charts), lit
// across their seams. Stitched, the largest lookup difference along every seam is under 1/255:
// of the receiver's largest value in irradiance (measured by the test's own lookups), and in
// visibility where the light reaches (the bake's own measure, which leaves out the texels no
// light reaches, whose V means nothing).
TEST(Seams, BakedCylinderAndBevelledBoxAgreeAcrossTheirSeams) {
  auto loaded = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/seams/scene.toml");
  ASSERT_TRUE(loaded) << loaded.error().message;
  Scene scene = *loaded;
  scene.bake.resolution = 256;
  scene.bake.method = "backprojection";
  for (const Quantity quantity : {Quantity::irradiance, Quantity::visibility}) {
    scene.bake.quantity = quantity;
    for (const bool stitched : {false, true}) {
      scene.bake.seams = stitched;
      auto result = bake(scene);
      ASSERT_TRUE(result) << result.error().message;
      for (const ReceiverBake& r : result->receivers) {
        if (r.name != "cylinder" && r.name != "box") continue;
        SCOPED_TRACE(r.name + (stitched ? " stitched" : " as baked") +
                     (quantity == Quantity::irradiance ? ", irradiance" : ", visibility"));
        const ObjectDesc& obj = scene.objects[r.object];
        auto mesh = import_mesh(obj, scene.file);
        ASSERT_TRUE(mesh) << mesh.error().message;
        // Seams and lookups by the test's own code: the stitcher's count agrees, and its result
        // is judged along the edges found independently.
        const std::vector<SeamEdge> seams = seams_by_definition(*mesh);
        EXPECT_EQ(std::int64_t(seams.size()), r.seams.edges);
        EXPECT_EQ(find_seams(*mesh).size(), seams.size());
        EXPECT_GE(r.seams.edges, 4);
        if (quantity == Quantity::irradiance) {
          const double scale = *std::max_element(r.image.pixels.begin(), r.image.pixels.end());
          const double difference = largest_seam_difference(r.image, seams) / scale;
          if (stitched) {
            EXPECT_LT(difference, 1.0 / 255);
          } else {
            EXPECT_GT(difference, 2.0 / 255) << "the seams show before stitching";
          }
        } else if (stitched) {
          EXPECT_LT(r.seams.after.largest, 1.0 / 255);
        } else {
          EXPECT_EQ(r.seams.after.largest, r.seams.before.largest);
        }
      }
    }
  }
}

}  // namespace
}  // namespace sb
