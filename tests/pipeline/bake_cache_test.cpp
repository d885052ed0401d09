// Incremental bakes (src/pipeline/bake_cache.h): a bake into a folder that holds an earlier bake
// takes the receivers nothing has changed for from its cache and bakes the others, and its files
// are byte for byte those of a full bake of the changed scene.
//
// The room: a floor (4 × 4 m), a wall across it at x = 2, a mat on the floor in the far corner and
// a ceiling above the light, all receivers; a 1 m panel at x = -1.5, 2.5 m up, shining down; a
// crate between the light and the wall, whose shadow falls on the wall from across the room.
#include "pipeline/bake_cache.h"
#include "pipeline/bake.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "formats/manifest.h"
#include "formats/outputs.h"
#include "scene/scene.h"

namespace sb {
namespace {

namespace fs = std::filesystem;

// A quad with corners a, b, c, d (counter-clockwise seen from the side it faces) and UVs over
// [0, 1]², as an OBJ.
void write_quad(const fs::path& path, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  std::ofstream out(path);
  for (const Vec3& p : {a, b, c, d}) out << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
  out << "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
}

// An axis-aligned box from lo to hi, as an OBJ (no UVs: a blocker).
void write_box(const fs::path& path, const Vec3& lo, const Vec3& hi) {
  std::ofstream out(path);
  for (int c = 0; c < 8; ++c)
    out << "v " << (c & 1 ? hi : lo).x() << " " << (c & 2 ? hi : lo).y() << " "
        << (c & 4 ? hi : lo).z() << "\n";
  out << "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
}

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

class Incremental : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("sb_incremental_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    write_quad(dir_ / "floor.obj", {-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0});
    write_quad(dir_ / "wall.obj", {2, 2, 0}, {2, -2, 0}, {2, -2, 3}, {2, 2, 3});
    write_quad(dir_ / "mat.obj", {-2, 1.2, 0.01}, {-1.2, 1.2, 0.01}, {-1.2, 2, 0.01},
               {-2, 2, 0.01});
    write_quad(dir_ / "ceiling.obj", {-2, -2, 3}, {-2, 2, 3}, {2, 2, 3}, {2, -2, 3});
    write_scene(Vec3(0.6, -0.3, 1.2));
  }
  void TearDown() override { fs::remove_all(dir_); }

  // The scene with the crate's lower corner at `crate`.
  void write_scene(const Vec3& crate) {
    write_box(dir_ / "crate.obj", crate, crate + Vec3(0.5, 0.6, 0.5));
    std::ofstream out(dir_ / "scene.toml");
    out << "[bake]\nresolution = 32\nmethod = \"backprojection\"\nsamples = 16\n";
    for (const char* name : {"floor", "wall", "mat", "ceiling"})
      out << "[[object]]\nname = \"" << name << "\"\nmesh = \"" << name << ".obj\"\nuv = 0\n";
    out << "[[object]]\nname = \"crate\"\nmesh = \"crate.obj\"\nreceiver = false\n";
    out << "[[light]]\nname = \"panel\"\nshape = \"rectangle\"\nposition = [-1.5, 0, 2.5]\n"
           "normal = [0, 0, -1]\nup = [0, 1, 0]\nsize = [1, 1]\npower = 100\n";
  }

  // Bakes the scene into `out` as the CLI does (keeping the cache, taking from it); per receiver
  // whether it was reused.
  std::map<std::string, bool> bake_into(const fs::path& out, bool keys = true,
                                        std::vector<std::string> only = {}) {
    auto scene = load_scene((dir_ / "scene.toml").string());
    EXPECT_TRUE(scene) << scene.error().message;
    BakeOptions options;
    options.keys = keys;
    options.reuse_from = keys ? out : fs::path();
    options.only = std::move(only);
    auto result = bake(*scene, options);
    EXPECT_TRUE(result) << result.error().message;
    auto folder = OutputFolder::open(out);
    EXPECT_TRUE(folder);
    const Status written = write_outputs(*folder, *scene, scene->bake, *result);
    EXPECT_TRUE(written) << written.error().message;
    std::map<std::string, bool> reused;
    for (const ReceiverBake& r : result->receivers) reused[r.name] = r.reuse == "reused";
    return reused;
  }

  fs::path dir_;
};

// The lightmaps of two folders, byte for byte.
void expect_same_lightmaps(const fs::path& a, const fs::path& b) {
  int files = 0;
  for (const auto& e : fs::directory_iterator(a)) {
    const std::string name = e.path().filename().string();
    if (!e.is_regular_file() || name == kManifestFile) continue;
    EXPECT_EQ(slurp(e.path()), slurp(b / name)) << name;
    ++files;
  }
  EXPECT_GE(files, 8);
}

TEST_F(Incremental, MovingACrateRebakesTheWallItShadowsAndReusesTheRest) {
  const fs::path out = dir_ / "out", full = dir_ / "full";
  std::map<std::string, bool> first = bake_into(out);
  for (const auto& [name, reused] : first) EXPECT_FALSE(reused) << name;
  // Nothing changed: everything comes from the cache, the same bytes.
  std::map<std::string, bool> again = bake_into(out);
  for (const auto& [name, reused] : again) EXPECT_TRUE(reused) << name;

  // The crate moves 0.4 m along the wall: its shadow on the wall (and the floor) moves.
  write_scene(Vec3(0.6, 0.1, 1.2));
  const std::map<std::string, bool> moved = bake_into(out);
  EXPECT_FALSE(moved.at("wall"));
  EXPECT_FALSE(moved.at("floor"));
  // The mat's shafts to the panel and the ceiling (behind the panel) never meet the crate.
  EXPECT_TRUE(moved.at("mat"));
  EXPECT_TRUE(moved.at("ceiling"));
  bake_into(full, false);
  expect_same_lightmaps(full, out);
  // The manifest says which and why.
  auto manifest = read_manifest(out);
  ASSERT_TRUE(manifest);
  for (const ManifestReceiver& r : manifest->receivers) {
    ASSERT_TRUE(r.bake) << r.name;
    EXPECT_EQ(r.bake->reused, moved.at(r.name)) << r.name;
    if (r.name == "wall") {
      EXPECT_EQ(r.bake->why, "changed: the blockers in its shafts");
    }
  }
  // The cache holds the receivers of the last bake, and a receiver it lacks is baked.
  fs::remove(out / kCacheFolder / "mat.json");
  const std::map<std::string, bool> lacking = bake_into(out);
  EXPECT_FALSE(lacking.at("mat"));
  EXPECT_TRUE(lacking.at("wall"));
  expect_same_lightmaps(full, out);
}

TEST_F(Incremental, ALightChangedRebakesWhatItReaches) {
  const fs::path out = dir_ / "out";
  bake_into(out);
  // Brighter: every receiver it reaches changes; the ceiling behind it does not.
  std::string text = slurp(dir_ / "scene.toml");
  text.replace(text.find("power = 100"), 11, "power = 250");
  std::ofstream(dir_ / "scene.toml") << text;
  const std::map<std::string, bool> brighter = bake_into(out);
  EXPECT_FALSE(brighter.at("floor"));
  EXPECT_FALSE(brighter.at("mat"));
  EXPECT_FALSE(brighter.at("wall"));
  EXPECT_TRUE(brighter.at("ceiling"));
}

TEST_F(Incremental, OnlyBakesWhatItNamesAndKeepsTheRestEvenIfStale) {
  const fs::path out = dir_ / "out";
  bake_into(out);
  write_scene(Vec3(0.6, 0.1, 1.2));
  const std::map<std::string, bool> only = bake_into(out, true, {"floor"});
  EXPECT_FALSE(only.at("floor"));
  EXPECT_TRUE(only.at("wall"));  // changed, but not named: left as it was
  auto manifest = read_manifest(out);
  ASSERT_TRUE(manifest);
  for (const ManifestReceiver& r : manifest->receivers) {
    if (r.name == "wall") {
      EXPECT_EQ(
          r.bake->why,
          "left as it was: not named by --only or --lights (changed: the blockers in its shafts)");
    }
  }
  // The next plain bake sees the wall's stale entry for what it is.
  const std::map<std::string, bool> next = bake_into(out);
  EXPECT_FALSE(next.at("wall"));
  EXPECT_TRUE(next.at("floor"));
}

TEST_F(Incremental, LightsBakesWhatTheyMayReachAndKeepsTheRest) {
  const fs::path out = dir_ / "out";
  bake_into(out);
  write_scene(Vec3(0.6, 0.1, 1.2));  // the wall changes, but only the panel is named
  auto scene = load_scene((dir_ / "scene.toml").string());
  ASSERT_TRUE(scene);
  BakeOptions options;
  options.keys = true;
  options.reuse_from = out;
  options.relight = {"panel"};
  auto result = bake(*scene, options);
  ASSERT_TRUE(result) << result.error().message;
  std::map<std::string, std::string> why;
  for (const ReceiverBake& r : result->receivers) why[r.name] = r.reuse_why;
  EXPECT_EQ(why.at("floor"), "may be reached by --lights panel");
  EXPECT_EQ(why.at("wall"), "may be reached by --lights panel");
  // Behind the panel: taken from the cache as it was.
  EXPECT_EQ(why.at("ceiling"), "nothing that may reach it changed");
  options.relight = {"lamp"};
  result = bake(*scene, options);
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("--lights lamp: no light has that name"),
            std::string::npos);
}

TEST_F(Incremental, OnlyNamingNoReceiverIsAnError) {
  auto scene = load_scene((dir_ / "scene.toml").string());
  ASSERT_TRUE(scene);
  BakeOptions options;
  options.keys = true;
  options.only = {"crate"};
  auto result = bake(*scene, options);
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("--only crate: no receiver has that name"),
            std::string::npos)
      << result.error().message;
}

}  // namespace
}  // namespace sb
