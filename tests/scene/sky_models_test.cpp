// Analytic skies (scene/sky_models.h): Preetham's clear sky as Blender's Sky Texture renders it
// (tests/tools/blender_preetham_sky.py made the files under tests/scene/data), read from a scene
// file around its sun, and baked through a sky light as the sky's own integral says.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "core/image_io.h"
#include "pipeline/bake.h"
#include "scene/lights.h"
#include "scene/scene.h"
#include "scene/sky.h"
#include "scene/sky_models.h"

namespace sb {
namespace {

constexpr double pi = std::numbers::pi;

// The sun blender_preetham_sky.py puts in its skies: 38° up, 215° from +X towards +Y.
Vec3 blender_sun() {
  const double e = 38 * pi / 180, a = 215 * pi / 180;
  return {std::cos(a) * std::cos(e), std::sin(a) * std::cos(e), std::sin(e)};
}

double luminance(const Vec3& c) { return 0.2126 * c.x() + 0.7152 * c.y() + 0.0722 * c.z(); }

// Blender's render of its own Preetham sky, pixel by pixel, above the horizon and below it (the
// horizon's radiance): within 1 % of the pixel's luminance everywhere (the worst, 0.7 %, next to
// the sun, where Cycles' samples wander inside the pixel over a steep glow), and within 0.01 % on
// the mean, where a wrong coefficient, scale or colour matrix would show.
TEST(Sky, PreethamMatchesBlendersSkyTexture) {
  for (const double turbidity : {2.2, 6.0}) {
    const auto file = std::filesystem::path(SB_SOURCE_DIR) / "tests/scene/data" /
                      fmt::format("preetham_t{:g}.exr", turbidity);
    auto blender = read_image(file);
    ASSERT_TRUE(blender) << blender.error().message;
    double worst = 0, sum = 0;
    for (int y = 0; y < blender->height; ++y)
      for (int x = 0; x < blender->width; ++x) {
        const Vec3 d =
            equirectangular_direction((x + 0.5) / blender->width, 1 - (y + 0.5) / blender->height);
        const Vec3 mine = preetham_radiance(blender_sun(), turbidity, d);
        const float* p = blender->at(x, y);
        const Vec3 theirs(p[0], p[1], p[2]);
        for (int c = 0; c < 3; ++c) {
          const double error = std::abs(mine[c] - theirs[c]) / luminance(theirs);
          worst = std::max(worst, error);
          sum += error;
        }
      }
    EXPECT_LT(worst, 0.01) << "turbidity " << turbidity;
    EXPECT_LT(sum / (3.0 * blender->width * blender->height), 1e-4) << "turbidity " << turbidity;
  }
}

// ∫ L cos θ dω over the upper hemisphere of a Z-up sky, by a fine midpoint rule in (θ, φ) on the
// model itself, not through a map.
Vec3 hemisphere_irradiance(const Vec3& sun, double turbidity) {
  const int rows = 400, columns = 800;
  Vec3 sum = Vec3::Zero();
  for (int i = 0; i < rows; ++i) {
    const double theta = (i + 0.5) / rows * pi / 2;
    for (int j = 0; j < columns; ++j) {
      const double phi = (j + 0.5) / columns * 2 * pi;
      const Vec3 d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                   std::cos(theta));
      sum += preetham_radiance(sun, turbidity, d) * std::cos(theta) * std::sin(theta);
    }
  }
  return sum * (pi / 2 / rows) * (2 * pi / columns);
}

// An open floor under a Preetham sky alone, irradiance: the reference's rays over its map give
// the sky's own cosine-weighted integral within 0.5 % (0.1 % here), its 128 parts
// (backprojection) within 2 % (1.4 % in red here, the glow's colour spread over wide patches;
// 0.4 % at 320 parts, 0.2 % at 1024).
TEST(Sky, APreethamSkyBakesToItsIntegral) {
  auto loaded = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/plane/scene.toml");
  ASSERT_TRUE(loaded) << loaded.error().message;
  Scene scene = *loaded;
  LightDesc sky;
  sky.name = "sky";
  sky.shape = LightShape::sky;
  sky.up = Vec3::UnitZ();
  sky.sky_strength = 2;
  sky.sky_turbidity = 3;
  sky.sky_sun_direction = -Vec3(0.3, -0.5, 0.6).normalized();
  scene.lights = {sky};
  scene.bake.resolution = 8;
  scene.bake.margin = 0;
  scene.bake.quantity = Quantity::irradiance;
  const Vec3 truth = 2 * hemisphere_irradiance(-sky.sky_sun_direction, 3);
  for (const std::string method : {"backprojection", "reference"}) {
    scene.bake.method = method;
    scene.bake.samples = 4096;
    auto result = bake(scene);
    ASSERT_TRUE(result) << result.error().message;
    const float* centre = result->receivers[0].image.at(4, 4);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(centre[c] / truth[c], 1, method == "reference" ? 0.005 : 0.02)
          << method << " channel " << c;
  }
}

// The scene file: model = "preetham" around the scene's one sun, the sun it names or the
// direction it gives; what does not fit is refused at the sky's line.
TEST(Sky, SceneFileReadsAPreethamSkyAroundItsSun) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("shadowbake_preetham_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "m.obj").flush();
  const std::string object = "[[object]]\nname = \"floor\"\nmesh = \"m.obj\"\n";
  const std::string sun =
      "[[light]]\nname = \"noon\"\nshape = \"sun\"\n"
      "direction = [1, 0, -1]\nirradiance = 800\n";
  const auto write = [&](const std::string& lights, const std::string& sky) {
    std::ofstream(dir / "scene.toml")
        << object << lights << "[[light]]\nname = \"sky\"\nshape = \"sky\"\n"
        << sky;
    return load_scene(dir / "scene.toml");
  };
  auto around_sun = write(sun, "model = \"preetham\"\n");
  ASSERT_TRUE(around_sun) << around_sun.error().message;
  const LightDesc& sky = around_sun->lights[1];
  EXPECT_EQ(sky.sky_turbidity, kDefaultTurbidity);
  EXPECT_TRUE(sky.sky_sun_direction.isApprox(Vec3(1, 0, -1).normalized(), 1e-12));
  auto named = write(sun +
                         "[[light]]\nname = \"evening\"\nshape = \"sun\"\n"
                         "direction = [0, 1, -0.2]\nirradiance = 100\n",
                     "model = \"preetham\"\nsun = \"evening\"\nturbidity = 5\n");
  ASSERT_TRUE(named) << named.error().message;
  EXPECT_EQ(named->lights[2].sky_turbidity, 5);
  EXPECT_TRUE(named->lights[2].sky_sun_direction.isApprox(Vec3(0, 1, -0.2).normalized(), 1e-12));
  auto given = write("", "model = \"preetham\"\nsun_direction = [0, 0, -2]\n");
  ASSERT_TRUE(given) << given.error().message;
  EXPECT_EQ(given->lights[0].sky_sun_direction, Vec3(0, 0, -1));
  // Made into its parts, the sky is brightest towards its sun.
  auto lights = make_lights(around_sun->lights, dir / "scene.toml");
  ASSERT_TRUE(lights) << lights.error().message;
  EXPECT_NE(lights->back().sky(), nullptr);
  const auto& made = *lights->back().sky();
  EXPECT_GT(made.radiance(Vec3(-1, 0, 1.1).normalized()).x(),
            2 * made.radiance(Vec3(1, 0, 1.1).normalized()).x());

  const std::vector<std::pair<std::string, std::string>> refused = {
      {"model = \"cloudy\"\n", "'model' must be"},
      {"model = \"preetham\"\nturbidity = 1\n", "'turbidity' must be a number in [2, 10]"},
      {"model = \"preetham\"\nmap = \"m.obj\"\n", "'map' is a sky of its own"},
      {"model = \"preetham\"\nrotation_deg = 10\n", "'rotation_deg' turns a map"},
      {"turbidity = 3\n", "applies only to a sky of model = \"preetham\""},
      {"model = \"preetham\"\nsun = \"dusk\"\n", "no light of that name"},
      {"model = \"preetham\"\nsun = \"\"\n", "'sun' must be the name of a sun light"},
      {"model = \"preetham\"\nsun = \"noon\"\nsun_direction = [0, 0, -1]\n",
       "both place the sky's sun"},
      {"model = \"preetham\"\nsun_direction = [0, 0, 1]\n", "below the horizon"}};
  for (const auto& [text, problem] : refused) {
    auto bad = write(sun, text);
    ASSERT_FALSE(bad) << text;
    EXPECT_NE(bad.error().message.find("light 'sky'"), std::string::npos) << bad.error().message;
    EXPECT_NE(bad.error().message.find(problem), std::string::npos) << bad.error().message;
  }
  // No sun to follow: none in the scene, or two and none named.
  for (const std::string& lights :
       {std::string(), sun + "[[light]]\nname = \"b\"\nshape = \"sun\"\n"
                             "direction = [0, 1, -1]\nirradiance = 1\n"}) {
    auto bad = write(lights, "model = \"preetham\"\n");
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("needs its sun"), std::string::npos) << bad.error().message;
  }
  auto not_sun = write(
      "[[light]]\nname = \"lamp\"\nshape = \"sphere\"\nposition = [0, 0, 3]\nradius = 0.1\npower = "
      "10\n",
      "model = \"preetham\"\nsun = \"lamp\"\n");
  ASSERT_FALSE(not_sun);
  EXPECT_NE(not_sun.error().message.find("a sphere light, not a sun"), std::string::npos)
      << not_sun.error().message;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sb
