// End to end: runs the shadowbake executable on small scenes written by the test, and checks the
// files, the manifest, byte-identical re-runs, and the errors and exit codes for bad input,
// with no partial output left behind.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <thread>

#include "core/image_io.h"
#include "formats/manifest.h"

namespace fs = std::filesystem;

namespace {

struct CliRun {
  int code = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// `text` with every `from` replaced by `to`.
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos;
       at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("shadowbake_cli_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // A 2 m floor with UVs, and a blocker quad 0.5 m above it.
    write("floor.obj",
          "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
          "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
          "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n");
    write("blocker.obj",
          "v -0.3 -0.3 0.5\nv 0.3 -0.3 0.5\nv 0.3 0.3 0.5\nv -0.3 0.3 0.5\n"
          "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
          "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n");
  }
  void TearDown() override { fs::remove_all(dir_); }

  void write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }

  std::string scene(const std::string& bake_extra = "", const std::string& object_extra = "",
                    const std::string& light_extra = "") {
    return "[bake]\nresolution = 32\nsamples = 16\n" + bake_extra +
           "\n[[object]]\nname = \"floor\"\nmesh = \"floor.obj\"\n" + object_extra +
           "\n[[object]]\nname = \"blocker\"\nmesh = \"blocker.obj\"\nreceiver = false\n"
           "\n[[light]]\nname = \"panel\"\nshape = \"rectangle\"\nposition = [0, 0, 1.5]\n"
           "normal = [0, 0, -1]\nsize = [0.5, 0.5]\npower = 100.0\n" +
           light_extra;
  }

  CliRun run(const std::string& args) {
    CliRun r;
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string cmd = std::string(SB_CLI) + " " + args + " >" + out.string() + " 2>" +
                            err.string() + " </dev/null";
    const int status = std::system(cmd.c_str());
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
  }

  // Files in `folder`, temporary ones included.
  static std::vector<std::string> listing(const fs::path& folder) {
    std::vector<std::string> names;
    if (!fs::exists(folder)) return names;
    for (const auto& e : fs::directory_iterator(folder)) names.push_back(e.path().filename());
    std::sort(names.begin(), names.end());
    return names;
  }

  fs::path dir_;
};

TEST_F(Cli, BakesFilesAndManifest) {
  write("scene.toml", scene());
  const CliRun r = run("bake " + (dir_ / "scene.toml").string() + " -o " + (dir_ / "out").string());
  ASSERT_EQ(r.code, 0) << r.err;
  // The lightmap, its preview and coverage, the manifest, and the cache the next bake into the
  // folder takes unchanged receivers from (incremental bakes).
  EXPECT_EQ(listing(dir_ / "out"),
            (std::vector<std::string>{".shadowbake-cache", "floor.coverage.png", "floor.exr",
                                      "floor.png", "manifest.json"}));
  const auto manifest = sb::read_manifest(dir_ / "out");
  ASSERT_TRUE(manifest) << manifest.error().message;
  ASSERT_EQ(manifest->receivers.size(), 1u);
  const sb::ManifestReceiver& floor = manifest->receivers[0];
  EXPECT_EQ(floor.name, "floor");
  ASSERT_TRUE(floor.files);
  EXPECT_EQ(floor.files->lightmap.file, "floor.exr");
  EXPECT_EQ(floor.files->lightmap.encoding, sb::Encoding::linear_exr);
  ASSERT_TRUE(floor.files->preview);
  EXPECT_EQ(floor.files->preview->file, "floor.png");
  EXPECT_EQ(floor.files->coverage.file, "floor.coverage.png");
  EXPECT_EQ(floor.uv_channel, 0);
  EXPECT_EQ(floor.width, 32);
  EXPECT_EQ(floor.height, 32);
  EXPECT_EQ(floor.method, "backprojection");  // the default
  EXPECT_EQ(floor.quantity, sb::Quantity::visibility);
  EXPECT_EQ(floor.samples, 16);
  EXPECT_GT(floor.seconds, 0.0);
  EXPECT_LE(floor.seconds, manifest->bake_seconds);

  auto exr = sb::read_image(dir_ / "out" / "floor.exr");
  ASSERT_TRUE(exr);
  EXPECT_EQ(exr->width, 32);
  EXPECT_EQ(exr->channels, 3);
  // The centre is in the blocker's umbra, the corners in full light.
  EXPECT_LT(exr->at(16, 16)[0], 0.01f);
  EXPECT_GT(exr->at(1, 1)[0], 0.99f);
  auto png = sb::read_image(dir_ / "out" / "floor.png");
  ASSERT_TRUE(png);
  EXPECT_NEAR(png->at(1, 1)[0], exr->at(1, 1)[0], 1.0 / 255 + 1e-6);
}

// Ambient occlusion from the command line: a scene without lights bakes with --quantity
// ambient-occlusion (which picks its method), a light-method named beside it is refused, and
// without it the scene's missing light is the error.
TEST_F(Cli, AmbientOcclusionBakesAFileWithoutLights) {
  const std::string unlit = scene().substr(0, scene().find("\n[[light]]"));
  write("scene.toml", unlit);
  const std::string s = (dir_ / "scene.toml").string();
  const CliRun ok = run("bake " + s + " -o " + (dir_ / "out").string() +
                        " --quantity ambient-occlusion --ao-distance 5 -q");
  ASSERT_EQ(ok.code, 0) << ok.err;
  const auto manifest = sb::read_manifest(dir_ / "out");
  ASSERT_TRUE(manifest) << manifest.error().message;
  EXPECT_EQ(manifest->receivers[0].method, "ambient-occlusion");
  EXPECT_EQ(manifest->receivers[0].quantity, sb::Quantity::ambient_occlusion);
  auto exr = sb::read_image(dir_ / "out" / "floor.exr");
  ASSERT_TRUE(exr);
  EXPECT_LT(exr->at(16, 16)[0], 0.8f);  // under the blocker
  EXPECT_GT(exr->at(1, 1)[0], exr->at(16, 16)[0]);
  const CliRun mixed = run("bake " + s + " -o " + (dir_ / "mixed").string() +
                           " --quantity ambient-occlusion --method reference");
  EXPECT_NE(mixed.code, 0);
  EXPECT_NE(mixed.err.find("do not go together"), std::string::npos) << mixed.err;
  EXPECT_FALSE(fs::exists(dir_ / "mixed" / "floor.exr"));
  const CliRun unlit_visibility = run("bake " + s + " -o " + (dir_ / "vis").string());
  EXPECT_NE(unlit_visibility.code, 0);
  EXPECT_NE(unlit_visibility.err.find("no light"), std::string::npos) << unlit_visibility.err;
  EXPECT_EQ(std::count(unlit_visibility.err.begin(), unlit_visibility.err.end(), '\n'), 1);
}

TEST_F(Cli, ShardsMergeIntoWhatOneBakeWrites) {
  // The floor and the blocker both receive, so that two shards each get one.
  write("scene.toml", replaced(scene("method = \"reference\"\n"), "receiver = false\n", ""));
  const std::string s = (dir_ / "scene.toml").string();
  ASSERT_EQ(run("bake " + s + " -o " + (dir_ / "whole").string() + " --gltf --per-light").code, 0);
  const CliRun a =
      run("bake " + s + " -o " + (dir_ / "a").string() + " --gltf --per-light --shard 0/2");
  ASSERT_EQ(a.code, 0) << a.err;
  EXPECT_NE(a.out.find("shard 0/2: baked 1 receiver(s)"), std::string::npos) << a.out;
  // auto/N takes K from the scheduler's variable.
  const std::string with_env = "SLURM_ARRAY_TASK_ID=1 " + std::string(SB_CLI);
  const int code = std::system((with_env + " bake " + s + " -o " + (dir_ / "b").string() +
                                " --gltf --per-light --shard auto/2 -q")
                                   .c_str());
  ASSERT_EQ(WEXITSTATUS(code), 0);
  const CliRun missing = run("merge " + (dir_ / "a").string() + " -o " + (dir_ / "m").string());
  EXPECT_EQ(missing.code, 3);
  EXPECT_NE(missing.err.find("shard 1/2 is missing"), std::string::npos) << missing.err;
  EXPECT_FALSE(fs::exists(dir_ / "m" / "manifest.json"));
  // The scene where the merge sees it: a copy elsewhere (the same bytes) is accepted, a changed
  // one is not.
  fs::create_directories(dir_ / "elsewhere");
  for (const std::string file : {"scene.toml", "floor.obj", "blocker.obj"})
    fs::copy_file(dir_ / file, dir_ / "elsewhere" / file);
  const std::string shards = (dir_ / "b").string() + " " + (dir_ / "a").string();
  std::ofstream(dir_ / "elsewhere" / "floor.obj", std::ios::app) << "# changed\n";
  const CliRun changed = run("merge " + shards + " -o " + (dir_ / "m").string() + " --scene " +
                             (dir_ / "elsewhere" / "scene.toml").string());
  EXPECT_EQ(changed.code, 3);
  EXPECT_NE(changed.err.find("changed since the shards were baked"), std::string::npos)
      << changed.err;
  fs::copy_file(dir_ / "floor.obj", dir_ / "elsewhere" / "floor.obj",
                fs::copy_options::overwrite_existing);
  const CliRun merged = run("merge " + shards + " -o " + (dir_ / "m").string() + " --scene " +
                            (dir_ / "elsewhere" / "scene.toml").string());
  ASSERT_EQ(merged.code, 0) << merged.err;
  for (const std::string file : {"floor.exr", "blocker.exr", "floor.panel.exr", "scene.glb"}) {
    std::ifstream x(dir_ / "whole" / file, std::ios::binary),
        y(dir_ / "m" / file, std::ios::binary);
    const std::string bx((std::istreambuf_iterator<char>(x)), {}),
        by((std::istreambuf_iterator<char>(y)), {});
    EXPECT_FALSE(bx.empty()) << file;
    EXPECT_EQ(bx, by) << file;
  }
}

TEST_F(Cli, BatchBakesEachSceneIntoItsOwnFolder) {
  fs::create_directories(dir_ / "one");
  fs::create_directories(dir_ / "two");
  const auto beside = [](const std::string& text) {
    return replaced(replaced(text, "floor.obj", "../floor.obj"), "blocker.obj", "../blocker.obj");
  };
  write("one/scene.toml", beside(scene()));
  write("two/scene.toml", beside(scene("quantity = \"irradiance\"\n")));
  write("broken.toml", "[bake\n");
  write("scenes.txt", "# the batch\none/scene.toml\n\ntwo/scene.toml\n");
  const fs::path out = dir_ / "out";
  const CliRun r = run("bake --list " + (dir_ / "scenes.txt").string() + " " +
                       (dir_ / "broken.toml").string() + " -o " + out.string());
  // The broken scene fails with its own error; the others are baked.
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_NE(r.err.find("TOML syntax error"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("batch: 2 of 3 scene(s) baked"), std::string::npos) << r.out;
  auto first = sb::read_manifest(out / dir_.relative_path() / "one" / "scene");
  auto second = sb::read_manifest(out / dir_.relative_path() / "two" / "scene");
  ASSERT_TRUE(first) << first.error().message;
  ASSERT_TRUE(second) << second.error().message;
  EXPECT_EQ(second->quantity, sb::Quantity::irradiance);
}

TEST_F(Cli, RebakesTakeUnchangedReceiversFromTheFolder) {
  write("scene.toml", scene());
  const std::string bake = "bake " + (dir_ / "scene.toml").string() + " -o ";
  ASSERT_EQ(run(bake + (dir_ / "out").string()).code, 0);
  const std::string first = slurp(dir_ / "out" / "floor.exr");
  // Unchanged: taken from the cache, the same bytes, and the manifest says so.
  CliRun r = run(bake + (dir_ / "out").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(slurp(dir_ / "out" / "floor.exr"), first);
  auto manifest = sb::read_manifest(dir_ / "out");
  ASSERT_TRUE(manifest) << manifest.error().message;
  ASSERT_TRUE(manifest->receivers[0].bake);
  EXPECT_TRUE(manifest->receivers[0].bake->reused);
  EXPECT_EQ(manifest->receivers[0].seconds, 0);
  // --force bakes it again, to the same bytes.
  r = run(bake + (dir_ / "out").string() + " --force");
  ASSERT_EQ(r.code, 0) << r.err;
  manifest = sb::read_manifest(dir_ / "out");
  ASSERT_TRUE(manifest) << manifest.error().message;
  EXPECT_FALSE(manifest->receivers[0].bake->reused);
  EXPECT_EQ(manifest->receivers[0].bake->why, "--force");
  EXPECT_EQ(slurp(dir_ / "out" / "floor.exr"), first);
  // --no-cache keeps no cache; --only names a receiver that must exist.
  r = run(bake + (dir_ / "plain").string() + " --no-cache");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "plain" / ".shadowbake-cache"));
  r = run(bake + (dir_ / "out").string() + " --only nothing");
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("--only nothing: no receiver has that name"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(dir_ / "out" / "floor.exr"), first);
}

TEST_F(Cli, PreviewPresetBakesASixteenthOfTheTexelsByRaysAndOptionsOverrideIt) {
  std::string text = scene();
  text.replace(text.find("resolution = 32\nsamples = 16"), 28,
               "resolution = 128\nsamples = 64\nmethod = \"backprojection\"");
  write("scene.toml", text);
  const std::string bake = "bake " + (dir_ / "scene.toml").string() + " -o ";
  CliRun r = run(bake + (dir_ / "preview").string() + " --preset preview --per-light");
  ASSERT_EQ(r.code, 0) << r.err;
  auto manifest = sb::read_manifest(dir_ / "preview");
  ASSERT_TRUE(manifest) << manifest.error().message;
  EXPECT_EQ(manifest->resolution, 32);
  EXPECT_EQ(manifest->method, "reference");
  EXPECT_EQ(manifest->samples, 16);
  EXPECT_FALSE(manifest->receivers[0].seams.stitched);
  EXPECT_TRUE(manifest->output.per_light);  // asked for beside the preset
  r = run(bake + (dir_ / "preview2").string() + " --preset preview --resolution 64 --samples 4");
  ASSERT_EQ(r.code, 0) << r.err;
  manifest = sb::read_manifest(dir_ / "preview2");
  ASSERT_TRUE(manifest) << manifest.error().message;
  EXPECT_EQ(manifest->resolution, 64);
  EXPECT_EQ(manifest->samples, 4);
  r = run(bake + (dir_ / "final").string() + " --preset final");
  ASSERT_EQ(r.code, 0) << r.err;
  manifest = sb::read_manifest(dir_ / "final");
  ASSERT_TRUE(manifest) << manifest.error().message;
  EXPECT_EQ(manifest->resolution, 128);
  EXPECT_EQ(manifest->method, "backprojection");
  EXPECT_EQ(run(bake + (dir_ / "x").string() + " --preset draft").code, 2);
}

TEST_F(Cli, WatchRebakesWhenTheSceneChanges) {
  write("scene.toml", scene());
  const fs::path out = dir_ / "out", pid = dir_ / "watch.pid";
  // In the background, its pid kept to stop it.
  const std::string cmd = "sh -c '" + std::string(SB_CLI) + " bake " +
                          (dir_ / "scene.toml").string() + " -o " + out.string() +
                          " --watch --quiet >/dev/null 2>&1 & echo $! >" + pid.string() + "'";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  const auto wait_for = [](const std::function<bool()>& done) {
    for (int i = 0; i < 600 && !done(); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    return done();
  };
  const auto manifest_text = [&] { return slurp(out / "manifest.json"); };
  EXPECT_TRUE(wait_for([&] { return !manifest_text().empty(); }));
  const std::string first = manifest_text();
  // A brighter light: the watcher bakes again (the floor, which it reaches).
  std::string text = scene();
  text.replace(text.find("power = 100.0"), 13, "power = 250.0");
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));  // a new modification time
  write("scene.toml", text);
  const bool rebaked = wait_for([&] {
    const std::string now = manifest_text();
    return !now.empty() && now != first;
  });
  const std::string kill = "kill $(cat " + pid.string() + ")";
  EXPECT_EQ(std::system(kill.c_str()), 0);
  ASSERT_TRUE(rebaked);
  const auto manifest = sb::read_manifest(out);
  ASSERT_TRUE(manifest) << manifest.error().message;
  ASSERT_TRUE(manifest->receivers[0].bake);
  EXPECT_FALSE(manifest->receivers[0].bake->reused);
  EXPECT_EQ(manifest->receivers[0].bake->why, "changed: the lights that may reach it");
}

TEST_F(Cli, OutputFlagsWriteAtlasesMasksPerLightImagesAndGltf) {
  write("scene.toml", scene());
  const fs::path out = dir_ / "out";
  const CliRun r = run("bake " + (dir_ / "scene.toml").string() + " -o " + out.string() +
                       " --method reference --texels-per-metre 12 --atlas 256 --atlas-padding 3 "
                       "--shadowmask --per-light --gltf --encoding png");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(listing(out),
            (std::vector<std::string>{".shadowbake-cache", "lightmap_0.coverage.png",
                                      "lightmap_0.panel.png", "lightmap_0.png",
                                      "lightmap_0.shadowmask.png", "manifest.json", "scene.glb"}));
  const auto manifest = sb::read_manifest(out);
  ASSERT_TRUE(manifest) << manifest.error().message;
  EXPECT_EQ(manifest->texels_per_metre, 12.0);
  ASSERT_EQ(manifest->atlases.size(), 1u);
  EXPECT_EQ(manifest->atlases[0].files.lightmap.encoding, sb::Encoding::png);
  ASSERT_TRUE(manifest->receivers[0].atlas);
  // The 2 × 2 m floor over the unit square at 12 texels per metre: 24 texels a side, 3 texels
  // of padding, in the smallest power-of-two atlas that holds 30: 32.
  EXPECT_EQ(manifest->receivers[0].atlas->side, 24);
  EXPECT_EQ(manifest->receivers[0].atlas->x, 3);
  EXPECT_EQ(manifest->atlases[0].size, 32);
  EXPECT_EQ(manifest->lights[0].shadowmask_channel, 0);
  ASSERT_TRUE(manifest->gltf);

  // A resolution and a density at once is a usage error.
  const CliRun both = run("bake " + (dir_ / "scene.toml").string() + " -o " + out.string() +
                          " --resolution 64 --texels-per-metre 12");
  EXPECT_EQ(both.code, 2) << both.err;
}

TEST_F(Cli, SameSceneSameSeedSameBytes) {
  write("scene.toml", scene("method = \"reference\"\n"));
  const std::string s = (dir_ / "scene.toml").string();
  ASSERT_EQ(run("bake " + s + " -o " + (dir_ / "a").string() + " --threads 1").code, 0);
  // A second apart, so a timestamp written into a file would show.
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  ASSERT_EQ(run("bake " + s + " -o " + (dir_ / "b").string() + " --threads 2").code, 0);
  for (const char* f : {"floor.exr", "floor.png"}) {
    EXPECT_EQ(slurp(dir_ / "a" / f), slurp(dir_ / "b" / f)) << f;
  }
  ASSERT_EQ(run("bake " + s + " -o " + (dir_ / "c").string() + " --seed 9").code, 0);
  EXPECT_NE(slurp(dir_ / "a" / "floor.exr"), slurp(dir_ / "c" / "floor.exr"));
  // The convolution method, which draws no random numbers, likewise.
  ASSERT_EQ(
      run("bake " + s + " -o " + (dir_ / "d").string() + " --method convolution --threads 1").code,
      0);
  ASSERT_EQ(
      run("bake " + s + " -o " + (dir_ / "e").string() + " --method convolution --threads 2").code,
      0);
  for (const char* f : {"floor.exr", "floor.png"}) {
    EXPECT_EQ(slurp(dir_ / "d" / f), slurp(dir_ / "e" / f)) << f;
  }
}

TEST_F(Cli, OverridesReachTheManifest) {
  write("scene.toml", scene());
  const CliRun r = run("bake " + (dir_ / "scene.toml").string() + " -o " + (dir_ / "out").string() +
                       " --quantity irradiance --resolution 16 --samples 4 --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  const auto manifest = sb::read_manifest(dir_ / "out");
  ASSERT_TRUE(manifest) << manifest.error().message;
  EXPECT_EQ(manifest->quantity, sb::Quantity::irradiance);
  ASSERT_EQ(manifest->receivers.size(), 1u);
  EXPECT_EQ(manifest->receivers[0].width, 16);
  EXPECT_EQ(manifest->receivers[0].height, 16);
  EXPECT_EQ(manifest->receivers[0].samples, 4);
  auto exr = sb::read_image(dir_ / "out" / "floor.exr");
  ASSERT_TRUE(exr);
  // A corner texel in full light: irradiance of the order of P/(π d²) ≈ 14 W/m².
  EXPECT_GT(exr->at(0, 0)[0], 1.0f);
}

TEST_F(Cli, WarnsAboutDegenerateTriangles) {
  // The blocker gains a zero-area triangle (three collinear points): skipped, with a warning.
  write("blocker.obj",
        "v -0.3 -0.3 0.5\nv 0.3 -0.3 0.5\nv 0.3 0.3 0.5\nv -0.3 0.3 0.5\nv 0 0 0.5\n"
        "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
        "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\nf 1/1/1 5/1/1 3/3/1\n");
  write("scene.toml", scene());
  const CliRun r = run("bake " + (dir_ / "scene.toml").string() + " -o " + (dir_ / "out").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("blocker"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("degenerate"), std::string::npos) << r.err;
}

// A bad scene: exit code 3, one line on stderr naming the file and the item, and no output.
void expect_scene_error(const CliRun& r, const std::vector<std::string>& words) {
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  for (const auto& w : words) EXPECT_NE(r.err.find(w), std::string::npos) << w << " in " << r.err;
}

TEST_F(Cli, RejectsUnknownKeyWithoutOutput) {
  write("scene.toml", scene("", "recever = true\n"));
  const CliRun r = run("bake " + (dir_ / "scene.toml").string() + " -o " + (dir_ / "out").string());
  expect_scene_error(r, {"scene.toml", "floor", "recever"});
  EXPECT_TRUE(listing(dir_ / "out").empty());
}

TEST_F(Cli, RejectsMissingSceneFile) {
  const CliRun r = run("bake " + (dir_ / "nope.toml").string() + " -o " + (dir_ / "out").string());
  expect_scene_error(r, {"nope.toml"});
}

TEST_F(Cli, RejectsMissingMesh) {
  write("scene.toml", scene());
  fs::remove(dir_ / "blocker.obj");
  const CliRun r = run("bake " + (dir_ / "scene.toml").string() + " -o " + (dir_ / "out").string());
  expect_scene_error(r, {"scene.toml", "blocker", "blocker.obj"});
}

TEST_F(Cli, RejectsUnreadableMesh) {
  write("scene.toml", scene());
  write("blocker.obj", "this is not a mesh\n\x01\x02\x03");
  const CliRun r = run("bake " + (dir_ / "scene.toml").string() + " -o " + (dir_ / "out").string());
  expect_scene_error(r, {"scene.toml", "blocker"});
  EXPECT_TRUE(listing(dir_ / "out").empty());
}

TEST_F(Cli, RejectsMissingUvChannel) {
  write("scene.toml", scene("", "uv = 1\n"));
  const CliRun r = run("bake " + (dir_ / "scene.toml").string() + " -o " + (dir_ / "out").string());
  expect_scene_error(r, {"scene.toml", "floor", "1"});
}

TEST_F(Cli, RejectsImpossibleLight) {
  write("scene.toml", scene() +
                          "\n[[light]]\nname = \"bad\"\nshape = \"disk\"\n"
                          "position = [0, 0, 1]\nnormal = [0, 0, 0]\nradius = [0.1]\n"
                          "power = 10.0\n");
  const CliRun r = run("bake " + (dir_ / "scene.toml").string() + " -o " + (dir_ / "out").string());
  expect_scene_error(r, {"scene.toml", "bad", "normal"});
}

TEST_F(Cli, UnwritableOutputLeavesNothing) {
  write("scene.toml", scene());
  write("a_file", "x");
  const CliRun r =
      run("bake " + (dir_ / "scene.toml").string() + " -o " + (dir_ / "a_file" / "out").string());
  EXPECT_EQ(r.code, 4) << r.err;
  EXPECT_NE(r.err.find("a_file"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;

  // A folder in the way of one output: nothing else is published either.
  fs::create_directories(dir_ / "out" / "floor.png");
  const CliRun blocked =
      run("bake " + (dir_ / "scene.toml").string() + " -o " + (dir_ / "out").string());
  EXPECT_EQ(blocked.code, 4) << blocked.err;
  EXPECT_NE(blocked.err.find("floor.png"), std::string::npos) << blocked.err;
  EXPECT_EQ(listing(dir_ / "out"), std::vector<std::string>{"floor.png"});

  // A read-only folder: nothing, not even a temporary file, is left in it. For a user, a folder
  // without write permission; root ignores permissions, so for root a read-only tmpfs mounted
  // over the folder in a mount namespace of the command's own (gone when it ends; the folder's
  // listing is taken inside it).
  fs::create_directories(dir_ / "ro");
  const std::string ro_bake =
      "bake " + (dir_ / "scene.toml").string() + " -o " + (dir_ / "ro").string();
  if (::geteuid() != 0) {
    fs::permissions(dir_ / "ro", fs::perms::owner_read | fs::perms::owner_exec);
    const CliRun ro = run(ro_bake);
    EXPECT_EQ(ro.code, 4) << ro.err;
    EXPECT_TRUE(listing(dir_ / "ro").empty());
    fs::permissions(dir_ / "ro", fs::perms::owner_all);
  } else {
    const fs::path code = dir_ / "ro_code.txt", list = dir_ / "ro_listing.txt";
    const fs::path err = dir_ / "ro_stderr.txt";
    const std::string inner = "mount -t tmpfs -o ro,size=1m tmpfs " + (dir_ / "ro").string() +
                              " || exit 99; " + SB_CLI + " " + ro_bake + " >/dev/null 2>" +
                              err.string() + " </dev/null; echo $? >" + code.string() + "; ls -A " +
                              (dir_ / "ro").string() + " >" + list.string();
    const int status = std::system(("unshare -m sh -c '" + inner + "'").c_str());
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
      GTEST_SKIP() << "root without a mount namespace of its own: the read-only folder is untested";
    EXPECT_EQ(slurp(code), "4\n") << slurp(err);
    EXPECT_NE(slurp(err).find((dir_ / "ro").string()), std::string::npos) << slurp(err);
    EXPECT_EQ(slurp(list), "") << "left in the read-only folder";
  }
}

TEST_F(Cli, UsageErrorsAndHelp) {
  EXPECT_EQ(run("--help").code, 0);
  const CliRun v = run("--version");
  EXPECT_EQ(v.code, 0);
  EXPECT_NE(v.out.find("shadowbake"), std::string::npos);
  EXPECT_EQ(run("bake").code, 2);
  EXPECT_EQ(run("bake x.toml -o out --method nonsense").code, 2);
  EXPECT_EQ(run("bake x.toml -o out --resolution 0").code, 2);
  EXPECT_EQ(run("frobnicate").code, 2);
}

}  // namespace
