// The `backprojection` method through the whole pipeline: the exact parallel case against its
// closed form; the same bytes for any thread count and from run to run; routes counted; and
// against the reference on the configurations the method must get right (a light flush with a
// ceiling, a receiver shadowing itself, a blocker across the light's plane, lights of every
// shape).
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

#include "methods/backprojection/backprojection_bake.h"
#include "pipeline/bake.h"
#include "support/built_scene.h"
#include "support/closed_forms.h"
#include "support/image_errors.h"
#include "support/test_scenes.h"
#include "texels/texel_space.h"

namespace sb {
namespace {

Scene scene_of(const std::string& name, int resolution, const std::string& file = "scene.toml") {
  auto scene = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/" + name + "/" + file);
  EXPECT_TRUE(scene) << scene.error().message;
  if (!scene) throw std::runtime_error(scene.error().message);
  scene->bake.resolution = resolution;
  scene->bake.method = "backprojection";
  scene->bake.margin = 0;
  return *scene;
}

double stat(const ReceiverBake& r, const std::string& name) {
  for (const auto& [key, value] : r.report.stats)
    if (key == name) return value;
  ADD_FAILURE() << "no " << name;
  return 0;
}

// Three parallel planes (docs/design.md §2): the closed form is exact (the light's weight less
// its hidden part's, square_light_weighted_visibility), and so is the estimator but for its
// rows; interpolation may add to that only where it checked.
TEST(BackprojectionBake, ExactParallelCaseIsWithinAThousandthOfTheClosedForm) {
  const Scene scene = scene_of("parallel", 512);
  auto result = bake(scene);
  ASSERT_TRUE(result) << result.error().message;
  const Image& img = result->receivers[0].image;
  const image_errors::Errors e = image_errors::errors_against(img, 0, [&](int x, int y) {
    const double u = (x + 0.5) / img.width, v = 1.0 - (y + 0.5) / img.height;
    return closed_forms::square_light_weighted_visibility(2 * u - 1, 2 * v - 1, 0, 0, 0.5);
  });
  std::printf("parallel planes at 512²: RMSE %.5f, max %.4f; interpolated %.3f of pairs\n", e.rmse,
              e.max, stat(result->receivers[0], "interpolated_fraction"));
  EXPECT_LT(e.rmse, 0.001);
  EXPECT_LT(e.max, 0.02);
  EXPECT_GT(stat(result->receivers[0], "interpolated_fraction"), 0.05);
}

// Parallel configurations the project has not tuned to: the light's size (0.2–1.8 m) and height
// (0.5–3 m), the blocker's size (0.04–1.2 m), height (5–95 % of the light's) and place, and the
// resolution (256², 512²) drawn at random, each bake's image against the closed form.
void expect_random_parallel_configurations(unsigned seed, int draws) {
  std::mt19937 draw(seed);
  const auto uniform = [&](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(draw);
  };
  double worst_rmse = 0, worst_max = 0;
  for (int k = 0; k < draws; ++k) {
    Scene scene = scene_of("parallel", k % 2 == 0 ? 512 : 256);
    const double light = uniform(0.1, 0.9), light_height = uniform(0.5, 3.0);
    const double h = light_height * uniform(0.05, 0.95), half = uniform(0.02, 0.6);
    const double bx = uniform(-0.3, 0.3), by = uniform(-0.3, 0.3);
    scene.lights[0].position = Vec3(0, 0, light_height);
    scene.lights[0].width = scene.lights[0].height = 2 * light;
    // blocker.obj: the square of half-width 0.3 at z = 0.5, scaled, then moved.
    ObjectDesc& blocker = test_scenes::object(scene, "blocker");
    const double scale = half / 0.3;
    blocker.transform = Affine3::Identity();
    blocker.transform.translate(Vec3(bx, by, h - 0.5 * scale));
    blocker.transform.scale(scale);
    auto result = bake(scene);
    ASSERT_TRUE(result) << result.error().message;
    const Image& img = result->receivers[0].image;
    const image_errors::Errors e = image_errors::errors_against(img, 0, [&](int x, int y) {
      const double u = (x + 0.5) / img.width, v = 1.0 - (y + 0.5) / img.height;
      return closed_forms::parallel_square_visibility(2 * u - 1, 2 * v - 1, light, light_height, bx,
                                                      by, half, h);
    });
    std::printf(
        "light %.2f at %.2f, blocker %.2f at %.2f (%.2f, %.2f), %d²: RMSE %.5f, max %.4f; "
        "interpolated %.3f\n",
        2 * light, light_height, 2 * half, h, bx, by, img.width, e.rmse, e.max,
        stat(result->receivers[0], "interpolated_fraction"));
    EXPECT_LT(e.rmse, 0.001) << k;
    EXPECT_LT(e.max, 0.01) << k;
    worst_rmse = std::max(worst_rmse, e.rmse);
    worst_max = std::max(worst_max, e.max);
  }
  std::printf("%d draws: worst RMSE %.5f, worst max %.4f\n", draws, worst_rmse, worst_max);
}

// Forty draws (a fixed seed) within RMSE 0.001 and max 0.01.
TEST(BackprojectionBake, RandomParallelConfigurationsAreWithinTheClosedForm) {
  expect_random_parallel_configurations(20261206, 40);
}

// Two hundred more (another seed), by label: `ctest -L stress` (docs/testing.md).
TEST(BackprojectionBake, RandomParallelConfigurationsStress) {
  expect_random_parallel_configurations(20261207, 200);
}

// midpoint_cells, the method's own [bake] key: read from a scene file and checked there; 0
// turns check 5 off, which on a configuration where it matters (a low wide blocker under a wide
// light) leaves more of the pairs interpolated and the worst texel further from the closed form.
TEST(BackprojectionBake, MidpointCellsIsReadAndHonoured) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("sb_midpoint_cells_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string parallel = std::string(SB_SOURCE_DIR) + "/scenes/parallel/";
  const auto write = [&](const std::string& value) {
    std::ofstream(dir / "scene.toml")
        << "[bake]\nresolution = 256\nmargin = 0\nmidpoint_cells = " << value << "\n"
        << "[[object]]\nname = \"floor\"\nmesh = \"" << parallel << "floor.obj\"\n"
        << "[[object]]\nname = \"blocker\"\nmesh = \"" << parallel
        << "blocker.obj\"\nreceiver = false\nscale = [1.166667, 1.166667, 1]\n"
        << "translate = [0, 0, -0.32]\n"
        << "[[light]]\nname = \"panel\"\nshape = \"rectangle\"\nposition = [0, 0, 1.32]\n"
        << "normal = [0, 0, -1]\nsize = [1.03, 1.03]\npower = 100.0\n";
    return load_scene(dir / "scene.toml");
  };
  auto refused = write("-1");
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("midpoint_cells"), std::string::npos)
      << refused.error().message;
  double interpolated[2], worst[2];
  for (int on = 0; on < 2; ++on) {
    auto scene = write(on ? "4" : "0");
    ASSERT_TRUE(scene) << scene.error().message;
    EXPECT_EQ(setting_number(scene->bake, "midpoint_cells"), on ? 4.0 : 0.0);
    auto result = bake(*scene);
    ASSERT_TRUE(result) << result.error().message;
    const Image& img = result->receivers[0].image;
    worst[on] = image_errors::errors_against(img, 0, [&](int x, int y) {
                  const double u = (x + 0.5) / img.width, v = 1.0 - (y + 0.5) / img.height;
                  return closed_forms::parallel_square_visibility(2 * u - 1, 2 * v - 1, 0.515, 1.32,
                                                                  0, 0, 0.35, 0.18);
                }).max;
    interpolated[on] = stat(result->receivers[0], "interpolated_fraction");
  }
  std::printf("midpoint_cells 0: interpolated %.4f, max %.4f; 4: %.4f, %.4f\n", interpolated[0],
              worst[0], interpolated[1], worst[1]);
  EXPECT_GT(interpolated[0], interpolated[1]);
  EXPECT_GE(worst[0], worst[1]);
  std::filesystem::remove_all(dir);
}

TEST(BackprojectionBake, SameBytesForAnyThreadCountAndRun) {
  Scene scene = scene_of("showcase", 96);
  BakeOptions one, two;
  one.threads = 1;
  two.threads = 2;
  auto a = bake(scene, one), b = bake(scene, two), c = bake(scene, two);
  ASSERT_TRUE(a && b && c);
  for (std::size_t r = 0; r < a->receivers.size(); ++r) {
    EXPECT_EQ(a->receivers[r].image.pixels, b->receivers[r].image.pixels) << r;
    EXPECT_EQ(b->receivers[r].image.pixels, c->receivers[r].image.pixels) << r;
  }
}

// A scene built as the bake builds it, with what the method reads, for tests that call
// bake_backprojection on one receiver's texel space.
struct Prepared : test_scenes::Built {
  BackprojectionInputs in;
  explicit Prepared(const Scene& scene) : Built(scene) {
    in.lights = &lights;
    in.culler = &*culler;
    in.rays = &*rays;
  }
};

// The tiles' shaft tests take a flat block's box from its summary (TexelBlock) without reading
// its texels: the same image and routes as from the texels, on the courtyard's ground under the
// sun (every block flat) and on the level's curved furniture beside flat floors.
TEST(BackprojectionBake, BlockSummariesGiveTheSameBakeAsTheTexels) {
  for (const auto& [name, file] : {std::pair<std::string, std::string>{"outdoor", "scene_sun.toml"},
                                   {"level", "scene.toml"}}) {
    const Scene scene = scene_of(name, 256, file);
    const Prepared p(scene);
    int uniform_blocks = 0;
    for (std::size_t i = 0; i < p.meshes.size(); ++i) {
      if (!scene.objects[i].receiver) continue;
      const TexelSpace space = rasterise_texels(p.meshes[i], 256, 256);
      TexelSpace without = rasterise_texels(p.meshes[i], 256, 256);
      for (const TexelBlock& b : space.blocks) uniform_blocks += b.uniform;
      without.blocks.clear();
      RouteCounts with_routes, without_routes;
      const MixedImages a = bake_backprojection(space, p.in, &with_routes);
      const MixedImages b = bake_backprojection(without, p.in, &without_routes);
      EXPECT_EQ(a.image.pixels, b.image.pixels) << name << " " << scene.objects[i].name;
      EXPECT_EQ(with_routes.pairs, without_routes.pairs) << name << " " << scene.objects[i].name;
    }
    EXPECT_GT(uniform_blocks, 100) << name;
  }
}

// The umbra route (texel_routes.h): on the courtyard's ground under the sun, the tiles it values
// 0 without an estimate are 0 in the reference too, every ray of every texel blocked.
TEST(BackprojectionBake, UmbraTilesAreDarkInTheReference) {
  Scene scene = scene_of("outdoor", 512, "scene_sun.toml");
  const Prepared p(scene);
  std::size_t ground = 0;
  while (!scene.objects[ground].receiver) ++ground;
  const TexelSpace space = rasterise_texels(p.meshes[ground], 512, 512);
  const LightField field = backprojection_light(space, p.in, 0);
  scene.bake.method = "reference";
  scene.bake.samples = 64;
  auto reference = bake(scene);
  ASSERT_TRUE(reference) << reference.error().message;
  const Image& truth = reference->receivers[0].image;
  int umbra = 0;
  for (const Texel& t : space.texels) {
    if (field.route_at(t.x, t.y) != TexelRoute::umbra) continue;
    ++umbra;
    EXPECT_EQ(field.visibility_at(t.x, t.y), 0.0f);
    EXPECT_EQ(truth.at(t.x, t.y)[0], 0.0f) << t.x << ", " << t.y;
  }
  std::printf("umbra route: %d of %zu texels\n", umbra, space.texels.size());
  EXPECT_GT(umbra, int(space.texels.size() / 100));
}

TEST(BackprojectionBake, CountsEveryPairByItsRoute) {
  const Scene scene = scene_of("showcase", 128);
  auto result = bake(scene);
  ASSERT_TRUE(result) << result.error().message;
  for (const ReceiverBake& r : result->receivers) {
    double sum = 0;
    for (const char* route : {"clear_fraction", "umbra_fraction", "exact_fraction",
                              "interpolated_fraction", "traced_fraction"})
      sum += stat(r, route);
    EXPECT_NEAR(sum, 1.0, 1e-9) << r.name;
    for (const auto& [key, value] : r.report.stats)
      EXPECT_NE(key, "convolved_fraction") << "a route the method never takes";
  }
  // The floor has shadows from every kind of route.
  const ReceiverBake& floor = result->receivers[0];
  EXPECT_GT(stat(floor, "clear_fraction"), 0.3);
  EXPECT_GT(stat(floor, "exact_fraction"), 0.0);
  EXPECT_GT(stat(floor, "interpolated_fraction"), 0.0);
}

// Against the reference at 1024 samples, pooled over receivers: within the error the reference
// itself has at 256 samples (and a little noise of the truth's own).
void expect_as_accurate_as_reference_256(Scene scene, const std::string& what) {
  Scene reference = scene;
  reference.bake.method = "reference";
  reference.bake.samples = 1024;
  reference.bake.seed = 4321;
  Scene ref256 = reference;
  ref256.bake.samples = 256;
  ref256.bake.seed = 0;
  auto truth = bake(reference), coarse = bake(ref256), ours = bake(scene);
  ASSERT_TRUE(truth && coarse && ours);
  const double e_ours = image_errors::errors(*ours, *truth).rmse;
  const double e_ref = image_errors::errors(*coarse, *truth).rmse;
  std::printf("%s: backprojection RMSE %.5f, reference-256 %.5f (against reference-1024)\n",
              what.c_str(), e_ours, e_ref);
  EXPECT_LE(e_ours, e_ref * 1.05 + 2e-4) << what;
}

TEST(BackprojectionBake, LightFlushWithACeilingAndCurvedReceivers) {
  // The atrium's panel, 1.5 cm under the ceiling slab (a blocker), over columns and benches.
  Scene scene = scene_of("atrium", 64);
  expect_as_accurate_as_reference_256(scene, "atrium (panel under the ceiling)");
}

TEST(BackprojectionBake, ReceiverShadowingItself) {
  expect_as_accurate_as_reference_256(scene_of("bracket", 96), "bracket");
}

TEST(BackprojectionBake, BlockerAcrossTheLightsPlaneAndADiskLight) {
  // The room's back wall rises past the window's plane; the disk variant of the same room.
  expect_as_accurate_as_reference_256(scene_of("room", 64), "room (wall past the light's plane)");
  expect_as_accurate_as_reference_256(scene_of("room", 64, "scene_disk.toml"), "room, disk light");
}

TEST(BackprojectionBake, SphereLightsLowAmongObjects) {
  expect_as_accurate_as_reference_256(scene_of("atrium", 64, "scene_bulb.toml"), "atrium, bulb");
}

}  // namespace
}  // namespace sb
