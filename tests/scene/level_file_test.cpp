// Levels (scene/level_file.h): a whole glTF baked with no scene file, its nodes as objects and its
// lights as lights, checked on scenes/level (Blender's export) and on small hand-written files.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "pipeline/bake.h"
#include "scene/level_file.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "scene/scene.h"
#include "scene/sun_light.h"

namespace sb {
namespace {

namespace fs = std::filesystem;

const fs::path kLevel = fs::path(SB_SOURCE_DIR) / "scenes" / "level" / "level.glb";

const ObjectDesc* object_named(const Scene& scene, const std::string& name) {
  for (const ObjectDesc& o : scene.objects)
    if (o.name == name) return &o;
  return nullptr;
}

const LightDesc* light_named(const Scene& scene, const std::string& name) {
  for (const LightDesc& l : scene.lights)
    if (l.name == name) return &l;
  return nullptr;
}

bool any_warning_has(const std::vector<std::string>& warnings, const std::string& text) {
  return std::any_of(warnings.begin(), warnings.end(),
                     [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

TEST(LevelFile, BlendersExportBecomesObjectsAndLights) {
  auto scene = load_scene(kLevel);
  ASSERT_TRUE(scene) << scene.error().message;
  std::vector<std::string> names;
  for (const ObjectDesc& o : scene->objects) names.push_back(o.name);
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"back_wall", "book_a", "book_b", "chair_a", "chair_b",
                                             "floor", "shelf", "side_wall", "table"}));
  for (const ObjectDesc& o : scene->objects) {
    EXPECT_TRUE(o.receiver && o.blocker) << o.name;
    EXPECT_EQ(o.uv_channel, 1) << o.name << ": the second UV set is the lightmap's";
    EXPECT_FALSE(o.auto_uv) << o.name;
    EXPECT_GE(o.node, 0) << o.name;
  }
  // Blender's Z-up (x, y, z) is glTF's (x, z, -y). The ceiling panel: a 1 × 0.5 m quad at
  // (0.4, 0.3, 2.4) facing down, emission (1, 0.95, 0.85) × 6, so 0.5 m² × π × 6 W.
  const LightDesc* panel = light_named(*scene, "ceiling_panel");
  ASSERT_NE(panel, nullptr);
  EXPECT_EQ(panel->shape, LightShape::rectangle);
  EXPECT_LT((panel->position - Vec3(0.4, 2.4, -0.3)).norm(), 1e-5);
  EXPECT_LT((panel->normal - Vec3(0, -1, 0)).norm(), 1e-6);
  EXPECT_NEAR(panel->width * panel->height, 0.5, 1e-5);
  EXPECT_NEAR(std::max(panel->width, panel->height), 1.0, 1e-5);
  EXPECT_NEAR(panel->power, std::numbers::pi * 6 * 0.5, 1e-3);
  EXPECT_LT((panel->color - Vec3(1, 0.95, 0.85)).norm(), 1e-6);
  // The disc: a 32-gon of radius 0.2 m at (-1.6, -1.2, 2.0), a disk of its own area.
  const LightDesc* disc = light_named(*scene, "disc_lamp");
  ASSERT_NE(disc, nullptr);
  EXPECT_EQ(disc->shape, LightShape::disk);
  EXPECT_LT((disc->position - Vec3(-1.6, 2.0, 1.2)).norm(), 1e-5);
  const double polygon_area = 16 * 0.2 * 0.2 * std::sin(2 * std::numbers::pi / 32);
  EXPECT_NEAR(disc->radius, std::sqrt(polygon_area / std::numbers::pi), 1e-5);
  EXPECT_LT((disc->normal - Vec3(0, -1, 0)).norm(), 1e-6);
  // The point light: 150 W at (1.6, -1.3, 1.8), written as 150 / 4π × 683 cd.
  const LightDesc* bulb = light_named(*scene, "bulb");
  ASSERT_NE(bulb, nullptr);
  EXPECT_EQ(bulb->shape, LightShape::sphere);
  EXPECT_LT((bulb->position - Vec3(1.6, 1.8, 1.3)).norm(), 1e-5);
  EXPECT_NEAR(bulb->power, 150, 1e-3);
  EXPECT_EQ(bulb->radius, kPointLightRadius);  // a point, as glTF's are
  // The spot: 300 W at (-1.4, 1.2, 2.4) pointing down, a 70° cone blended over 15 % of it
  // (Blender's spot_size and spot_blend, written as half-angles 35° and 29.75°).
  const LightDesc* spot = light_named(*scene, "spot");
  ASSERT_NE(spot, nullptr);
  EXPECT_LT((spot->spot_axis - Vec3(0, -1, 0)).norm(), 1e-6);
  EXPECT_NEAR(spot->spot_outer, 35 * std::numbers::pi / 180, 1e-6);
  EXPECT_NEAR(spot->spot_inner, 0.5192354463883326, 1e-6);
  EXPECT_NEAR(spot->power, 300, 1e-3);
  // The sun: 3 W/m² (written as 3 × 683 lux), Blender's rotation (40°, 0, 30°) of -Z, as a disk
  // of Blender's 0.526° seen from the room.
  const LightDesc* sun = light_named(*scene, "sun");
  ASSERT_NE(sun, nullptr);
  const double rx = 40 * std::numbers::pi / 180, rz = 30 * std::numbers::pi / 180;
  const Vec3 blender_direction(-std::sin(rz) * std::sin(rx), std::cos(rz) * std::sin(rx),
                               -std::cos(rx));
  const Vec3 direction(blender_direction.x(), blender_direction.z(), -blender_direction.y());
  EXPECT_LT((sun->normal - direction).norm(), 1e-6);
  const Vec3 floor_centre(0, 0, 0);
  const Light sun_light(*sun);
  EXPECT_NEAR(sun_light.unoccluded_irradiance(floor_centre, Vec3(0, 1, 0)).x(), 3 * -direction.y(),
              3e-3);
  EXPECT_EQ(scene->lights.size(), 5u);
  EXPECT_EQ(sun->sun_angle_deg, kSunAngleDeg);
  // Another angle keeps the sun's irradiance and widens its disk.
  LightDesc wider = *sun;
  set_sun_angle(wider, 2.0);
  EXPECT_NEAR(
      wider.radius / sun->radius,
      std::tan(std::numbers::pi / 180) / std::tan(kSunAngleDeg / 2 * std::numbers::pi / 180), 1e-9);
  EXPECT_NEAR(Light(wider).unoccluded_irradiance(floor_centre, Vec3(0, 1, 0)).x(),
              sun_light.unoccluded_irradiance(floor_centre, Vec3(0, 1, 0)).x(), 1e-3);
}

// scenes/level/lamp.glb: its emissive UV sphere and capped cylinder are neither rectangle nor
// disc, so mesh lights of their triangles (front sides outwards), at their centroids, of power
// π × emission × area; the bake takes each as its triangles (make_lights).
TEST(LevelFile, EmissiveMeshesOfOtherShapesAreMeshLights) {
  const fs::path file = fs::path(SB_SOURCE_DIR) / "scenes" / "level" / "lamp.glb";
  auto scene = load_scene(file);
  ASSERT_TRUE(scene) << scene.error().message;
  ASSERT_EQ(scene->lights.size(), 2u);
  const LightDesc* lantern = light_named(*scene, "lantern");
  const LightDesc* tube = light_named(*scene, "wall_tube");
  ASSERT_NE(lantern, nullptr);
  ASSERT_NE(tube, nullptr);
  EXPECT_EQ(lantern->shape, LightShape::mesh);
  EXPECT_EQ(tube->shape, LightShape::mesh);
  // 16 segments × 8 rings: 2 × 16 triangles at the poles, 6 × 16 quads between.
  EXPECT_EQ(lantern->corners.size(), 3u * (32 + 192));
  // 16 sides (32 triangles) and two 16-gon caps (14 each).
  EXPECT_EQ(tube->corners.size(), 3u * (32 + 28));
  // Blender's (0.1, 0.3, 1.6) is glTF's (0.1, 1.6, -0.3).
  EXPECT_LT((lantern->position - Vec3(0.1, 1.6, -0.3)).norm(), 1e-4);
  const Light whole(*lantern);
  EXPECT_NEAR(lantern->power, std::numbers::pi * 3 * whole.area(), 1e-6 * lantern->power);
  // Its area: a little less than the sphere's 4π r², and every triangle faces away from it.
  EXPECT_GT(whole.area(), 0.9 * 4 * std::numbers::pi * 0.25 * 0.25);
  EXPECT_LT(whole.area(), 4 * std::numbers::pi * 0.25 * 0.25);
  auto lights = make_lights(scene->lights, file);
  ASSERT_TRUE(lights) << lights.error().message;
  // The lantern's 192 quads between its rings become one light each, with its 32 pole
  // triangles; the tube's 16 sides likewise, and its two 16-gon caps, 14 triangles each, join
  // where two neighbours make a convex quad (18 parts of the 28, as its triangulation goes).
  std::size_t lantern_parts = 0, tube_parts = 0;
  for (const Light& l : *lights) (l.output() == 0 ? lantern_parts : tube_parts) += 1;
  EXPECT_EQ(lantern_parts, 96u + 32u);
  EXPECT_EQ(tube_parts, 16u + 18u);
  EXPECT_EQ(output_count(*lights), 2u);
  for (const Light& l : *lights) {
    const Vec3 out = l.centre() - (l.output() == 0 ? lantern->position : tube->position);
    EXPECT_GT(l.normal().dot(out), 0) << l.desc().name;
  }
  // Seen from below the lantern, it is near a sphere light of its radius and power.
  LightDesc sphere = *lantern;
  sphere.shape = LightShape::sphere;
  sphere.radius = 0.25;
  sphere.corners.clear();
  const Vec3 y = lantern->position - Vec3(0, 1.2, 0), n(0, 1, 0);
  double h0 = 0;
  for (const Light& l : *lights)
    if (l.output() == 0) h0 += l.unoccluded_irradiance(y, n).x();
  const double sphere_h0 = Light(sphere).unoccluded_irradiance(y, n).x();
  EXPECT_NEAR(h0, sphere_h0, 0.03 * sphere_h0);
}

// The level baked as one file equals the same objects baked one file per object
// (scenes/level/objects, each exported alone by Blender with its world transform): bit for bit
// where the node has no parent, and within float rounding of the composed transforms where it
// has (the shelf under the wall, the books under the shelf).
TEST(LevelFile, BakeEqualsOneFilePerObject) {
  auto level = load_scene(kLevel);
  ASSERT_TRUE(level) << level.error().message;
  level->bake.resolution = 64;
  level->bake.margin = 0;
  Scene per_object = *level;
  for (ObjectDesc& o : per_object.objects) {
    o.mesh = kLevel.parent_path() / "objects" / (o.name + ".glb");
    o.node = -1;
    o.parts.clear();
  }
  auto a = bake(*level);
  auto b = bake(per_object);
  ASSERT_TRUE(a) << a.error().message;
  ASSERT_TRUE(b) << b.error().message;
  ASSERT_EQ(a->receivers.size(), b->receivers.size());
  for (std::size_t r = 0; r < a->receivers.size(); ++r) {
    const Image& x = a->receivers[r].image;
    const Image& y = b->receivers[r].image;
    ASSERT_EQ(x.pixels.size(), y.pixels.size());
    float largest = 0;
    for (std::size_t i = 0; i < x.pixels.size(); ++i)
      largest = std::max(largest, std::abs(x.pixels[i] - y.pixels[i]));
    const std::string& name = a->receivers[r].name;
    const bool parented = name == "shelf" || name == "book_a" || name == "book_b";
    if (parented) {
      EXPECT_LT(largest, 1e-3) << name;
    } else {
      EXPECT_EQ(largest, 0) << name;
    }
  }
}

// The same room modelled in millimetres under a root scaled by 0.001, lit by its emissive panel
// alone: the level's transforms make it the metre room.
TEST(LevelFile, MillimetreLevelIsTheMetreLevel) {
  auto mm = load_scene(kLevel.parent_path() / "level_mm.glb");
  auto m = load_scene(kLevel);
  ASSERT_TRUE(mm) << mm.error().message;
  ASSERT_TRUE(m) << m.error().message;
  ASSERT_EQ(mm->lights.size(), 1u);
  const LightDesc& a = mm->lights[0];
  const LightDesc& b = *light_named(*m, "ceiling_panel");
  EXPECT_LT((a.position - b.position).norm(), 1e-6);
  EXPECT_NEAR(a.width, b.width, 1e-6);
  EXPECT_NEAR(a.power, b.power, 1e-4);
  for (const char* name : {"floor", "chair_b", "book_a"}) {
    const ObjectDesc* x = object_named(*mm, name);
    const ObjectDesc* y = object_named(*m, name);
    ASSERT_TRUE(x && y) << name;
    auto mx = import_mesh(*x, mm->file);
    auto my = import_mesh(*y, m->file);
    ASSERT_TRUE(mx && my) << name;
    ASSERT_EQ(mx->mesh.n_vertices(), my->mesh.n_vertices()) << name;
    double largest = 0;
    for (auto v : mx->mesh.vertices())
      largest = std::max(largest, (mx->mesh.point(v) - my->mesh.point(v)).norm());
    EXPECT_LT(largest, 1e-6) << name << ": metres";
  }
}

// The level exported by Blender as FBX is the glTF level: the same objects, lights and powers
// (FBX's light intensity is watts, glTF's candela), and a bake within float rounding of the
// transforms.
TEST(LevelFile, FbxExportIsTheGltfLevel) {
  auto fbx = load_scene(kLevel.parent_path() / "level.fbx");
  auto gltf = load_scene(kLevel);
  ASSERT_TRUE(fbx) << fbx.error().message;
  ASSERT_TRUE(gltf) << gltf.error().message;
  ASSERT_EQ(fbx->lights.size(), gltf->lights.size());
  for (const LightDesc& a : fbx->lights) {
    const LightDesc* b = light_named(*gltf, a.name);
    ASSERT_NE(b, nullptr) << a.name;
    EXPECT_EQ(a.shape, b->shape) << a.name;
    // (A sun's disk lies 10⁴ m off: its place carries the float rounding of its direction.)
    EXPECT_LT((a.position - b->position).norm(), 1e-5 + 1e-6 * b->position.norm()) << a.name;
    EXPECT_LT((a.normal - b->normal).norm(), 1e-6) << a.name;
    EXPECT_NEAR(a.power, b->power, 1e-3 * b->power) << a.name;
    EXPECT_LT((a.spot_axis - b->spot_axis).norm(), 1e-5) << a.name;
    EXPECT_NEAR(a.spot_outer, b->spot_outer, 1e-6) << a.name;
    EXPECT_NEAR(a.spot_inner, b->spot_inner, 1e-6) << a.name;
  }
  ASSERT_EQ(fbx->objects.size(), gltf->objects.size());
  fbx->bake.resolution = gltf->bake.resolution = 64;
  auto x = bake(*fbx);
  auto y = bake(*gltf);
  ASSERT_TRUE(x && y);
  for (const ReceiverBake& r : x->receivers) {
    const auto other = std::find_if(y->receivers.begin(), y->receivers.end(),
                                    [&](const ReceiverBake& o) { return o.name == r.name; });
    ASSERT_NE(other, y->receivers.end()) << r.name;
    float largest = 0;
    for (std::size_t i = 0; i < r.image.pixels.size(); ++i)
      largest = std::max(largest, std::abs(r.image.pixels[i] - other->image.pixels[i]));
    EXPECT_LT(largest, 2e-3) << r.name;
  }
}

// Small glTF files written here: one quad mesh (two triangles, normals +Z, one UV set) placed by
// the nodes given.
class HandWrittenLevel : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("sb_level_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static std::string base64(const std::vector<std::uint8_t>& bytes) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
      const std::uint32_t n = (std::uint32_t(bytes[i]) << 16) |
                              (i + 1 < bytes.size() ? std::uint32_t(bytes[i + 1]) << 8 : 0) |
                              (i + 2 < bytes.size() ? bytes[i + 2] : 0);
      out += table[(n >> 18) & 63];
      out += table[(n >> 12) & 63];
      out += i + 1 < bytes.size() ? table[(n >> 6) & 63] : '=';
      out += i + 2 < bytes.size() ? table[n & 63] : '=';
    }
    return out;
  }

  // A glTF of `nodes`, the quad as mesh 0 with material 0 of the given emissive factor (and
  // strength, when not 1), and the scene's root nodes.
  // `lights`, when given, is KHR_lights_punctual's array of lights, which nodes name by index.
  fs::path write(const nlohmann::json& nodes, const std::vector<int>& roots,
                 const std::vector<double>& emissive = {0, 0, 0}, double strength = 1,
                 double quad_size = 1, const nlohmann::json& lights = nullptr) {
    const float h = float(quad_size / 2);
    const float positions[] = {-h, -h, 0, h, -h, 0, h, h, 0, -h, h, 0};
    const float normals[] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    const float uvs[] = {0.1f, 0.1f, 0.9f, 0.1f, 0.9f, 0.9f, 0.1f, 0.9f};
    const std::uint16_t indices[] = {0, 1, 2, 0, 2, 3};
    std::vector<std::uint8_t> bytes(sizeof positions + sizeof normals + sizeof uvs +
                                    sizeof indices);
    std::uint8_t* at = bytes.data();
    for (const auto& [data, size] :
         {std::pair<const void*, std::size_t>{positions, sizeof positions},
          {normals, sizeof normals},
          {uvs, sizeof uvs},
          {indices, sizeof indices}}) {
      std::memcpy(at, data, size);
      at += size;
    }
    nlohmann::json material = {{"name", "m"}, {"emissiveFactor", emissive}};
    if (strength != 1)
      material["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] = strength;
    nlohmann::json primitive;
    primitive["attributes"] = {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}};
    primitive["indices"] = 3;
    primitive["material"] = 0;
    nlohmann::json gltf;
    gltf["asset"]["version"] = "2.0";
    gltf["scene"] = 0;
    gltf["scenes"] = nlohmann::json::array({{{"nodes", roots}}});
    gltf["nodes"] = nodes;
    gltf["materials"] = nlohmann::json::array({material});
    gltf["meshes"] = nlohmann::json::array({{{"primitives", nlohmann::json::array({primitive})}}});
    gltf["buffers"] =
        nlohmann::json::array({{{"byteLength", bytes.size()},
                                {"uri", "data:application/octet-stream;base64," + base64(bytes)}}});
    const auto view = [](int offset, int length) {
      return nlohmann::json{{"buffer", 0}, {"byteOffset", offset}, {"byteLength", length}};
    };
    gltf["bufferViews"] =
        nlohmann::json::array({view(0, 48), view(48, 48), view(96, 32), view(128, 12)});
    const auto accessor = [](int view, int type, int count, const char* shape) {
      return nlohmann::json{
          {"bufferView", view}, {"componentType", type}, {"count", count}, {"type", shape}};
    };
    nlohmann::json position = accessor(0, 5126, 4, "VEC3");
    position["min"] = {-h, -h, 0};
    position["max"] = {h, h, 0};
    gltf["accessors"] =
        nlohmann::json::array({position, accessor(1, 5126, 4, "VEC3"), accessor(2, 5126, 4, "VEC2"),
                               accessor(3, 5123, 6, "SCALAR")});
    if (strength != 1) gltf["extensionsUsed"] = {"KHR_materials_emissive_strength"};
    if (!lights.is_null()) {
      gltf["extensions"]["KHR_lights_punctual"]["lights"] = lights;
      gltf["extensionsUsed"] = {"KHR_lights_punctual"};
    }
    const fs::path file = dir_ / "level.gltf";
    std::ofstream(file) << gltf.dump(1);
    return file;
  }

  fs::path dir_;
};

TEST_F(HandWrittenLevel, RepeatedNamesTakeTheirParentsPath) {
  const nlohmann::json nodes = {
      {{"name", "shelf_a"}, {"children", {2}}, {"translation", {0, 0, 1}}},
      {{"name", "shelf_b"}, {"children", {3}}, {"translation", {0, 0, 2}}},
      {{"name", "book"}, {"mesh", 0}},
      {{"name", "book"}, {"mesh", 0}, {"translation", {1, 0, 0}}},
      {{"name", "book"}, {"mesh", 0}, {"translation", {3, 0, 0}}},
      {{"name", "book"}, {"mesh", 0}, {"translation", {4, 0, 0}}}};
  const fs::path file = write(nodes, {0, 1, 4, 5});
  auto level = import_level(file, Affine3::Identity(), 0);
  ASSERT_TRUE(level) << level.error().message;
  std::vector<std::string> names;
  for (const ObjectDesc& o : level->objects) names.push_back(o.name);
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"book", "book-2", "shelf_a-book", "shelf_b-book"}));
  EXPECT_TRUE(any_warning_has(level->warnings, "node 'book': another node has the same name"));
  // Each instance of the one mesh is its own object at its own place. With no second UV set,
  // the bake makes their lightmap UVs; channel 0 stays their texture UVs.
  for (const ObjectDesc& o : level->objects) {
    EXPECT_TRUE(o.auto_uv) << o.name;
    EXPECT_EQ(o.uv_channel, 0) << o.name;
    auto mesh = import_mesh(o, file);
    ASSERT_TRUE(mesh) << mesh.error().message;
    EXPECT_EQ(mesh->mesh.n_faces(), 2u);
  }
}

TEST_F(HandWrittenLevel, EmissiveQuadIsARectangleLightWithItsStrength) {
  const nlohmann::json nodes = {
      {{"name", "panel"},
       {"mesh", 0},
       {"translation", {0, 3, 0}},
       {"rotation", {0.7071067811865476, 0, 0, 0.7071067811865476}}},  // +Z turned to -Y
      {{"name", "floor"},
       {"mesh", 0},
       {"rotation", {-0.7071067811865476, 0, 0, 0.7071067811865476}},
       {"scale", {4, 4, 4}}}};
  // The floor shares the emissive mesh: it is a light too, and the level has no object.
  const fs::path file = write(nodes, {0, 1}, {1, 0.5, 0.25}, 8, 0.5);
  auto level = import_level(file, Affine3::Identity(), 0);
  ASSERT_TRUE(level) << level.error().message;
  ASSERT_EQ(level->lights.size(), 2u);
  const LightDesc& panel = level->lights[0];
  EXPECT_EQ(panel.name, "panel");
  EXPECT_EQ(panel.shape, LightShape::rectangle);
  EXPECT_LT((panel.position - Vec3(0, 3, 0)).norm(), 1e-6);
  EXPECT_LT((panel.normal - Vec3(0, -1, 0)).norm(), 1e-6);
  EXPECT_NEAR(panel.width, 0.5, 1e-6);
  EXPECT_NEAR(panel.height, 0.5, 1e-6);
  EXPECT_NEAR(panel.power, std::numbers::pi * 8 * 0.25, 1e-5);  // π L A, L = 8 W/(m² sr)
  EXPECT_LT((panel.color - Vec3(1, 0.5, 0.25)).norm(), 1e-6);
  EXPECT_NEAR(level->lights[1].width, 2.0, 1e-6);
  EXPECT_TRUE(level->objects.empty());
  auto scene = load_level_scene(file);
  ASSERT_FALSE(scene);
  EXPECT_NE(scene.error().message.find("no node places a mesh"), std::string::npos)
      << scene.error().message;
}

TEST_F(HandWrittenLevel, BadNodesAndEmissionAreOneLineErrors) {
  {  // a node that is its own grandchild
    const nlohmann::json nodes = {{{"name", "a"}, {"children", {1}}, {"mesh", 0}},
                                  {{"name", "b"}, {"children", {0}}}};
    auto level = import_level(write(nodes, {0}), Affine3::Identity(), 0);
    ASSERT_FALSE(level);
    EXPECT_EQ(level.error().message.find('\n'), std::string::npos);
    EXPECT_NE(level.error().message.find("level.gltf"), std::string::npos) << level.error().message;
  }
  {  // 300 nodes each the child of the last
    nlohmann::json nodes = nlohmann::json::array();
    for (int i = 0; i < 300; ++i) {
      nlohmann::json node = {{"name", fmt::format("n{}", i)}, {"mesh", 0}};
      if (i + 1 < 300) node["children"] = {i + 1};
      nodes.push_back(node);
    }
    auto level = import_level(write(nodes, {0}), Affine3::Identity(), 0);
    ASSERT_FALSE(level);
    EXPECT_NE(level.error().message.find("nested more than"), std::string::npos)
        << level.error().message;
  }
  {  // negative emission
    const nlohmann::json nodes = {{{"name", "lamp"}, {"mesh", 0}}};
    auto level = import_level(write(nodes, {0}, {1, 1, 1}, -2), Affine3::Identity(), 0);
    ASSERT_FALSE(level);
    EXPECT_NE(level.error().message.find("node 'lamp': material 'm' has a negative"),
              std::string::npos)
        << level.error().message;
  }
  {  // an emissive quad of zero area: not a light, said so
    const nlohmann::json nodes = {{{"name", "flat"}, {"mesh", 0}, {"scale", {1, 0, 1}}},
                                  {{"name", "floor"}, {"mesh", 0}}};
    auto level = import_level(write(nodes, {0, 1}, {1, 1, 1}), Affine3::Identity(), 0);
    ASSERT_TRUE(level) << level.error().message;
    EXPECT_TRUE(any_warning_has(level->warnings, "node 'flat': its emissive material"));
  }
}

// An OBJ level (its .mtl's Ke is the emission) with a folded emissive strip of `triangles`
// triangles 2 m over a 4 × 4 m floor.
fs::path write_strip_obj(const fs::path& dir, int triangles) {
  std::ofstream(dir / "strip.mtl") << "newmtl plaster\nKd 0.8 0.8 0.8\nnewmtl lamp\nKd 0 0 0\n"
                                      "Ke 1 1 1\n";
  const fs::path file = dir / "strip.obj";
  std::ofstream obj(file);
  obj << "mtllib strip.mtl\no floor\nv -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\n";
  const int columns = triangles / 2 + 1;
  for (int i = 0; i < columns; ++i) {
    const double x = -1 + 2.0 * i / (columns - 1), y = 2 + 0.1 * (i % 2);  // folded
    obj << fmt::format("v {} {} -0.2\nv {} {} 0.2\n", x, y, x, y);
  }
  obj << "usemtl plaster\nf 1 3 2\nf 1 4 3\no strip\nusemtl lamp\n";
  for (int i = 0; i + 1 < columns; ++i) {
    const int a = 5 + 2 * i, b = a + 1, c = a + 2, d = a + 3;
    obj << fmt::format("f {} {} {}\nf {} {} {}\n", a, d, b, a, c, d);
  }
  return file;
}

// An emissive mesh of another shape from an OBJ is a mesh light; one of more than
// kMaxMeshLightTriangles is left out with a warning naming it, which the error of a level left
// with no light repeats.
TEST_F(HandWrittenLevel, FoldedEmissiveStripIsAMeshLightUnlessTooLarge) {
  {
    auto scene = load_level_scene(write_strip_obj(dir_, 100));
    ASSERT_TRUE(scene) << scene.error().message;
    ASSERT_EQ(scene->lights.size(), 1u);
    EXPECT_EQ(scene->lights[0].shape, LightShape::mesh);
    EXPECT_EQ(scene->lights[0].corners.size(), 3u * 100);
    auto baked = bake(*scene);
    ASSERT_TRUE(baked) << baked.error().message;
  }
  auto scene = load_level_scene(write_strip_obj(dir_, 1100));
  ASSERT_FALSE(scene);
  const std::string& message = scene.error().message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
  EXPECT_NE(message.find("holds no light"), std::string::npos) << message;
  EXPECT_NE(message.find("node 'strip'"), std::string::npos) << message;
  EXPECT_NE(message.find("1100 triangles, more than the 1024"), std::string::npos) << message;
}

// 100,000 instances of one mesh: read, and refused by the bake's memory check with its estimate
// (each is a receiver with a 512² lightmap), not built until memory runs out.
TEST_F(HandWrittenLevel, HundredThousandInstancesAreRefusedWithTheirCost) {
  nlohmann::json nodes = nlohmann::json::array();
  std::vector<int> roots;
  for (int i = 0; i < 100000; ++i) {
    nodes.push_back({{"name", fmt::format("crate{}", i)},
                     {"mesh", 0},
                     {"translation", {double(i % 300), 0, double(i / 300)}}});
    roots.push_back(i);
  }
  const fs::path file = write(nodes, roots);
  auto scene = load_level_scene(file);
  ASSERT_FALSE(scene);  // no light: the quad is not emissive
  // With a light added by hand, the bake refuses before building the meshes.
  auto level = import_level(file, Affine3::Identity(), 0);
  ASSERT_TRUE(level) << level.error().message;
  EXPECT_EQ(level->objects.size(), 100000u);
  Scene crates;
  crates.file = file;
  crates.objects = level->objects;
  LightDesc lamp;
  lamp.name = "lamp";
  lamp.shape = LightShape::sphere;
  lamp.position = Vec3(0, 5, 0);
  lamp.radius = 0.1;
  lamp.power = 100;
  crates.lights = {lamp};
  auto baked = bake(crates);
  ASSERT_FALSE(baked);
  EXPECT_NE(baked.error().message.find("GiB"), std::string::npos) << baked.error().message;
}

}  // namespace
}  // namespace sb

namespace sb {
namespace {

// A scene file that imports the level and overrides by glob.
TEST(LevelImport, SceneFileOverridesByNameAndGlob) {
  auto scene = load_scene(fs::path(SB_SOURCE_DIR) / "scenes" / "level" / "scene.toml");
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_EQ(scene->bake.resolution, 256);
  EXPECT_EQ(scene->objects.size(), 9u);
  for (const ObjectDesc& o : scene->objects)
    EXPECT_EQ(o.receiver, o.name.rfind("book_", 0) != 0) << o.name;
  EXPECT_EQ(light_named(*scene, "spot"), nullptr);
  ASSERT_NE(light_named(*scene, "bulb"), nullptr);
  EXPECT_EQ(light_named(*scene, "bulb")->radius, 0.1);
  EXPECT_EQ(scene->lights.size(), 4u);
}

class LevelImportErrors : public ::testing::Test {
 protected:
  // The scene file `text` beside the level; load_scene's error message.
  std::string error_of(const std::string& text) {
    const fs::path file =
        kLevel.parent_path() / ("import_test_" + std::to_string(::getpid()) + ".toml");
    std::ofstream(file) << text;
    auto scene = load_scene(file);
    fs::remove(file);
    return scene ? std::string() : scene.error().message;
  }
};

TEST_F(LevelImportErrors, NamesThatMatchNothingOrClashAreErrors) {
  const std::string head = "[[import]]\nfile = \"level.glb\"\n";
  std::string e = error_of(head + "[[import.object]]\nname = \"chiar*\"\nreceiver = false\n");
  EXPECT_NE(e.find(":4: [[import.object]]: 'chiar*' matches no object of"), std::string::npos) << e;
  EXPECT_NE(e.find("chair_a"), std::string::npos) << e;
  e = error_of(head + "[[import.light]]\nname = \"ceiling_panel\"\nradius = 0.2\n");
  EXPECT_NE(e.find("'radius' applies to sphere and disk lights"), std::string::npos) << e;
  e = error_of(head + "[[import.light]]\nname = \"sun\"\nradius = 0.2\n");
  EXPECT_NE(e.find("'sun' is a sun: give its size as 'angle_deg'"), std::string::npos) << e;
  e = error_of(head + "[[import.light]]\nname = \"bulb\"\nangle_deg = 1\n");
  EXPECT_NE(e.find("'angle_deg' applies to suns"), std::string::npos) << e;
  e = error_of(head + "[[import.object]]\nname = \"floor\"\nuv = 9\n");
  EXPECT_NE(e.find("'uv' must be a UV channel from 0 to 7 or \"auto\""), std::string::npos) << e;
  e = error_of(head +
               "[[object]]\nname = \"floor\"\nmesh = \"objects/floor.glb\"\n\n[[light]]\nname = "
               "\"sun\"\nshape = \"sphere\"\nposition = [0, 5, 0]\nradius = 0.1\npower = 10\n");
  EXPECT_NE(e.find("object 'floor': object names must be unique"), std::string::npos) << e;
  e = error_of("[[import]]\nfile = \"missing.glb\"\n");
  EXPECT_NE(e.find(":2: [[import]] #1: level file 'missing.glb' not found"), std::string::npos)
      << e;
  e = error_of(head + "colour = 1\n");
  EXPECT_NE(e.find("unknown key 'colour'"), std::string::npos) << e;
}

}  // namespace
}  // namespace sb

namespace sb {
namespace {

// A sun is a disk far away: its H0 is E cos θ on any surface of the scene (within the 10⁻⁴ rad
// its direction varies across the scene), 0 below the horizon.
TEST(SunLight, IrradianceIsECosThetaAcrossTheScene) {
  Bounds3 bounds;
  bounds.extend(Vec3(-5, 0, -4));
  bounds.extend(Vec3(5, 3, 4));
  const Vec3 direction = Vec3(0.3, -1, 0.2).normalized();
  const double irradiance = 800;
  const Light sun(sun_light(direction, kSunAngleDeg, irradiance, bounds));
  EXPECT_GE((sun.centre() - bounds.centre()).norm(), 1e4);
  for (const Vec3& y : {Vec3(-5, 0, -4), Vec3(5, 3, 4), Vec3(0, 1, 0), Vec3(2, 0, -3)}) {
    for (const Vec3& n : {Vec3(0, 1, 0), Vec3(1, 0, 0), Vec3(0, 0, -1), Vec3(-0.3, 1, -0.2)}) {
      const Vec3 unit = n.normalized();
      const double cosine = -direction.dot(unit);
      const double expected = cosine > 0.01 ? irradiance * cosine : cosine < -0.01 ? 0 : -1;
      if (expected < 0) continue;  // within the sun's radius of the horizon: clipped, not cos θ
      EXPECT_NEAR(sun.unoccluded_irradiance(y, unit).x(), expected, 1e-3 * irradiance)
          << y.transpose() << " n " << unit.transpose();
    }
  }
}

// place_sun moves a sun for other bounds and keeps what it is: direction, angle, irradiance.
TEST(SunLight, PlacingKeepsDirectionAngleAndIrradiance) {
  Bounds3 origin;
  origin.extend(Vec3::Zero());
  const Vec3 direction = Vec3(0.3, -1, 0.2).normalized();
  LightDesc sun = sun_light(direction, 1.5, 600, origin);
  Bounds3 far;
  far.extend(Vec3(40, 0, 40));
  far.extend(Vec3(60, 5, 70));
  place_sun(sun, far);
  EXPECT_LT((sun.normal - direction).norm(), 1e-12);
  EXPECT_EQ(sun.sun_angle_deg, 1.5);
  EXPECT_LT(((sun.position - far.centre()).normalized() + direction).norm(), 1e-9);
  const Vec3 up(0, 1, 0);
  EXPECT_NEAR(Light(sun).unoccluded_irradiance(Vec3(50, 0, 50), up).x(), 600 * -direction.y(),
              1e-3 * 600);
}

// A scene file's sun (shape = "sun"), placed by the bake for its meshes: on the sphere scene's
// floor the lit texels of an irradiance bake are E cos θ, for the exact methods.
TEST(SunLight, SceneFileSunBakesItsIrradiance) {
  for (const char* method : {"reference", "backprojection", "convolution"}) {
    SCOPED_TRACE(method);
    auto scene = load_scene(fs::path(SB_SOURCE_DIR) / "scenes" / "sphere" / "scene.toml");
    ASSERT_TRUE(scene) << scene.error().message;
    Bounds3 origin;
    origin.extend(Vec3::Zero());
    const Vec3 direction = Vec3(0.4, 0.1, -1).normalized();
    scene->lights = {sun_light(direction, kSunAngleDeg, 500, origin)};
    scene->lights[0].name = "sun";
    scene->bake.method = method;
    scene->bake.quantity = Quantity::irradiance;
    scene->bake.resolution = 64;
    scene->bake.samples = 16;
    scene->bake.margin = 0;
    auto baked = bake(*scene);
    ASSERT_TRUE(baked) << baked.error().message;
    const Image& image = baked->receivers.at(0).image;
    int lit = 0, shadowed = 0;
    for (std::size_t i = 0; i < baked->receivers[0].covered.size(); ++i) {
      if (!baked->receivers[0].covered[i]) continue;
      const double h = image.pixels[3 * i];
      if (std::abs(h - 500 * -direction.z()) <= 1e-3 * 500) ++lit;
      if (h <= 1e-3 * 500) ++shadowed;
    }
    EXPECT_GT(lit, 64 * 64 / 2);
    EXPECT_GT(shadowed, 64);  // the square's hard shadow
  }
}

// The level under its sun alone: the noise-free estimator against the reference, the sun's
// narrow penumbrae included.
TEST(SunLight, LevelBakesAsTheReferenceDoes) {
  auto scene = load_scene(kLevel);
  ASSERT_TRUE(scene) << scene.error().message;
  std::erase_if(scene->lights, [](const LightDesc& l) { return l.name != "sun"; });
  ASSERT_EQ(scene->lights.size(), 1u);
  scene->bake.resolution = 64;
  scene->bake.margin = 0;
  Scene reference = *scene;
  reference.bake.method = "reference";
  reference.bake.samples = 1024;
  auto ours = bake(*scene);
  auto truth = bake(reference);
  ASSERT_TRUE(ours && truth);
  for (std::size_t r = 0; r < ours->receivers.size(); ++r) {
    const ReceiverBake& a = ours->receivers[r];
    const ReceiverBake& b = truth->receivers[r];
    double sum = 0;
    std::int64_t count = 0;
    for (std::size_t i = 0; i < a.covered.size(); ++i) {
      if (!a.covered[i]) continue;
      const double d = a.image.pixels[3 * i] - b.image.pixels[3 * i];
      sum += d * d;
      ++count;
    }
    ASSERT_GT(count, 0) << a.name;
    EXPECT_LT(std::sqrt(sum / double(count)), 0.01) << a.name;
  }
}

}  // namespace
}  // namespace sb

namespace sb {
namespace {

// KHR_lights_punctual's `range` (which Assimp 5.2 does not carry) is each light's reach, scaled
// with the level; a light without one reaches everywhere; a range that is not a number > 0 is an
// error naming the light's node.
TEST_F(HandWrittenLevel, PunctualLightsKeepTheirRange) {
  const nlohmann::json lights = {{{"type", "point"}, {"intensity", 20}, {"range", 4.5}},
                                 {{"type", "point"}, {"intensity", 20}},
                                 {{"type", "point"}, {"intensity", 20}, {"range", -1}}};
  const auto node = [](const char* name, int light, double z) {
    return nlohmann::json{{"name", name},
                          {"translation", {0, 0, z}},
                          {"extensions", {{"KHR_lights_punctual", {{"light", light}}}}}};
  };
  const nlohmann::json nodes = {
      {{"name", "floor"}, {"mesh", 0}}, node("near", 0, 1), node("far", 1, 2)};
  auto level = import_level(write(nodes, {0, 1, 2}, {0, 0, 0}, 1, 1, lights),
                            object_transform(Vec3::Zero(), Vec3::Zero(), Vec3::Constant(2)), 0);
  ASSERT_TRUE(level) << level.error().message;
  ASSERT_EQ(level->lights.size(), 2u);
  for (const LightDesc& light : level->lights) {
    if (light.name == "near") {
      EXPECT_DOUBLE_EQ(light.range, 9.0);  // 4.5 m of the file, the level scaled by 2
      EXPECT_DOUBLE_EQ(light.shadowmask_range, 9.0);
    } else {
      EXPECT_TRUE(std::isinf(light.range)) << light.name;
    }
  }
  const nlohmann::json bad = {{{"name", "floor"}, {"mesh", 0}}, node("broken", 2, 1)};
  auto refused = import_level(write(bad, {0, 1}, {0, 0, 0}, 1, 1, lights), Affine3::Identity(), 0);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("node 'broken': the light's KHR_lights_punctual range"),
            std::string::npos)
      << refused.error().message;
  EXPECT_EQ(refused.error().message.find('\n'), std::string::npos);
}

}  // namespace
}  // namespace sb
