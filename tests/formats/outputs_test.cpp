// Tests of the files a bake writes for engines (src/formats/outputs.h), on the hall of the
// corpus: each light's own file is that light alone; six lights that meet fill a shadow mask's
// four channels, the same way on every run, and the two left out are named; 26 receivers pack
// into at most two 2048² atlases where no bilinear filter on one receiver's triangles reads
// another's texels; every encoding decodes to the lightmap by the manifest's formula.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/image_io.h"
#include "formats/manifest.h"
#include "formats/outputs.h"
#include "lightmaps/encodings.h"
#include "pipeline/bake.h"
#include "pipeline/receiver_stages.h"
#include "scene/mesh.h"

namespace sb {
namespace {

namespace fs = std::filesystem;

Scene hall(const std::string& file) {
  auto scene = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/hall/" + file);
  EXPECT_TRUE(scene) << scene.error().message;
  if (!scene) throw std::runtime_error(scene.error().message);
  return *scene;
}

class Outputs : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("shadowbake_outputs_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Bakes `scene` and writes its files into dir_/name; the bake's result.
  BakeResult bake_into(const Scene& scene, const std::string& name) {
    auto result = bake(scene);
    EXPECT_TRUE(result) << result.error().message;
    if (!result) throw std::runtime_error(result.error().message);
    auto folder = OutputFolder::open(dir_ / name);
    EXPECT_TRUE(folder) << folder.error().message;
    Status written = write_outputs(*folder, scene, scene.bake, *result);
    EXPECT_TRUE(written) << written.error().message;
    return std::move(*result);
  }

  Image read(const std::string& name, const std::string& file) {
    auto image = read_image(dir_ / name / file);
    EXPECT_TRUE(image) << image.error().message;
    if (!image) throw std::runtime_error(image.error().message);
    return std::move(*image);
  }

  Manifest manifest(const std::string& name) {
    auto m = read_manifest(dir_ / name);
    EXPECT_TRUE(m) << m.error().message;
    if (!m) throw std::runtime_error(m.error().message);
    return std::move(*m);
  }

  std::string bytes(const std::string& name, const std::string& file) {
    std::ifstream in(dir_ / name / file, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  }

  fs::path dir_;
};

// The six-light hall, small and quick.
Scene six_lights() {
  Scene scene = hall("scene_six_lights.toml");
  scene.bake.resolution = 64;
  scene.bake.samples = 4;
  return scene;
}

TEST_F(Outputs, EachLightsFileIsThatLightAlone) {
  const Scene scene = six_lights();
  bake_into(scene, "all");
  const Manifest all = manifest("all");
  for (const std::size_t l : {std::size_t(0), std::size_t(4)}) {
    Scene alone = scene;
    alone.lights = {scene.lights[l]};
    alone.output = {};
    bake_into(alone, "alone");
    const Manifest one = manifest("alone");
    for (std::size_t r = 0; r < all.receivers.size(); ++r) {
      const ManifestFiles& files = *all.receivers[r].files;
      ASSERT_EQ(files.per_light.size(), scene.lights.size());
      EXPECT_EQ(files.per_light[l].first, scene.lights[l].name);
      const Image per_light = read("all", files.per_light[l].second.file);
      const Image single = read("alone", one.receivers[r].files->lightmap.file);
      ASSERT_EQ(per_light.pixels.size(), single.pixels.size());
      double worst = 0;
      for (std::size_t i = 0; i < single.pixels.size(); ++i)
        worst = std::max(worst, double(std::abs(per_light.pixels[i] - single.pixels[i])));
      EXPECT_LE(worst, 1e-6) << all.receivers[r].name << ", light " << scene.lights[l].name;
    }
  }
}

TEST_F(Outputs, SixOverlappingLightsFillTheMaskAndTheTwoLeftOutAreNamed) {
  const Scene scene = six_lights();
  const BakeResult result = bake_into(scene, "first");
  EXPECT_EQ(result.shadowmask_channels, (std::vector<int>{0, 1, 2, 3, -1, -1}));
  std::vector<std::string> left_out;
  for (const std::string& w : result.warnings)
    if (w.find("no shadow-mask channel is free") != std::string::npos) left_out.push_back(w);
  ASSERT_EQ(left_out.size(), 2u);
  EXPECT_NE(left_out[0].find("light 'sconce_north'"), std::string::npos) << left_out[0];
  EXPECT_NE(left_out[1].find("light 'sconce_west'"), std::string::npos) << left_out[1];
  const Manifest m = manifest("first");
  ASSERT_EQ(m.lights.size(), 6u);
  EXPECT_EQ(m.lights[3].shadowmask_channel, 3);
  EXPECT_EQ(m.lights[5].shadowmask_channel, -1);

  // Channel c of every receiver's mask is its light's visibility, in 8 bits: the per-light
  // file's value where the light reaches the texel, 1 where it does not.
  std::int64_t shadowed = 0;
  for (const ManifestReceiver& r : m.receivers) {
    const Image mask = read("first", r.files->shadowmask->file);
    const Image coverage = read("first", r.files->coverage.file);
    ASSERT_EQ(mask.channels, 4);
    for (int l = 0; l < 4; ++l) {
      const Image light = read("first", r.files->per_light[std::size_t(l)].second.file);
      for (std::size_t t = 0; t < coverage.pixels.size(); ++t) {
        if (coverage.pixels[t] < 0.5f) continue;
        const double in_mask = mask.pixels[4 * t + std::size_t(l)];
        const double v = light.pixels[3 * t];
        if (v > 0) {
          EXPECT_NEAR(in_mask, v, 0.5 / 255 + 1e-6) << r.name << " texel " << t;
        } else {
          EXPECT_TRUE(in_mask == 0.0 || in_mask == 1.0) << r.name << " texel " << t;
        }
        shadowed += in_mask < 0.5;
      }
    }
  }
  EXPECT_GT(shadowed, 100);

  // A rerun gives the same channels and the same mask bytes.
  const BakeResult again = bake_into(scene, "second");
  EXPECT_EQ(again.shadowmask_channels, result.shadowmask_channels);
  for (const ManifestReceiver& r : m.receivers)
    EXPECT_EQ(bytes("first", r.files->shadowmask->file), bytes("second", r.files->shadowmask->file))
        << r.name;
}

TEST_F(Outputs, TwentySixReceiversPackIntoAtlasesNoFilterReadsAnother) {
  Scene scene = hall("scene_level.toml");
  scene.bake.samples = 1;
  scene.output.per_light = false;
  scene.output.gltf = false;
  const BakeResult result = bake_into(scene, "level");
  const Manifest m = manifest("level");
  ASSERT_EQ(m.receivers.size(), 26u);
  ASSERT_GE(m.atlases.size(), 1u);
  EXPECT_LE(m.atlases.size(), 2u);
  for (const ManifestAtlas& a : m.atlases) EXPECT_LE(a.size, 2048);

  // Each receiver's padded rectangle: its own, inside its atlas, apart from every other.
  const int pad = scene.output.atlas->padding;
  struct Rect {
    int atlas, x0, y0, x1, y1;  // texels, half-open
  };
  std::vector<Rect> rects;
  for (const ManifestReceiver& r : m.receivers) {
    ASSERT_TRUE(r.atlas) << r.name;
    const ManifestAtlasPlacement& p = *r.atlas;
    rects.push_back({p.index, p.x - pad, p.y - pad, p.x + p.side + pad, p.y + p.side + pad});
  }
  for (std::size_t i = 0; i < rects.size(); ++i)
    for (std::size_t j = i + 1; j < rects.size(); ++j) {
      const Rect &a = rects[i], &b = rects[j];
      EXPECT_TRUE(a.atlas != b.atlas || a.x1 <= b.x0 || b.x1 <= a.x0 || a.y1 <= b.y0 ||
                  b.y1 <= a.y0)
          << m.receivers[i].name << " and " << m.receivers[j].name << " overlap";
    }

  // Every point of every triangle, through the manifest's scale and offset as an engine applies
  // them, is filtered (bilinear: the 2 × 2 texels around it) from texels of its own rectangle
  // only; and the atlas holds the receiver's own values there.
  std::vector<Image> atlases;
  for (const ManifestAtlas& a : m.atlases) atlases.push_back(read("level", a.files.lightmap.file));
  std::size_t receiver = 0;
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const ObjectDesc& obj = scene.objects[i];
    auto mesh = import_mesh(obj, scene.file);
    ASSERT_TRUE(mesh) << mesh.error().message;
    const ManifestAtlasPlacement& p = *m.receivers[receiver].atlas;
    const Rect& own = rects[receiver];
    const int size = m.atlases[std::size_t(p.index)].size;
    const auto& so = p.scale_offset;
    int outside = 0;
    for (auto f : mesh->mesh.faces()) {
      const Triangle t = triangle(mesh->mesh, f);
      for (const auto& w :
           {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(0.5, 0.5, 0), Vec3(0, 0.5, 0.5),
            Vec3(0.5, 0, 0.5), Vec3(1.0 / 3, 1.0 / 3, 1.0 / 3)}) {
        const Vec2 uv = w[0] * t.uv[0] + w[1] * t.uv[1] + w[2] * t.uv[2];
        const double au = uv.x() * so[0] + so[2], av = uv.y() * so[1] + so[3];  // v up
        const double x = au * size - 0.5, y = (1.0 - av) * size - 0.5;  // texel centres at .5
        const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
        for (const int tx : {x0, x0 + 1})
          for (const int ty : {y0, y0 + 1})
            outside += tx < own.x0 || tx >= own.x1 || ty < own.y0 || ty >= own.y1;
      }
    }
    EXPECT_EQ(outside, 0) << obj.name;
    const Image& own_image = result.receivers[receiver].image;
    const Image& atlas = atlases[std::size_t(p.index)];
    double worst = 0;
    for (int y = 0; y < p.side; ++y)
      for (int x = 0; x < p.side; ++x)
        for (int c = 0; c < 3; ++c)
          worst = std::max(worst,
                           double(std::abs(atlas.at(p.x + x, p.y + y)[c] - own_image.at(x, y)[c])));
    EXPECT_EQ(worst, 0.0) << obj.name;
    ++receiver;
  }
}

// A level's world is Y up, glTF's frame (docs/scene-format.md), so its receivers go into the
// glTF output where the level has them; a scene file's Z-up world is turned to Y up.
TEST_F(Outputs, TheGltfOutputKeepsALevelsYUpWorld) {
  for (const char* file : {"/scenes/level/scene.toml", "/scenes/showcase/scene.toml"}) {
    Scene scene = load_scene(std::string(SB_SOURCE_DIR) + file).value();
    const bool level = std::string(file).find("level") != std::string::npos;
    scene.bake.resolution = 32;
    scene.bake.samples = 1;
    scene.output.gltf = true;
    const auto meshes = load_meshes(scene, nullptr);
    ASSERT_TRUE(meshes) << meshes.error().message;
    const auto result = bake(scene, {});
    ASSERT_TRUE(result) << result.error().message;
    const ReceiverBake& r = result->receivers.at(0);
    ASSERT_TRUE(r.gltf_mesh);
    const Mesh& mesh = meshes->at(r.object);
    const auto p = mesh.mesh.point(*mesh.mesh.vertices_begin());
    const std::vector<float>& out = r.gltf_mesh->positions;
    const std::array<double, 3> expected =
        level ? std::array<double, 3>{p[0], p[1], p[2]} : std::array<double, 3>{p[0], p[2], -p[1]};
    for (int k = 0; k < 3; ++k)
      EXPECT_FLOAT_EQ(out[std::size_t(k)], float(expected[std::size_t(k)])) << file << " " << k;
  }
}

TEST_F(Outputs, EveryEncodingDecodesToTheLightmap) {
  Scene scene = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/showcase/scene.toml").value();
  scene.bake.resolution = 48;
  scene.bake.samples = 4;
  scene.bake.quantity = Quantity::irradiance;
  bake_into(scene, "float");
  const Manifest reference = manifest("float");
  for (const Encoding e : {Encoding::half_exr, Encoding::png, Encoding::rgbm_png}) {
    scene.output.encoding = e;
    bake_into(scene, to_string(e));
    const Manifest m = manifest(to_string(e));
    for (std::size_t r = 0; r < m.receivers.size(); ++r) {
      const ManifestFile& file = m.receivers[r].files->lightmap;
      EXPECT_EQ(file.encoding, e);
      const Image truth = read("float", reference.receivers[r].files->lightmap.file);
      Image stored = read(to_string(e), file.file);
      Image decoded = e == Encoding::rgbm_png ? decode_rgbm(stored, file.scale) : stored;
      if (e == Encoding::png)
        for (float& v : decoded.pixels) v = float(v * file.scale);
      double peak = 0, worst = 0;
      for (float v : truth.pixels) peak = std::max(peak, double(v));
      for (std::size_t i = 0; i < truth.pixels.size(); ++i)
        worst = std::max(worst, double(std::abs(decoded.pixels[i] - truth.pixels[i])));
      // Half: 11 bits; 8-bit PNG: half a step of the scale; RGBM: half a step of the texel's
      // multiplier, at most the range's.
      const double bound = e == Encoding::half_exr ? peak * 1e-3
                           : e == Encoding::png    ? 0.5 / 255 * file.scale + 1e-6
                                                   : 0.5 / 255 * kRgbmRange * file.scale;
      EXPECT_LE(worst, bound) << to_string(e) << " " << m.receivers[r].name;
      EXPECT_GT(peak, 1.0);  // irradiance, not visibility
    }
  }
}

TEST_F(Outputs, PerLightNamesMustMakeFileNames) {
  Scene scene = six_lights();
  scene.lights[2].name = "ceiling panel";
  const Status s = check_output_names(scene);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find(":" + std::to_string(scene.lights[2].line) +
                                   ": light 'ceiling panel': [output] per_light names a file"),
            std::string::npos)
      << s.error().message;
  // A light called "coverage" would write every receiver's coverage mask (PNG encoding).
  scene.lights[2].name = "coverage";
  scene.output.encoding = Encoding::png;
  const Status clash = check_output_names(scene);
  ASSERT_FALSE(clash);
  EXPECT_NE(clash.error().message.find("its output file 'floor.coverage.png' is also a file of"),
            std::string::npos)
      << clash.error().message;
}

}  // namespace
}  // namespace sb
