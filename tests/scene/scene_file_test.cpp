// Tests of the scene file reader (src/scene/scene_file.cpp): every key and default read back, every
// kind of bad input rejected with a one-line message naming file, line, item and key, and the
// order in which object transforms compose.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>

#include "methods/method.h"
#include "scene/lights.h"
#include "scene/scene.h"
#include "scene/sun_light.h"

namespace sb {
namespace {

constexpr double degrees = std::numbers::pi / 180.0;

// The smallest valid object and light; tests append keys to them or put them together.
const std::string object_floor = "[[object]]\nname = \"floor\"\nmesh = \"m.obj\"\n";
const std::string light_panel =
    "[[light]]\nname = \"panel\"\nshape = \"rectangle\"\nposition = [0, 0, 1.5]\n"
    "normal = [0, 0, -1]\nsize = [0.5, 0.5]\npower = 100.0\n";
const std::string light_bulb =
    "[[light]]\nname = \"bulb\"\nshape = \"sphere\"\nposition = [0, 0, 1]\nradius = 0.1\n"
    "power = 10\n";
const std::string light_disk =
    "[[light]]\nname = \"spot\"\nshape = \"disk\"\nposition = [0, 0, 1]\nnormal = [0, 0, -1]\n"
    "radius = [0.2]\npower = 10\n";

// 1-based line of the first occurrence of `needle` in `text`.
int line_of(const std::string& text, const std::string& needle) {
  const std::size_t at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
}

// Each test gets its own folder holding an empty mesh "m.obj", so mesh existence checks pass.
class SceneFile : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device random;
    dir_ = std::filesystem::temp_directory_path() /
           ("shadowbake_scene_test_" + std::to_string(random()) + std::to_string(random()));
    std::filesystem::create_directories(dir_);
    std::ofstream(dir_ / "m.obj").flush();
  }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }

  std::filesystem::path write(const std::string& text, const std::string& name = "scene.toml") {
    const std::filesystem::path file = dir_ / name;
    std::filesystem::create_directories(file.parent_path());
    std::ofstream(file, std::ios::binary) << text;
    return file;
  }

  Scene load_ok(const std::string& text) {
    Expected<Scene> scene = load_scene(write(text));
    EXPECT_TRUE(scene.has_value()) << scene.error().message;
    return scene ? *scene : Scene{};
  }

  std::string error_of(const std::string& text) {
    Expected<Scene> scene = load_scene(write(text));
    if (scene) {
      ADD_FAILURE() << "expected an error for:\n" << text;
      return {};
    }
    EXPECT_EQ(scene.error().kind, ErrorKind::scene);
    EXPECT_EQ(scene.error().message.find('\n'), std::string::npos) << scene.error().message;
    return scene.error().message;
  }

  // The error starts "<file>:<line of line_needle>: <item>: " and mentions `key`.
  void expect_error(const std::string& text, const std::string& line_needle,
                    const std::string& item, const std::string& key) {
    const std::string message = error_of(text);
    const std::string prefix = (dir_ / "scene.toml").string() + ":" +
                               std::to_string(line_of(text, line_needle)) + ": " + item + ": ";
    EXPECT_EQ(message.rfind(prefix, 0), 0u) << message << "\nexpected prefix: " << prefix;
    EXPECT_NE(message.find(key), std::string::npos) << message << "\nexpected key: " << key;
  }

  std::filesystem::path dir_;
};

// The scene reader knows the methods only through the vocabulary it is handed: a method and a
// key this build lacks are read where the vocabulary has them, and refused where this build's
// is given.
TEST_F(SceneFile, ChecksTheMethodVocabularyItIsGiven) {
  const std::string text =
      "[bake]\nmethod = \"imagined\"\nimagined_rows = 7\n" + object_floor + light_disk;
  MethodVocabulary imagined;
  imagined.names = {"imagined"};
  SettingSpec rows;
  rows.key = "imagined_rows";
  rows.fallback = std::int64_t(4);
  rows.lo = 1, rows.hi = 8;
  imagined.settings = {rows};
  Expected<Scene> read = load_scene(write(text), imagined);
  ASSERT_TRUE(read) << read.error().message;
  EXPECT_EQ(read->bake.method, "imagined");
  EXPECT_EQ(std::get<std::int64_t>(read->bake.own.at("imagined_rows")), 7);
  // This build's vocabulary knows neither.
  expect_error(text, "imagined_rows =", "[bake]", "unknown key 'imagined_rows'");
  expect_error("[bake]\nmethod = \"imagined\"\n" + object_floor + light_disk, "method =", "[bake]",
               "unknown method 'imagined'");
}

// A scene's default method, which the scene layer names without knowing the methods, is the
// registry's first.
TEST(MethodRegistry, DefaultIsTheFirst) {
  EXPECT_EQ(BakeSettings{}.method, method_registry().front().name);
  EXPECT_EQ(method_vocabulary().names.front(), method_registry().front().name);
}

TEST_F(SceneFile, ReadsEveryValue) {
  const std::string text = R"(
[bake]
resolution = 1024
method = "reference"
quantity = "irradiance"
samples = 64
margin = 2
seed = 7

[[object]]
name = "floor"
mesh = "m.obj"
receiver = true
blocker = false
uv = 1
translate = [1, 2, 3]
rotate_deg = [0, 0, 90]
scale = [2, 2, 2]

[[object]]
name = "box.01"
mesh = "m.obj"
receiver = false

[[light]]
name = "panel"
shape = "rectangle"
position = [0, 0, 1.5]
normal = [0, 0, -2]
up = [0, 1, 0]
size = [0.5, 0.25]
color = [1, 0.5, 0.25]
power = 100.0

[[light]]
name = "bulb"
shape = "sphere"
position = [1, 1, 1]
radius = 0.1
power = 5
)";
  const Scene scene = load_ok(text);
  EXPECT_EQ(scene.file, dir_ / "scene.toml");
  EXPECT_EQ(scene.bake.resolution, 1024);
  EXPECT_EQ(scene.bake.method, "reference");
  EXPECT_EQ(scene.bake.quantity, Quantity::irradiance);
  EXPECT_EQ(scene.bake.samples, 64);
  EXPECT_EQ(scene.bake.margin, 2);
  EXPECT_EQ(scene.bake.seed, 7u);

  ASSERT_EQ(scene.objects.size(), 2u);
  const ObjectDesc& floor = scene.objects[0];
  EXPECT_EQ(floor.name, "floor");
  EXPECT_EQ(floor.mesh, dir_ / "m.obj");
  EXPECT_TRUE(floor.receiver);
  EXPECT_FALSE(floor.blocker);
  EXPECT_EQ(floor.uv_channel, 1);
  EXPECT_EQ(floor.line, line_of(text, "name = \"floor\"") - 1);
  EXPECT_TRUE(
      floor.transform.isApprox(object_transform(Vec3(1, 2, 3), Vec3(0, 0, 90), Vec3(2, 2, 2))));
  EXPECT_EQ(scene.objects[1].name, "box.01");
  EXPECT_FALSE(scene.objects[1].receiver);
  EXPECT_TRUE(scene.objects[1].blocker);

  ASSERT_EQ(scene.lights.size(), 2u);
  const LightDesc& panel = scene.lights[0];
  EXPECT_EQ(panel.name, "panel");
  EXPECT_EQ(panel.shape, LightShape::rectangle);
  EXPECT_EQ(panel.position, Vec3(0, 0, 1.5));
  EXPECT_EQ(panel.normal, Vec3(0, 0, -1));
  EXPECT_EQ(panel.up, Vec3(0, 1, 0));
  EXPECT_EQ(panel.width, 0.5);
  EXPECT_EQ(panel.height, 0.25);
  EXPECT_EQ(panel.color, Vec3(1, 0.5, 0.25));
  EXPECT_EQ(panel.power, 100.0);
  EXPECT_EQ(panel.line, line_of(text, "name = \"panel\"") - 1);
  const LightDesc& bulb = scene.lights[1];
  EXPECT_EQ(bulb.shape, LightShape::sphere);
  EXPECT_EQ(bulb.position, Vec3(1, 1, 1));
  EXPECT_EQ(bulb.radius, 0.1);
  EXPECT_EQ(bulb.power, 5.0);
}

TEST_F(SceneFile, AppliesDefaults) {
  const Scene scene = load_ok(object_floor + light_panel);
  const BakeSettings defaults;
  EXPECT_EQ(scene.bake.resolution, defaults.resolution);
  EXPECT_EQ(scene.bake.resolution, 512);
  EXPECT_EQ(scene.bake.method, "backprojection");
  EXPECT_EQ(scene.bake.quantity, Quantity::visibility);
  EXPECT_EQ(scene.bake.samples, 256);
  EXPECT_EQ(scene.bake.margin, 4);
  EXPECT_EQ(scene.bake.seed, 0u);
  ASSERT_EQ(scene.objects.size(), 1u);
  EXPECT_TRUE(scene.objects[0].receiver);
  EXPECT_TRUE(scene.objects[0].blocker);
  EXPECT_EQ(scene.objects[0].uv_channel, 0);
  EXPECT_TRUE(scene.objects[0].transform.isApprox(Affine3::Identity()));
  ASSERT_EQ(scene.lights.size(), 1u);
  EXPECT_EQ(scene.lights[0].up, Vec3(0, 1, 0));
  EXPECT_EQ(scene.lights[0].color, Vec3(1, 1, 1));
}

TEST_F(SceneFile, UvAutoAsksForGeneratedLightmapUvs) {
  const Scene scene =
      load_ok("[[object]]\nname = \"floor\"\nmesh = \"m.obj\"\nuv = \"auto\"\n" + light_panel);
  EXPECT_TRUE(scene.objects[0].auto_uv);
  EXPECT_EQ(scene.objects[0].uv_channel, 0);
  EXPECT_FALSE(load_ok(object_floor + light_panel).objects[0].auto_uv);
  const std::string e =
      error_of("[[object]]\nname = \"floor\"\nmesh = \"m.obj\"\nuv = \"smart\"\n" + light_panel);
  EXPECT_NE(
      e.find("scene.toml:4: object 'floor': 'uv' must be a UV channel from 0 to 7 or \"auto\", "
             "got \"smart\""),
      std::string::npos)
      << e;
}

TEST_F(SceneFile, ResolvesMeshAgainstSceneFolder) {
  const std::filesystem::path file =
      write("[[object]]\nname = \"floor\"\nmesh = \"../m.obj\"\n" + light_panel, "sub/scene.toml");
  Expected<Scene> scene = load_scene(file);
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_EQ(scene->objects[0].mesh, dir_ / "m.obj");
}

TEST_F(SceneFile, ReportsMissingSceneFile) {
  const std::filesystem::path file = dir_ / "absent.toml";
  Expected<Scene> scene = load_scene(file);
  ASSERT_FALSE(scene);
  EXPECT_EQ(scene.error().message.rfind(file.string() + ": cannot open scene file: ", 0), 0u)
      << scene.error().message;
}

TEST_F(SceneFile, ReportsTomlSyntaxErrorWithLineAndColumn) {
  const std::string text = object_floor + "receiver = = true\n" + light_panel;
  const std::string message = error_of(text);
  const std::string prefix =
      (dir_ / "scene.toml").string() + ":" + std::to_string(line_of(text, "= =")) + ":";
  EXPECT_EQ(message.rfind(prefix, 0), 0u) << message;
  EXPECT_NE(message.find("TOML syntax error: "), std::string::npos) << message;
}

TEST_F(SceneFile, RejectsUnknownKey) {
  const std::string text = object_floor + "recever = true\n" + light_panel;
  expect_error(text, "recever", "object 'floor'", "unknown key 'recever'");
  EXPECT_NE(error_of(text).find("(known: name, mesh, receiver, blocker, uv, allow_uncovered, "
                                "translate, "
                                "rotate_deg, scale, lightmap_scale)"),
            std::string::npos);
}

TEST_F(SceneFile, ReportsFirstUnknownKeyInFileOrder) {
  // toml++ iterates keys alphabetically; the message must point at the earliest line.
  const std::string text = object_floor + "zz_first = 1\naa_second = 2\n" + light_panel;
  expect_error(text, "zz_first", "object 'floor'", "unknown key 'zz_first'");
}

TEST_F(SceneFile, RejectsUnknownTopLevelKeyAndTable) {
  expect_error("resolution = 5\n" + object_floor + light_panel, "resolution", "top level",
               "'resolution'");
  expect_error(object_floor + light_panel + "[render]\nsamples = 4\n", "[render]", "top level",
               "'render'");
}

TEST_F(SceneFile, RejectsUnknownBakeKey) {
  const std::string text = "[bake]\nresolution = 64\nsample = 4\n" + object_floor + light_panel;
  expect_error(text, "sample =", "[bake]", "unknown key 'sample'");
}

TEST_F(SceneFile, RejectsUnknownMethod) {
  const std::string text = "[bake]\nmethod = \"foo\"\n" + object_floor + light_panel;
  expect_error(text, "method", "[bake]",
               "unknown method 'foo' (known: backprojection, convolution, accumulation, pcf, "
               "pcss, adaptive-pcf, erosion, chun-oh, reference, ambient-occlusion)");
}

TEST_F(SceneFile, ReadsAndChecksMethodSettings) {
  const Scene scene = load_ok(
      "[bake]\nerror_texels = 0.5\nmax_image = 2048\nmax_triples = 32\nlight_parts = 2\n"
      "blocker_combine = \"product\"\nweighting = \"emission\"\nshadow_map = 1024\npcf_radius = 3\n"
      "erosion_factor = \"distance\"\n" +
      object_floor + light_panel);
  EXPECT_EQ(setting_number(scene.bake, "error_texels"), 0.5);
  EXPECT_EQ(setting_whole(scene.bake, "max_image"), 2048);
  EXPECT_EQ(setting_whole(scene.bake, "max_triples"), 32);
  EXPECT_EQ(setting_whole(scene.bake, "light_parts"), 2);
  EXPECT_EQ(setting_word(scene.bake, "blocker_combine"), "product");
  EXPECT_EQ(setting_word(scene.bake, "weighting"), "emission");
  EXPECT_EQ(setting_whole(scene.bake, "shadow_map"), 1024);
  EXPECT_EQ(setting_number(scene.bake, "pcf_radius"), 3.0);
  EXPECT_EQ(setting_word(scene.bake, "erosion_factor"), "distance");
  // Keys not given take their method's default.
  EXPECT_EQ(setting_whole(scene.bake, "light_rows"), 32);
  EXPECT_TRUE(setting_flag(scene.bake, "trace"));
  // The keys given, with their lines, for the bake to report those its method ignores.
  ASSERT_EQ(scene.bake_keys.size(), 9u);
  EXPECT_EQ(scene.bake_keys[0].key, "error_texels");
  EXPECT_EQ(scene.bake_keys[0].line, 2);
  EXPECT_EQ(scene.bake_keys[8].key, "erosion_factor");
  EXPECT_EQ(scene.bake_keys[8].line, 10);
  expect_error("[bake]\nerror_texels = 0\n" + object_floor + light_panel, "error_texels", "[bake]",
               "'error_texels' must be a number > 0");
  expect_error("[bake]\nblocker_combine = \"max\"\n" + object_floor + light_panel,
               "blocker_combine", "[bake]", "'blocker_combine' must be \"product\" or \"sum\"");
  expect_error("[bake]\nweighting = \"area\"\n" + object_floor + light_panel, "weighting", "[bake]",
               "'weighting' must be \"irradiance\" or \"emission\"");
  expect_error("[bake]\nerosion_factor = 2\n" + object_floor + light_panel, "erosion_factor",
               "[bake]", "'erosion_factor' must be a string");
  expect_error("[bake]\nlight_parts = 3\n" + object_floor + light_panel, "light_parts", "[bake]",
               "'light_parts' must be 1, 2 or 4");
  expect_error("[bake]\nlight_parts = 8\n" + object_floor + light_panel, "light_parts", "[bake]",
               "'light_parts' must be an integer from 1 to 4");
  expect_error("[bake]\nmax_image = 10\n" + object_floor + light_panel, "max_image", "[bake]",
               "'max_image' must be an integer from 64 to 16384");
}

TEST_F(SceneFile, RejectsFloatWhereIntegerExpected) {
  const std::string text = "[bake]\nresolution = 512.5\n" + object_floor + light_panel;
  expect_error(text, "resolution", "[bake]", "'resolution' must be an integer");
  expect_error(object_floor + "uv = 1.0\n" + light_panel, "uv =", "object 'floor'", "'uv'");
}

TEST_F(SceneFile, RejectsBakeIntegersOutOfRange) {
  const std::string tail = object_floor + light_panel;
  expect_error("[bake]\nresolution = 0\n" + tail, "resolution", "[bake]", "'resolution'");
  expect_error("[bake]\nresolution = 16385\n" + tail, "resolution", "[bake]", "'resolution'");
  expect_error("[bake]\nsamples = 0\n" + tail, "samples", "[bake]", "'samples'");
  expect_error("[bake]\nmargin = -1\n" + tail, "margin", "[bake]", "'margin'");
  expect_error("[bake]\nseed = -1\n" + tail, "seed", "[bake]", "'seed'");
  EXPECT_TRUE(load_scene(write("[bake]\nresolution = 16384\nmargin = 0\n" + tail)));
}

TEST_F(SceneFile, RejectsUnknownQuantity) {
  const std::string text = "[bake]\nquantity = \"radiance\"\n" + object_floor + light_panel;
  expect_error(text, "quantity", "[bake]", "'quantity'");
  EXPECT_NE(error_of(text).find("got \"radiance\""), std::string::npos);
}

TEST_F(SceneFile, RejectsMissingMeshFile) {
  const std::string text = "[[object]]\nname = \"floor\"\nmesh = \"floor.obj\"\n" + light_panel;
  expect_error(text, "mesh", "object 'floor'", "mesh file 'floor.obj' not found");
  EXPECT_NE(error_of(text).find("(looked for " + (dir_ / "floor.obj").string() + ")"),
            std::string::npos)
      << error_of(text);
}

TEST_F(SceneFile, ReadsLightTexture) {
  std::ofstream(dir_ / "panel.png") << "not read here";
  const Scene scene = load_ok(object_floor + light_panel + "texture = \"panel.png\"\n");
  EXPECT_EQ(scene.lights[0].texture, dir_ / "panel.png");
  EXPECT_TRUE(load_ok(object_floor + light_panel).lights[0].texture.empty());
}

TEST_F(SceneFile, RejectsMissingOrMisplacedTexture) {
  const std::string missing = object_floor + light_panel + "texture = \"nope.png\"\n";
  expect_error(missing, "texture", "light 'panel'", "texture image 'nope.png' not found");
  std::ofstream(dir_ / "t.png") << "x";
  const std::string on_sphere = object_floor + light_bulb + "texture = \"t.png\"\n";
  expect_error(on_sphere, "texture", "light 'bulb'", "'texture' applies only to rectangle");
}

TEST_F(SceneFile, RejectsMeshThatIsNotARegularFile) {
  std::filesystem::create_directories(dir_ / "meshes");
  const std::string text = "[[object]]\nname = \"floor\"\nmesh = \"meshes\"\n" + light_panel;
  expect_error(text, "mesh", "object 'floor'", "not a regular file");
}

TEST_F(SceneFile, RejectsMissingObjectKeys) {
  expect_error("[[object]]\nmesh = \"m.obj\"\n" + light_panel, "[[object]]", "[[object]] #1",
               "missing required key 'name'");
  expect_error(object_floor + "[[object]]\nname = \"box\"\n" + light_panel,
               "[[object]]\nname = \"box\"", "object 'box'", "missing required key 'mesh'");
}

TEST_F(SceneFile, RejectsObjectNamesThatAreNotFileStems) {
  const std::string named = "[[object]]\nmesh = \"m.obj\"\nname = ";
  for (const char* bad : {"\"a/b\"", "\".hidden\"", "\"two words\"", "\"\"", "3"}) {
    const std::string text = object_floor + named + bad + "\n" + light_panel;
    expect_error(text, std::string("name = ") + bad, "[[object]] #2", "'name'");
  }
}

TEST_F(SceneFile, RejectsDuplicateObjectNames) {
  const std::string text = object_floor + "blocker = false\n" + object_floor + light_panel;
  const std::string message = error_of(text);
  EXPECT_NE(message.find(":5: object 'floor': object names must be unique: 'floor' is also "
                         "defined at line 1"),
            std::string::npos)
      << message;
}

TEST_F(SceneFile, RejectsDuplicateLightNames) {
  const std::string text = object_floor + light_panel + light_panel;
  const std::string message = error_of(text);
  EXPECT_NE(message.find(":11: light 'panel': light names must be unique: 'panel' is also "
                         "defined at line 4"),
            std::string::npos)
      << message;
}

TEST_F(SceneFile, RejectsNonPositiveSize) {
  const std::string text = object_floor +
                           "[[light]]\nname = \"panel\"\nshape = \"rectangle\"\n"
                           "position = [0, 0, 1.5]\nnormal = [0, 0, -1]\nsize = [0.5, 0]\n"
                           "power = 100.0\n";
  expect_error(text, "size", "light 'panel'", "'size' must be 2 positive numbers");
  EXPECT_NE(error_of(text).find("got [0.5, 0]"), std::string::npos) << error_of(text);
}

TEST_F(SceneFile, RejectsMissingLightKeys) {
  for (const char* key : {"shape", "position", "normal", "size", "power"}) {
    std::string light = light_panel;
    const std::size_t at = light.find(std::string(key) + " = ");
    light.erase(at, light.find('\n', at) + 1 - at);
    expect_error(object_floor + light, "[[light]]", "light 'panel'",
                 "missing required key '" + std::string(key) + "'");
  }
  expect_error(object_floor + "[[light]]\nshape = \"sphere\"\n", "[[light]]", "[[light]] #1",
               "missing required key 'name'");
}

TEST_F(SceneFile, RejectsUnknownShape) {
  std::string light = light_panel;
  light.replace(light.find("rectangle"), 9, "square");
  expect_error(object_floor + light, "shape", "light 'panel'", "'shape'");
}

TEST_F(SceneFile, RejectsShapeSpecificKeyOnWrongShape) {
  expect_error(object_floor + light_bulb + "size = [1, 1]\n", "size", "light 'bulb'", "'size'");
  expect_error(object_floor + light_bulb + "normal = [0, 0, -1]\n", "normal", "light 'bulb'",
               "'normal'");
  expect_error(object_floor + light_bulb + "up = [0, 1, 0]\n", "up =", "light 'bulb'", "'up'");
  expect_error(object_floor + light_disk + "up = [0, 1, 0]\n", "up =", "light 'spot'", "'up'");
  expect_error(object_floor + light_panel + "radius = 0.1\n", "radius", "light 'panel'",
               "'radius'");
}

TEST_F(SceneFile, AcceptsRadiusAsNumberOrOneElementArray) {
  const Scene scene = load_ok(object_floor + light_bulb + light_disk);
  ASSERT_EQ(scene.lights.size(), 2u);
  EXPECT_EQ(scene.lights[0].radius, 0.1);
  EXPECT_EQ(scene.lights[1].shape, LightShape::disk);
  EXPECT_EQ(scene.lights[1].radius, 0.2);
  EXPECT_EQ(scene.lights[1].normal, Vec3(0, 0, -1));
  EXPECT_NEAR(scene.lights[1].up.dot(scene.lights[1].normal), 0.0, 1e-12);
}

TEST_F(SceneFile, RejectsBadRadius) {
  std::string two = light_bulb;
  two.replace(two.find("0.1"), 3, "[0.1, 0.2]");
  expect_error(object_floor + two, "radius", "light 'bulb'", "'radius'");
  const std::string negative =
      "[[light]]\nname = \"bulb\"\nshape = \"sphere\"\nposition = [0, 0, 1]\nradius = [-0.1]\n"
      "power = 10\n";
  expect_error(object_floor + negative, "radius", "light 'bulb'", "'radius'");
}

// A sun: its direction, Blender's angle unless given, its irradiance; a distant disk (placed for
// the origin until the bake places it for its meshes) whose closed form is E cos θ.
TEST_F(SceneFile, SunIsADirectionAnAngleAndAnIrradiance) {
  const std::string sun =
      "[[light]]\nname = \"sun\"\nshape = \"sun\"\ndirection = [0, -2, -2]\nirradiance = 800\n";
  const Scene scene = load_ok(object_floor + sun);
  ASSERT_EQ(scene.lights.size(), 1u);
  const LightDesc& d = scene.lights[0];
  EXPECT_EQ(d.shape, LightShape::disk);
  EXPECT_EQ(d.sun_angle_deg, kSunAngleDeg);
  EXPECT_LT((d.normal - Vec3(0, -1, -1).normalized()).norm(), 1e-12);
  const Vec3 up(0, 0, 1);  // a floor facing up: cos θ = 1/√2
  EXPECT_NEAR(Light(d).unoccluded_irradiance(Vec3(0.3, 0.2, 0), up).x(), 800 / std::sqrt(2.0),
              1e-3 * 800);
  const Scene wide = load_ok(object_floor + sun + "angle_deg = 2\n");
  EXPECT_EQ(wide.lights[0].sun_angle_deg, 2.0);
  expect_error(object_floor + sun + "position = [0, 0, 1]\n", "position", "light 'sun'",
               "'position'");
  expect_error(object_floor + sun + "power = 10\n", "power", "light 'sun'", "'power'");
  expect_error(object_floor + sun + "angle_deg = 20\n", "angle_deg", "light 'sun'", "'angle_deg'");
  const std::string no_irradiance =
      "[[light]]\nname = \"sun\"\nshape = \"sun\"\ndirection = [0, 0, -1]\n";
  expect_error(object_floor + no_irradiance, "[[light]]", "light 'sun'", "'irradiance'");
  expect_error(object_floor + light_bulb + "irradiance = 3\n", "irradiance", "light 'bulb'",
               "'irradiance'");
}

// A spot: a point light (or a sphere of `radius`) with a cone, Blender's spot size and blend.
TEST_F(SceneFile, SpotIsAPointWithACone) {
  const std::string spot =
      "[[light]]\nname = \"spot\"\nshape = \"spot\"\nposition = [0, 0, 2]\n"
      "direction = [0, 0, -1]\ncone_deg = 60\npower = 100\n";
  const Scene scene = load_ok(object_floor + spot);
  const LightDesc& d = scene.lights[0];
  EXPECT_EQ(d.shape, LightShape::sphere);
  EXPECT_EQ(d.radius, kPointLightRadius);
  EXPECT_LT((d.spot_axis - Vec3(0, 0, -1)).norm(), 1e-12);
  EXPECT_NEAR(d.spot_outer, std::numbers::pi / 6, 1e-12);
  EXPECT_NEAR(d.spot_inner, std::numbers::pi / 6 * (1 - kSpotBlend), 1e-12);
  const Light light(d);
  EXPECT_EQ(light.spot_factor(Vec3(0, 0, 0)), 1.0);
  EXPECT_EQ(light.spot_factor(Vec3(2, 0, 0)), 0.0);  // 45° off the axis, outside 30°
  const Scene soft = load_ok(object_floor + spot + "blend = 1\nradius = 0.1\n");
  EXPECT_EQ(soft.lights[0].spot_inner, 0.0);
  EXPECT_EQ(soft.lights[0].radius, 0.1);
  expect_error(object_floor + spot + "normal = [0, 0, -1]\n", "normal", "light 'spot'", "'normal'");
  expect_error(object_floor + spot + "blend = 2\n", "blend", "light 'spot'", "'blend'");
  expect_error(object_floor + light_bulb + "cone_deg = 30\n", "cone_deg", "light 'bulb'",
               "'cone_deg'");
}

// A sphere of radius 0 is a point light, baked as a sphere of kPointLightRadius; a disk's radius
// must be positive.
TEST_F(SceneFile, SphereOfRadiusZeroIsAPointLight) {
  const std::string point =
      "[[light]]\nname = \"bulb\"\nshape = \"sphere\"\nposition = [0, 0, 1]\nradius = 0\n"
      "power = 10\n";
  const Scene scene = load_ok(object_floor + point);
  EXPECT_EQ(scene.lights[0].shape, LightShape::sphere);
  EXPECT_EQ(scene.lights[0].radius, kPointLightRadius);
  const std::string disk =
      "[[light]]\nname = \"lamp\"\nshape = \"disk\"\nposition = [0, 0, 1]\n"
      "normal = [0, 0, -1]\nradius = 0\npower = 10\n";
  expect_error(object_floor + disk, "radius", "light 'lamp'", "'radius' must be a positive number");
}

TEST_F(SceneFile, NormalisesNormalAndOrthogonalisesUp) {
  std::string light = light_panel;
  light.replace(light.find("normal = [0, 0, -1]"), 19, "normal = [0, 0, -3]\nup = [0, 2, 2]");
  const Scene scene = load_ok(object_floor + light);
  EXPECT_TRUE(scene.lights[0].normal.isApprox(Vec3(0, 0, -1)));
  EXPECT_TRUE(scene.lights[0].up.isApprox(Vec3(0, 1, 0))) << scene.lights[0].up.transpose();
}

TEST_F(SceneFile, DefaultUpAvoidsNormalAlongY) {
  std::string light = light_panel;
  light.replace(light.find("normal = [0, 0, -1]"), 19, "normal = [0, -1, 0]");
  const Scene scene = load_ok(object_floor + light);
  EXPECT_EQ(scene.lights[0].up, Vec3(0, 0, 1));
}

TEST_F(SceneFile, RejectsUpParallelToNormalAndZeroNormal) {
  expect_error(object_floor + light_panel + "up = [0, 0, 5]\n", "up =", "light 'panel'",
               "'up' must not be parallel to 'normal'");
  std::string light = light_panel;
  light.replace(light.find("normal = [0, 0, -1]"), 19, "normal = [0, 0, 0]");
  expect_error(object_floor + light, "normal", "light 'panel'", "'normal'");
}

TEST_F(SceneFile, RejectsBadColorAndPower) {
  expect_error(object_floor + light_panel + "color = [0, 0, 0]\n", "color", "light 'panel'",
               "'color'");
  expect_error(object_floor + light_panel + "color = [1, -1, 1]\n", "color", "light 'panel'",
               "'color'");
  for (const char* power : {"0", "-5", "inf", "nan", "\"100\""}) {
    std::string light = light_panel;
    light.replace(light.find("100.0"), 5, power);
    expect_error(object_floor + light, "power", "light 'panel'", "'power'");
  }
}

TEST_F(SceneFile, RejectsBadTransformKeys) {
  expect_error(object_floor + "scale = [1, 0, 1]\n" + light_panel, "scale", "object 'floor'",
               "'scale'");
  expect_error(object_floor + "translate = [1, 2]\n" + light_panel, "translate", "object 'floor'",
               "'translate'");
  expect_error(object_floor + "rotate_deg = [0, nan, 0]\n" + light_panel, "rotate_deg",
               "object 'floor'", "'rotate_deg'");
  expect_error(object_floor + "receiver = \"yes\"\n" + light_panel, "receiver", "object 'floor'",
               "'receiver'");
}

TEST_F(SceneFile, RejectsSceneWithoutLightsObjectsOrReceivers) {
  const std::string file = (dir_ / "scene.toml").string();
  EXPECT_EQ(error_of(object_floor).rfind(file + ": scene: no light: no [[light]] table", 0), 0u);
  EXPECT_EQ(error_of(light_panel).rfind(file + ": scene: no [[object]]", 0), 0u);
  EXPECT_EQ(error_of(object_floor + "receiver = false\n" + light_panel)
                .rfind(file + ": scene: no object has 'receiver' = true", 0),
            0u);
}

// Ambient occlusion needs no light, and is its method's only quantity: either key implies the
// other, and the two set apart are an error at the quantity's line.
TEST_F(SceneFile, AmbientOcclusionNeedsNoLightAndPairsQuantityWithMethod) {
  Scene ao =
      load_ok("[bake]\nquantity = \"ambient-occlusion\"\nao_distance = 0.5\n" + object_floor);
  EXPECT_EQ(ao.bake.quantity, Quantity::ambient_occlusion);
  EXPECT_EQ(ao.bake.method, "ambient-occlusion");
  EXPECT_EQ(ao.bake.ao_distance, 0.5);
  EXPECT_TRUE(ao.lights.empty());
  ao = load_ok("[bake]\nmethod = \"ambient-occlusion\"\n" + object_floor + light_panel);
  EXPECT_EQ(ao.bake.quantity, Quantity::ambient_occlusion);
  EXPECT_EQ(ao.bake.ao_distance, 10.0);  // Blender's default
  expect_error("[bake]\nmethod = \"reference\"\nquantity = \"ambient-occlusion\"\n" + object_floor,
               "quantity", "[bake]", "do not go together");
  expect_error("[bake]\nquantity = \"irradiance\"\nmethod = \"ambient-occlusion\"\n" +
                   object_floor + light_panel,
               "quantity", "[bake]", "'ambient-occlusion'");
  expect_error("[bake]\nao_distance = -1\n" + object_floor + light_panel, "ao_distance", "[bake]",
               "'ao_distance'");
  // Any other quantity still needs a light.
  EXPECT_NE(error_of("[bake]\nquantity = \"irradiance\"\n" + object_floor).find("no light"),
            std::string::npos);
}

TEST_F(SceneFile, RejectsTableWhereArrayOfTablesIsExpected) {
  const std::string text = "[object]\nname = \"floor\"\nmesh = \"m.obj\"\n" + light_panel;
  expect_error(text, "[object]", "top level", "[[object]]");
}

TEST_F(SceneFile, KeepsErrorsOnOneLine) {
  std::string light = light_panel;
  light.replace(light.find("\"panel\""), 7, "\"pa\\nnel\"");
  const std::string message = error_of(object_floor + light + "colour = [1, 1, 1]\n");
  EXPECT_NE(message.find("light 'pa\\nnel': unknown key 'colour'"), std::string::npos) << message;
}

TEST_F(SceneFile, NamesShapesAndQuantities) {
  EXPECT_STREQ(to_string(Quantity::visibility), "visibility");
  EXPECT_STREQ(to_string(Quantity::irradiance), "irradiance");
  EXPECT_STREQ(to_string(LightShape::rectangle), "rectangle");
  EXPECT_STREQ(to_string(LightShape::disk), "disk");
  EXPECT_STREQ(to_string(LightShape::sphere), "sphere");
}

TEST(Transform, IsIdentityForDefaults) {
  EXPECT_TRUE(
      object_transform(Vec3::Zero(), Vec3::Zero(), Vec3::Ones()).isApprox(Affine3::Identity()));
}

TEST(Transform, ScalesThenRotatesThenTranslates) {
  const Affine3 t = object_transform(Vec3(10, 0, 0), Vec3(0, 0, 90), Vec3(2, 1, 1));
  // (1, 0, 0) scaled to (2, 0, 0), turned 90 degrees about Z to (0, 2, 0), moved to (10, 2, 0).
  const Vec3 p = t * Vec3(1, 0, 0);
  EXPECT_NEAR((p - Vec3(10, 2, 0)).norm(), 0.0, 1e-12) << p.transpose();
  // Rotating before scaling would have given (10, 1, 0).
}

TEST(Transform, RotatesAboutXThenYThenZ) {
  const Vec3 angles(90, 90, 0);
  const Mat3 x_then_y = (Eigen::AngleAxisd(90 * degrees, Vec3::UnitY()) *
                         Eigen::AngleAxisd(90 * degrees, Vec3::UnitX()))
                            .toRotationMatrix();
  const Mat3 y_then_x = (Eigen::AngleAxisd(90 * degrees, Vec3::UnitX()) *
                         Eigen::AngleAxisd(90 * degrees, Vec3::UnitY()))
                            .toRotationMatrix();
  const Affine3 t = object_transform(Vec3::Zero(), angles, Vec3::Ones());
  EXPECT_TRUE(t.linear().isApprox(x_then_y));
  EXPECT_FALSE(t.linear().isApprox(y_then_x));
  // Z (0, 0, 1) goes to (0, -1, 0) about X, then to (0, -1, 0) about Y.
  EXPECT_NEAR((t * Vec3(0, 0, 1) - Vec3(0, -1, 0)).norm(), 0.0, 1e-12);

  const Vec3 r(30, -45, 60);
  const Mat3 blender = (Eigen::AngleAxisd(r.z() * degrees, Vec3::UnitZ()) *
                        Eigen::AngleAxisd(r.y() * degrees, Vec3::UnitY()) *
                        Eigen::AngleAxisd(r.x() * degrees, Vec3::UnitX()))
                           .toRotationMatrix();
  const Vec3 s(1, 2, 3);
  const Affine3 full = object_transform(Vec3(4, 5, 6), r, s);
  EXPECT_TRUE(full.linear().isApprox(blender * s.asDiagonal()));
  EXPECT_TRUE(full.translation().isApprox(Vec3(4, 5, 6)));
}

TEST_F(SceneFile, ReadsTheOutputTableAndTheDensityKeys) {
  const std::string text =
      "[bake]\ntexels_per_metre = 32\n[output]\nencoding = \"rgbm-png\"\n"
      "per_light = true\nshadowmask = true\nshadowmask_encoding = \"half-exr\"\n"
      "atlas = { size = 1024, padding = 3 }\ngltf = true\n" +
      object_floor + "lightmap_scale = 0.5\n" + light_panel + "shadowmask_range = 4.5\n";
  const Scene scene = load_ok(text);
  EXPECT_EQ(scene.bake.texels_per_metre, 32);
  EXPECT_EQ(scene.objects[0].lightmap_scale, 0.5);
  EXPECT_EQ(scene.lights[0].shadowmask_range, 4.5);
  const OutputSettings& o = scene.output;
  EXPECT_EQ(o.encoding, Encoding::rgbm_png);
  EXPECT_TRUE(o.per_light);
  EXPECT_TRUE(o.shadowmask);
  EXPECT_EQ(o.shadowmask_encoding, Encoding::half_exr);
  ASSERT_TRUE(o.atlas);
  EXPECT_EQ(o.atlas->size, 1024);
  EXPECT_EQ(o.atlas->padding, 3);
  EXPECT_TRUE(o.gltf);

  // Defaults: one EXR per receiver, nothing else; `atlas = true` takes the default atlas, and
  // [output.atlas] is the same table.
  const Scene plain = load_ok(object_floor + light_panel);
  EXPECT_EQ(plain.output.encoding, Encoding::linear_exr);
  EXPECT_FALSE(plain.output.atlas || plain.output.per_light || plain.output.shadowmask ||
               plain.output.gltf);
  EXPECT_TRUE(std::isinf(plain.lights[0].shadowmask_range));
  EXPECT_EQ(load_ok("[output]\natlas = true\n" + object_floor + light_panel).output.atlas->size,
            2048);
  EXPECT_EQ(load_ok("[output.atlas]\nsize = 512\n" + object_floor + light_panel).output.atlas->size,
            512);
}

TEST_F(SceneFile, RejectsBadOutputKeys) {
  expect_error("[output]\natlas = { size = 1024, paddng = 2 }\n" + object_floor + light_panel,
               "paddng", "[output] atlas", "unknown key 'paddng' (known: size, padding)");
  expect_error("[output]\natlas = 2048\n" + object_floor + light_panel, "atlas = 2048", "[output]",
               "'atlas' must be a table such as { size = 2048, padding = 2 }, or true");
  expect_error("[output]\ngltf = \"yes\"\n" + object_floor + light_panel, "gltf", "[output]",
               "'gltf' must be true or false");
  expect_error("output = 3\n" + object_floor + light_panel, "output = 3", "top level",
               "'output' must be a table, written [output]");
  expect_error("[bake]\ntexels_per_metre = 0\n" + object_floor + light_panel, "texels_per_metre",
               "[bake]", "'texels_per_metre' must be a number > 0");
}

}  // namespace
}  // namespace sb

namespace sb {
namespace {

// A light's reach: `range` on a [[light]] (its shadow mask's reach follows it unless given), and
// [bake] irradiance_floor; a range that is not a finite number > 0, or one on a sun or a sky, is an
// error naming the light.
TEST_F(SceneFile, ReadsARangeAndTheIrradianceFloor) {
  const Scene scene = load_ok("[bake]\nirradiance_floor = 0.02\n" + object_floor + light_bulb +
                              "range = 7.5\n" + light_panel + "range = 3\nshadowmask_range = 2\n");
  EXPECT_EQ(scene.bake.irradiance_floor, 0.02);
  EXPECT_EQ(scene.lights[0].range, 7.5);
  EXPECT_EQ(scene.lights[0].shadowmask_range, 7.5);
  EXPECT_EQ(scene.lights[1].range, 3);
  EXPECT_EQ(scene.lights[1].shadowmask_range, 2);
  const Scene plain = load_ok(object_floor + light_bulb);
  EXPECT_TRUE(std::isinf(plain.lights[0].range));
  EXPECT_EQ(plain.bake.irradiance_floor, 0);
  for (const char* bad : {"0", "-2", "nan", "inf", "\"far\""})
    expect_error(object_floor + light_bulb + "range = " + bad + "\n", "range", "light 'bulb'",
                 "'range' must be a finite number > 0");
  const std::string sun =
      "[[light]]\nname = \"sun\"\nshape = \"sun\"\ndirection = [0, 0, -1]\nirradiance = 1\n";
  expect_error(object_floor + sun + "range = 5\n", "range", "light 'sun'",
               "'range' does not apply to a sun");
  expect_error("[bake]\nirradiance_floor = -1\n" + object_floor + light_bulb, "irradiance_floor",
               "[bake]", "'irradiance_floor' must be a number >= 0");
}

}  // namespace
}  // namespace sb
