// Visibility across a smooth-shaded sphere's terminator (methods/terminator_fill.h), in every
// method: a texel whose centre lies past the terminator but part of whose square, as Blender
// bakes a texel (the middle half of its sides, within its triangle), faces the sun takes its lit
// neighbours' visibility; one whose square faces away wholly stays 0. Checked against the
// texels' squares sampled here, 12 × 12 points each, from the mesh's own UVs and vertex normals.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "methods/method.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "scene/sun_light.h"
#include "support/method_bakes.h"
#include "texels/texel_space.h"

namespace sb {
namespace {

namespace fs = std::filesystem;

// A UV sphere of 16 × 8 segments, radius 0.5 m at (0, 0, 0.5): coarse, as a game asset is, with
// unit radial vertex normals and longitude–latitude lightmap UVs (a seam at u = 0 and 1).
std::string sphere_obj() {
  std::ostringstream v, vt, vn, f;
  const int nu = 16, nv = 8;
  for (int j = 0; j <= nv; ++j) {
    for (int i = 0; i <= nu; ++i) {
      const double phi = 2 * std::numbers::pi * i / nu, theta = std::numbers::pi * j / nv;
      const double x = std::sin(theta) * std::cos(phi), y = std::sin(theta) * std::sin(phi),
                   z = std::cos(theta);
      v << "v " << 0.5 * x << " " << 0.5 * y << " " << 0.5 + 0.5 * z << "\n";
      vn << "vn " << x << " " << y << " " << z << "\n";
      vt << "vt " << 0.02 + 0.96 * i / nu << " " << 0.98 - 0.96 * j / nv << "\n";
    }
  }
  const auto at = [&](int i, int j) { return std::to_string(j * (nu + 1) + i + 1); };
  const auto corner = [&](int i, int j) { return at(i, j) + "/" + at(i, j) + "/" + at(i, j); };
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      // Outward: (i, j) → (i, j + 1) → (i + 1, j + 1) turns counter-clockwise seen from outside.
      if (j > 0)
        f << "f " << corner(i, j) << " " << corner(i, j + 1) << " " << corner(i + 1, j) << "\n";
      if (j < nv - 1)
        f << "f " << corner(i + 1, j) << " " << corner(i, j + 1) << " " << corner(i + 1, j + 1)
          << "\n";
    }
  }
  return v.str() + vt.str() + vn.str() + f.str();
}

class TerminatorFill : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("shadowbake_terminator_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    std::ofstream(dir_ / "sphere.obj") << sphere_obj();
    std::ofstream(dir_ / "scene.toml") << R"([bake]
resolution = 96
margin = 0
seams = false

[[object]]
name = "sphere"
mesh = "sphere.obj"
uv = 0

[[light]]
name = "sun"
shape = "sun"
direction = [-0.35, 0.45, -0.82]
irradiance = 1000
)";
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(TerminatorFill, ATexelTheSunReachesInPartIsLitInEveryMethod) {
  auto scene = load_scene(dir_ / "scene.toml");
  ASSERT_TRUE(scene) << scene.error().message;
  auto mesh = import_mesh(scene->objects[0], dir_ / "scene.toml");
  ASSERT_TRUE(mesh) << mesh.error().message;
  const int side = scene->bake.resolution;
  const TexelSpace space = rasterise_texels(*mesh, side, side);
  LightDesc desc = scene->lights[0];
  Bounds3 bounds;
  for (const auto v : mesh->mesh.vertices()) {
    const auto& q = mesh->mesh.point(v);
    bounds.extend(Vec3(q[0], q[1], q[2]));
  }
  place_sun(desc, bounds);
  const Light sun(desc);
  // Per texel: whether its centre, and whether some point of its square within its triangle,
  // faces the sun (12 × 12 points over the middle half of its sides; and, to leave out texels
  // lit only at the square's very edge, whether some point of a square of 0.6 of its sides does).
  std::vector<int> centre_lit(space.texels.size()), square_lit(space.texels.size()),
      near_lit(space.texels.size());
  int band = 0;
  for (std::size_t t = 0; t < space.texels.size(); ++t) {
    const Texel& texel = space.texels[t];
    const Triangle tri = triangle(mesh->mesh, mesh->mesh.face_handle(texel.face));
    Vec2 c[3];
    for (int i = 0; i < 3; ++i) c[i] = Vec2(tri.uv[i].x() * side, (1 - tri.uv[i].y()) * side);
    const double area =
        (c[1] - c[0]).x() * (c[2] - c[0]).y() - (c[1] - c[0]).y() * (c[2] - c[0]).x();
    const auto lit_at = [&](const Vec2& q) {
      double w[3];
      for (int i = 0; i < 3; ++i) {
        const Vec2 a = c[(i + 1) % 3] - q, b = c[(i + 2) % 3] - q;
        w[i] = (a.x() * b.y() - a.y() * b.x()) / area;
      }
      if (w[0] < 0 || w[1] < 0 || w[2] < 0) return false;
      const Vec3 n = (w[0] * tri.n[0] + w[1] * tri.n[1] + w[2] * tri.n[2]).normalized();
      return sun.unoccluded_irradiance(texel.position.cast<double>(), n).sum() > 0;
    };
    const Vec2 centre(texel.x + 0.5, texel.y + 0.5);
    centre_lit[t] =
        sun.unoccluded_irradiance(texel.position.cast<double>(), texel.normal.cast<double>())
            .sum() > 0;
    for (int i = 0; i < 12; ++i)
      for (int j = 0; j < 12; ++j) {
        const Vec2 offset((i + 0.5) / 12 - 0.5, (j + 0.5) / 12 - 0.5);
        square_lit[t] = square_lit[t] || lit_at(centre + 0.5 * offset);
        near_lit[t] = near_lit[t] || lit_at(centre + 0.6 * offset);
      }
    // A texel whose centre falls off its triangle (its position the triangle's nearest point) has
    // its centre's value.
    square_lit[t] = square_lit[t] || centre_lit[t];
    near_lit[t] = near_lit[t] || centre_lit[t];
    band += square_lit[t] && !centre_lit[t];
  }
  EXPECT_GT(band, 20) << "the terminator's texels whose centres face away";

  for (const MethodEntry& entry : method_registry()) {
    const std::string& method = entry.name;
    if (method == "ambient-occlusion") continue;  // no light takes part
    const BakeResult result = bake_with(*scene, method, 64, false);
    ASSERT_EQ(result.receivers.size(), 1u);
    const Image& image = result.receivers[0].image;
    int filled = 0;
    for (std::size_t t = 0; t < space.texels.size(); ++t) {
      const Texel& texel = space.texels[t];
      const float v = image.at(texel.x, texel.y)[0];
      if (square_lit[t]) {
        EXPECT_GT(v, 0.99) << method << " texel (" << texel.x << ", " << texel.y << ")";
        filled += !centre_lit[t];
      } else if (!near_lit[t]) {
        EXPECT_EQ(v, 0.0f) << method << " texel (" << texel.x << ", " << texel.y << ")";
      }
    }
    EXPECT_EQ(filled, band) << method;
  }
}

}  // namespace
}  // namespace sb
