// The shadow-map baselines (shadow_map.cpp, shadow_map_bake.cpp): the depth image itself, the
// depth bias (no acne, attached contact shadows), the property that tells each filter apart
// (PCF's fixed width, PCSS's growing width, adaptive PCF's shortcut, Chun–Oh's colour), and each
// method's error against the ray-traced reference.
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <numbers>

#include "core/image_io.h"
#include "methods/shadow_map.h"
#include "pipeline/bake.h"
#include "support/closed_forms.h"
#include "support/image_errors.h"
#include "support/test_scenes.h"

namespace sb {
namespace {

using test_scenes::load;
using test_scenes::object;

Image bake_first(const Scene& scene, MethodStats* stats = nullptr) {
  auto result = bake(scene);
  EXPECT_TRUE(result) << result.error().message;
  if (stats) *stats = result->receivers[0].report.stats;
  return result->receivers[0].image;
}

double stat(const MethodStats& stats, const std::string& name) {
  for (const auto& [key, value] : stats)
    if (key == name) return value;
  ADD_FAILURE() << "no stat " << name;
  return 0;
}

using image_errors::Errors;

// Channel `c` of `a` against `b`, over every texel.
Errors image_errors(const Image& a, const Image& b, int c = 0) {
  return image_errors::errors(a, b, {}, {.channel = c});
}

// The shadow's right-hand edge along a row of a floor image (x = 2(i + 0.5)/width − 1): from the
// middle of the shadow outwards, the distance in metres between V crossing 0.1 and 0.9.
double edge_width(const Image& img, int row) {
  const double texel = 2.0 / img.width;
  auto v = [&](int i) { return double(img.at(i, row)[0]); };
  auto crossing = [&](double level) {
    for (int i = img.width / 2; i + 1 < img.width; ++i)
      if (v(i) < level && v(i + 1) >= level)
        return (i + (level - v(i)) / (v(i + 1) - v(i))) * texel;
    return std::numeric_limits<double>::quiet_NaN();
  };
  return crossing(0.9) - crossing(0.1);
}

// A scene's meshes, lights and one receiver's texel space, for calling the filters directly.
struct Prepared {
  Scene scene;
  std::vector<Mesh> meshes;
  std::vector<Light> lights;
  TexelSpace space;
  BaselineInputs in;
};

std::unique_ptr<Prepared> prepare(const Scene& scene, const std::string& receiver) {
  auto p = std::make_unique<Prepared>();
  p->scene = scene;
  std::size_t index = 0;
  for (const auto& o : scene.objects) {
    auto mesh = import_mesh(o, scene.file);
    EXPECT_TRUE(mesh) << mesh.error().message;
    if (o.name == receiver) index = p->meshes.size();
    p->meshes.push_back(std::move(*mesh));
  }
  for (std::size_t i = 0; i < p->meshes.size(); ++i)
    if (scene.objects[i].blocker) p->in.blockers.push_back(&p->meshes[i]);
  auto lights = make_lights(scene.lights, scene.file);
  EXPECT_TRUE(lights) << lights.error().message;
  p->lights = std::move(*lights);
  p->space = rasterise_texels(p->meshes[index], scene.bake.resolution, scene.bake.resolution);
  p->in.lights = &p->lights;
  p->in.receiver = &p->meshes[index];
  p->in.settings = baseline_settings(p->scene.bake);
  p->in.stream = index;
  return p;
}

// --- The depth image --------------------------------------------------------------------------

// The parallel scene's blocker seen from the light: depth 1 m exactly where a pixel's centre
// projects inside the 0.6 m square, nothing elsewhere.
TEST(ShadowMap, DepthIsExactInsideTheBlockerAndEmptyOutside) {
  Scene scene = load("parallel", 16, "pcf");
  auto p = prepare(scene, "floor");
  const ProjectionFrame frame = frame_towards(Vec3(0, 0, 1.5), Vec3(0, 0, 0));
  const ShadowMap map = render_shadow_map(p->in.blockers, frame, 0.5, 200, 1e-3);
  int inside = 0;
  for (int y = 0; y < map.size; ++y)
    for (int x = 0; x < map.size; ++x) {
      const double tx = -0.5 + (x + 0.5) * map.pixel, ty = -0.5 + (y + 0.5) * map.pixel;
      const bool covered = std::abs(tx) < 0.3 && std::abs(ty) < 0.3;  // the square at depth 1
      if (covered) {
        EXPECT_NEAR(map.at(x, y), 1.0, 1e-6) << x << "," << y;
        ++inside;
      } else if (std::abs(tx) > 0.3 + 1e-9 || std::abs(ty) > 0.3 + 1e-9) {
        EXPECT_EQ(map.at(x, y), std::numeric_limits<float>::infinity()) << x << "," << y;
      }
    }
  EXPECT_EQ(inside, 120 * 120);
  EXPECT_NEAR(map.nearest, 1.0, 1e-6);
}

// A tilted plane: the stored depth at every pixel is the ray's intersection with it (1/depth
// interpolated linearly in the image is exact under perspective).
TEST(ShadowMap, TiltedPlaneDepthIsPerspectiveCorrect) {
  Scene scene = load("parallel", 16, "pcf");
  object(scene, "blocker").transform = Affine3(Eigen::Translation3d(0, 0, 0.5)) *
                                       Eigen::AngleAxisd(0.6, Vec3::UnitY()) *
                                       Affine3(Eigen::Translation3d(0, 0, -0.5));
  auto p = prepare(scene, "floor");
  const ProjectionFrame frame = frame_towards(Vec3(0.1, 0.05, 1.5), Vec3(0, 0, 0));
  const ShadowMap map = render_shadow_map(p->in.blockers, frame, 0.5, 128, 1e-3);
  const Vec3 n = Eigen::AngleAxisd(0.6, Vec3::UnitY()) * Vec3::UnitZ();
  const Vec3 on_plane(0, 0, 0.5);
  int checked = 0;
  for (int y = 0; y < map.size; ++y)
    for (int x = 0; x < map.size; ++x) {
      if (!std::isfinite(map.at(x, y))) continue;
      const double tx = -0.5 + (x + 0.5) * map.pixel, ty = -0.5 + (y + 0.5) * map.pixel;
      const Vec3 dir = frame.axis + tx * frame.e1 + ty * frame.e2;
      const double depth = n.dot(on_plane - frame.origin) / n.dot(dir);
      EXPECT_NEAR(map.at(x, y), depth, 2e-6 * depth);
      ++checked;
    }
  EXPECT_GT(checked, 2000);
}

// Points all round a light take the six faces of a cube; points below it, one frustum.
TEST(ShadowMap, FrustaSplitIntoCubeFacesAroundTheLight) {
  const Vec3 centre(0, 0, 1);
  std::vector<Vec3> below = {Vec3(-1, -1, 0), Vec3(1, 1, 0), Vec3(0.5, -0.5, 0)};
  const auto one = fit_frusta(centre, below, 0.25);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].points.size(), 3u);
  std::vector<Vec3> around = {Vec3(3, 0, 1),  Vec3(-3, 0, 1), Vec3(0, 3, 1),
                              Vec3(0, -3, 1), Vec3(0, 0, 4),  Vec3(0, 0, -2)};
  const auto six = fit_frusta(centre, around, 0.25);
  ASSERT_EQ(six.size(), 6u);
  for (const auto& f : six) {
    ASSERT_EQ(f.points.size(), 1u);
    EXPECT_NEAR(f.frame.depth(around[f.points[0]]), 3.0, 1e-12);
  }
}

// --- Depth bias ---------------------------------------------------------------------------------

// A floor that is itself a blocker does not shadow itself: wherever the floor lit without it as
// a blocker is fully lit, it stays lit, under an overhead light and under a light 20° above its
// horizon (where a PCSS footprint spans tens of shadow-map pixels).
TEST(ShadowMap, NoAcneOnALitFloorThatIsABlocker) {
  for (const bool grazing : {false, true}) {
    for (const char* method : {"pcf", "pcss", "adaptive-pcf", "chun-oh"}) {
      Scene scene = load("parallel", 96, method);
      if (grazing) {
        scene.lights[0].position = Vec3(-2.2, 0, 0.9);
        scene.lights[0].normal = Vec3(1, 0, -0.36).normalized();
      }
      const Image without = bake_first(scene);
      object(scene, "floor").blocker = true;
      const Image with = bake_first(scene);
      int lit = 0, acne = 0;
      for (std::size_t i = 0; i < with.pixels.size(); i += 3) {
        if (without.pixels[i] < 0.9999f) continue;
        ++lit;
        acne += with.pixels[i] < 0.99f;
      }
      EXPECT_GT(lit, 2000) << method;
      EXPECT_EQ(acne, 0) << method << (grazing ? ", grazing light" : ", overhead light");
    }
  }
}

// A box standing on the floor (x from 0.35 to 0.85 m, the light above x in [−0.25, 0.25]): the
// floor right behind its far face, 1.6 mm from it, is in full shadow in every method (with the
// floor blocking too); right before its near face it is in the light for PCF. (The bias alone is
// pinned by the thin wall below: here the box's top is far nearer the light than the floor.)
TEST(ShadowMap, ContactShadowsStayAttached) {
  for (const char* method : {"pcf", "pcss", "adaptive-pcf", "chun-oh", "reference"}) {
    Scene scene = load("parallel", 128, method);
    scene.bake.samples = 64;
    object(scene, "blocker").blocker = false;
    object(scene, "floor").blocker = true;
    ObjectDesc box;
    box.name = "box";
    box.mesh = std::string(SB_SOURCE_DIR) + "/scenes/showcase/box.obj";
    box.receiver = false;
    box.transform = Affine3(Eigen::Translation3d(0.6, 0, 0));
    scene.objects.push_back(box);
    const Image img = bake_first(scene);
    const double texel = 2.0 / img.width;
    const int far_column = int(std::floor((0.85 + 1) / texel - 0.5)) + 1;  // first beyond 0.85
    const int near_column = int(std::floor((0.35 + 1) / texel)) - 1;       // last before x = 0.35
    for (int row = img.height / 2 - 10; row <= img.height / 2 + 10; ++row) {
      EXPECT_LE(img.at(far_column, row)[0], 0.02f) << method << " row " << row;
      if (std::string(method) == "pcf") {
        EXPECT_GE(img.at(near_column, row)[0], 0.99f) << row;
      }
    }
  }
}

// The bias itself: a zero-thickness wall standing on the floor (x = 0.5 m, 0.6 m tall), lit from
// 45° above its front. Behind it the floor is shadowed from the base on: the first texel centre
// (8 mm behind the wall) lies 11 mm behind the wall along its ray from the light, far more than
// the bias (about 2 mm here); a bias of 30 pixels lit it. In front of the wall, PCF's floor is
// lit right up to the base: the taps that fall on the wall are beyond the point's depth.
TEST(ShadowMap, BiasKeepsAThinWallsShadowAtItsBase) {
  for (const char* method : {"pcf", "pcss", "adaptive-pcf", "chun-oh", "reference"}) {
    Scene scene = load("parallel", 128, method);
    scene.bake.samples = 64;
    object(scene, "floor").blocker = true;
    object(scene, "blocker").transform = Affine3(Eigen::Translation3d(0.5, 0, 0.3)) *
                                         Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitY()) *
                                         Affine3(Eigen::Translation3d(0, 0, -0.5));
    scene.lights[0].position = Vec3(-1, 0, 1.5);
    scene.lights[0].normal = Vec3(1, 0, -1).normalized();
    const Image img = bake_first(scene);
    const double texel = 2.0 / img.width;
    const int behind = int(std::floor((0.5 + 1) / texel - 0.5)) + 1;  // first centre beyond
    for (int row = img.height / 2 - 8; row <= img.height / 2 + 8; ++row) {
      EXPECT_LE(img.at(behind, row)[0], 0.02f) << method << " row " << row;
      if (std::string(method) == "pcf") {
        EXPECT_GE(img.at(behind - 1, row)[0], 0.99f) << row;
      }
    }
  }
}

// A concave corner seen at a grazing angle: a wall standing on the floor, the light 15° above
// the floor in front of it. Taps of a wide PCF footprint that fall beyond the corner meet the
// wall, which is nearer the light than the floor's plane there but farther than the point: the
// floor in front of the wall stays lit up to the base (the cap at d_r of shadow_map.h).
TEST(ShadowMap, ConcaveCornerDoesNotDarkenTheFloorAlongAWall) {
  Scene scene = load("parallel", 128, "pcf");
  set_setting(scene.bake, "pcf_radius", 8);
  object(scene, "floor").blocker = true;
  object(scene, "blocker").transform = Affine3(Eigen::Translation3d(0.5, 0, 0.3)) *
                                       Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitY()) *
                                       Affine3(Eigen::Translation3d(0, 0, -0.5));
  scene.lights[0].position = Vec3(-2, 0, 0.6);
  scene.lights[0].normal = Vec3(1, 0, -0.3).normalized();
  const Image img = bake_first(scene);
  const int front = int(std::floor((0.5 + 1) / (2.0 / img.width) - 0.5));  // last centre before
  for (int row = img.height / 2 - 8; row <= img.height / 2 + 8; ++row)
    EXPECT_GE(img.at(front, row)[0], 0.99f) << "row " << row;
}

// --- What tells the filters apart ---------------------------------------------------------------

// PCF's penumbra is its fixed footprint (pcf_radius shadow-map pixels) whatever the blocker's
// height; PCSS's is the parallel-planes estimate L·(d_r − d_b)/d_b, 0.1 m with the blocker 0.25
// m above the floor and 0.5 m at 0.75 m (10–90%: 0.8 of that, the ramp being linear). A 256²
// shadow map makes PCF's footprint (about 5 × 10 mm) several texels wide at 256².
TEST(Pcf, PenumbraWidthIndependentOfBlockerDistance) {
  double widths[2];
  for (int k = 0; k < 2; ++k) {
    Scene scene = load("parallel", 256, "pcf");
    set_setting(scene.bake, "shadow_map", 256);
    object(scene, "blocker").transform =
        Affine3(Eigen::Translation3d(0, 0, (k == 0 ? 0.25 : 0.75) - 0.5));
    widths[k] = edge_width(bake_first(scene), 128);
  }
  std::printf("PCF 10-90%% width: blocker at 0.25 m %.4f m, at 0.75 m %.4f m\n", widths[0],
              widths[1]);
  EXPECT_GT(widths[0], 0.02);  // resolved over several texels
  EXPECT_NEAR(widths[0], widths[1], 2.0 / 256);
}

TEST(Pcss, PenumbraWidthGrowsWithBlockerDistance) {
  double widths[2];
  const double heights[2] = {0.25, 0.75};
  for (int k = 0; k < 2; ++k) {
    Scene scene = load("parallel", 256, "pcss");
    object(scene, "blocker").transform = Affine3(Eigen::Translation3d(0, 0, heights[k] - 0.5));
    widths[k] = edge_width(bake_first(scene), 128);
    const double d_b = 1.5 - heights[k];
    const double expected = 0.8 * 0.5 * (1.5 - d_b) / d_b;
    std::printf("PCSS 10-90%% width, blocker at %.2f m: %.4f m (parallel planes: %.4f m)\n",
                heights[k], widths[k], expected);
    EXPECT_NEAR(widths[k], expected, 0.1 * expected + 2.0 / 256);
  }
  EXPECT_GT(widths[1], 4 * widths[0]);
}

// Adaptive PCF takes its full set only where the 8 rim samples disagree, and there it is the
// full filter on the same samples, to the bit; where they agree, the full filter mostly agrees
// too (Uralsky's bet), and the full set runs on a minority of texels.
TEST(AdaptivePcf, EqualsTheFullSetWhereItTakesItAndSkipsItMostly) {
  Scene scene = load("parallel", 128, "adaptive-pcf");
  auto p = prepare(scene, "floor");
  MethodStats stats;
  const Image adaptive =
      bake_shadow_map_filter(p->space, p->in, &stats, ShadowFilterOptions{}).image;
  ShadowFilterOptions full_options;
  full_options.adaptive_always_full = true;
  const Image full = bake_shadow_map_filter(p->space, p->in, nullptr, full_options).image;
  int settled = 0, missed = 0, filtered = 0;
  double settled_error = 0;
  for (std::size_t i = 0; i < adaptive.pixels.size(); i += 3) {
    const float a = adaptive.pixels[i], f = full.pixels[i];
    if (a > 0 && a < 1) {
      ++filtered;
      EXPECT_EQ(a, f) << "texel " << i / 3;  // the full set, same samples
    } else {
      ++settled;
      settled_error += std::abs(a - f);
      missed += std::abs(a - f) > 0.1f;
    }
  }
  const double fraction = stat(stats, "full_filter_fraction");
  std::printf(
      "adaptive PCF: full set on %.3f of lit texels (%d texels), settled %d, of which %d differ "
      "from the full set by > 0.1 (mean |difference| %.5f); %.1f filter samples per texel\n",
      fraction, filtered, settled, missed, settled_error / settled,
      stat(stats, "mean_filter_taps"));
  EXPECT_NEAR(fraction, double(filtered) / (adaptive.pixels.size() / 3), 0.01);
  EXPECT_LT(fraction, 0.3);
  EXPECT_LT(missed, settled / 200);
  EXPECT_LT(stat(stats, "mean_filter_taps"), 0.5 * 64);
}

// Every texel has its own random stream: the bytes do not depend on the thread count.
TEST(AdaptivePcf, SameResultForAnyThreadCount) {
  Scene scene = load("parallel", 64, "adaptive-pcf");
  Image one;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = bake_first(scene);
  }
  const Image many = bake_first(scene);
  EXPECT_EQ(one.pixels, many.pixels);
}

// A rectangle light red on one half and blue on the other: Chun–Oh's sub-regions each see their
// own part of it, so the two penumbrae of the shadow take opposite tints, each channel as in the
// reference (RMSE ≤ 0.03 per channel, measured 0.014, max 0.075: V_u against V and the filter's
// grid); PCSS, blind to the light's image, gives grey penumbrae.
TEST(ChunOh, PenumbraColourFollowsTheLightImage) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("shadowbake_chun_oh_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  Image texture(2, 1, 3, 0.0f);
  texture.at(0, 0)[0] = 1.0f;  // left: red
  texture.at(1, 0)[2] = 1.0f;  // right: blue
  ASSERT_TRUE(write_image(dir / "half.exr", texture, PixelFormat::float32));
  Scene chun = load("parallel", 96, "chun-oh"), ref = load("parallel", 96, "reference");
  Scene pcss = load("parallel", 96, "pcss");
  for (Scene* s : {&chun, &ref, &pcss}) s->lights[0].texture = dir / "half.exr";
  ref.bake.samples = 1024;
  MethodStats stats;
  const Image c = bake_first(chun, &stats), r = bake_first(ref), g = bake_first(pcss);
  std::filesystem::remove_all(dir);
  for (int ch : {0, 2}) {
    const Errors e = image_errors(c, r, ch);
    std::printf("Chun-Oh, channel %d: RMSE vs reference %.4f, max %.4f\n", ch, e.rmse, e.max);
    EXPECT_LE(e.rmse, 0.03) << "channel " << ch;
  }
  std::printf("Chun-Oh: split on %.3f of lit texels, twice on %.3f, %.2f regions\n",
              stat(stats, "split_fraction"), stat(stats, "split_twice_fraction"),
              stat(stats, "mean_regions"));
  // Along the middle row: the tint (red − blue) of each penumbra has the reference's sign and
  // is strong in both methods; PCSS's penumbrae are grey.
  const int row = c.height / 2;
  double strongest[2] = {0, 0}, reference[2] = {0, 0}, grey = 0;
  for (int i = 0; i < c.width; ++i) {
    const int side = i < c.width / 2 ? 0 : 1;
    const double tint = c.at(i, row)[0] - c.at(i, row)[2];
    const double ref_tint = r.at(i, row)[0] - r.at(i, row)[2];
    if (std::abs(ref_tint) > std::abs(reference[side])) reference[side] = ref_tint;
    if (std::abs(tint) > std::abs(strongest[side])) strongest[side] = tint;
    grey = std::max(grey, double(std::abs(g.at(i, row)[0] - g.at(i, row)[2])));
  }
  std::printf("strongest tint (red - blue): left %.3f (reference %.3f), right %.3f (%.3f)\n",
              strongest[0], reference[0], strongest[1], reference[1]);
  for (int side : {0, 1}) {
    EXPECT_GT(std::abs(strongest[side]), 0.3) << side;
    EXPECT_GT(strongest[side] * reference[side], 0) << side;  // the same tint as the reference
  }
  EXPECT_LT(strongest[0] * strongest[1], 0);  // one reddish, one bluish
  EXPECT_LT(grey, 1e-6);
  EXPECT_EQ(c.at(0, 0)[1], 0.0f);  // no green light
}

// --- Against the reference ----------------------------------------------------------------------

// Each method against the reference (256 samples) on scenes/parallel at 128². Measured (RMSE /
// max): pcf 0.138 / 0.77 (a hard shadow: its 5-pixel footprint is not the 0.25 m penumbra),
// pcss 0.008 / 0.05, adaptive-pcf 0.019 / 0.13, chun-oh 0.020 / 0.11; the convolution method
// gets 0.014, and V_u against V alone (docs/design.md §1) accounts for 0.015. PCSS's figure
// depends on where its fixed 16 × 16 grid's steps fall against the texels: 0.022 at 256².
// Tolerances: pcf within [0.10, 0.16], the others ≤ 0.03, max ≤ 0.2.
TEST(ShadowMapFilters, AgreeWithTheReferenceOnParallelPlanes) {
  Scene ref_scene = load("parallel", 128, "reference");
  ref_scene.bake.samples = 256;
  const Image r = bake_first(ref_scene);
  struct Case {
    const char* method;
    double rmse_lo, rmse_hi, max;
  };
  for (const Case& c : {Case{"pcf", 0.10, 0.16, 1.0}, Case{"pcss", 0, 0.03, 0.2},
                        Case{"adaptive-pcf", 0, 0.03, 0.2}, Case{"chun-oh", 0, 0.03, 0.2}}) {
    const Image img = bake_first(load("parallel", 128, c.method));
    const Errors e = image_errors(img, r);
    std::printf("%s vs reference at 128²: RMSE %.4f, max %.4f\n", c.method, e.rmse, e.max);
    RecordProperty(std::string(c.method) + "_rmse", std::to_string(e.rmse));
    EXPECT_GE(e.rmse, c.rmse_lo) << c.method;
    EXPECT_LE(e.rmse, c.rmse_hi) << c.method;
    EXPECT_LE(e.max, c.max) << c.method;
  }
}

// The showcase's sphere is a receiver and a blocker, lit by the panel above it: the half facing
// the panel is fully lit (convex: nothing of it lies between the panel and itself), whatever
// the facets of its tessellation.
TEST(ShadowMap, CurvedReceiverDoesNotShadowItself) {
  auto loaded = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/showcase/scene.toml");
  ASSERT_TRUE(loaded) << loaded.error().message;
  Scene scene = *loaded;
  scene.bake.resolution = 64;
  scene.lights.resize(1);  // the panel
  for (const char* method : {"pcf", "pcss", "adaptive-pcf", "chun-oh"}) {
    scene.bake.method = method;
    auto p = prepare(scene, "sphere");
    const Image img = bake_shadow_map_filter(p->space, p->in, nullptr).image;
    int facing = 0, dark = 0;
    for (const Texel& t : p->space.texels) {
      const Vec3 to_light = (p->lights[0].centre() - t.position.cast<double>()).normalized();
      if (t.normal.cast<double>().dot(to_light) < 0.5) continue;  // within 60° of the panel
      ++facing;
      dark += img.at(t.x, t.y)[0] < 0.99f;
    }
    EXPECT_GT(facing, 200) << method;
    EXPECT_EQ(dark, 0) << method;
  }
}

}  // namespace
}  // namespace sb
