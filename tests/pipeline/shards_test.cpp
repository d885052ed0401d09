// Tests of shards and their merge (src/pipeline/shards.h): for every scene of scenes/ and
// N = 1…8 shards, the merge writes what one bake of the whole scene writes, byte for byte (the
// manifest but for its timings), per-light images, shadow masks, atlases and glTF included; a
// rerun of a shard writes the same bytes; a missing, duplicated or foreign shard is a one-line
// error; cost balancing deals uneven receivers better than round robin.
#include "pipeline/shards.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "pipeline/manifest.h"
#include "pipeline/outputs.h"

namespace sb {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A manifest without the keys that hold timings.
nlohmann::json without_timings(nlohmann::json j) {
  if (j.is_object()) {
    nlohmann::json out = nlohmann::json::object();
    for (auto& [key, value] : j.items())
      if (key.find("seconds") == std::string::npos) out[key] = without_timings(value);
    return out;
  }
  if (j.is_array())
    for (auto& value : j) value = without_timings(value);
  return j;
}

// The files of folder `a` that `b` lacks or holds other bytes of (manifests: but for timings).
std::vector<std::string> differences(const fs::path& a, const fs::path& b) {
  std::vector<std::string> out;
  std::size_t count_a = 0, count_b = 0;
  for (const auto& e : fs::directory_iterator(b)) count_b += e.is_regular_file();
  for (const auto& e : fs::directory_iterator(a)) {
    if (!e.is_regular_file()) continue;
    ++count_a;
    const std::string name = e.path().filename().string();
    if (!fs::exists(b / name)) {
      out.push_back(name + " (missing)");
    } else if (name == kManifestFile) {
      if (without_timings(nlohmann::json::parse(slurp(e.path()))) !=
          without_timings(nlohmann::json::parse(slurp(b / name))))
        out.push_back(name);
    } else if (slurp(e.path()) != slurp(b / name)) {
      out.push_back(name);
    }
  }
  if (count_a != count_b)
    out.push_back("file counts " + std::to_string(count_a) + " and " + std::to_string(count_b));
  return out;
}

class ShardsFixture {
 public:
  explicit ShardsFixture(const std::string& name) {
    dir_ = fs::temp_directory_path() /
           ("shadowbake_shards_" + std::to_string(::getpid()) + "_" + name);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~ShardsFixture() { fs::remove_all(dir_); }

  const fs::path& dir() const { return dir_; }

  void bake_whole(const Scene& scene, const fs::path& folder) {
    auto result = bake(scene);
    ASSERT_TRUE(result) << result.error().message;
    auto out = OutputFolder::open(folder);
    ASSERT_TRUE(out) << out.error().message;
    Status s = write_outputs(*out, scene, scene.bake, *result);
    ASSERT_TRUE(s) << s.error().message;
  }

  void bake_shard(const Scene& scene, const ShardSpec& spec, const fs::path& folder) {
    BakeOptions options;
    options.shard = spec;
    auto result = bake(scene, options);
    ASSERT_TRUE(result) << result.error().message;
    auto out = OutputFolder::open(folder);
    ASSERT_TRUE(out) << out.error().message;
    Status s = write_shard(*out, scene, spec, *result);
    ASSERT_TRUE(s) << s.error().message;
  }

  void merge(const std::vector<fs::path>& shards, const fs::path& folder) {
    auto merged = merge_shards(shards);
    ASSERT_TRUE(merged) << merged.error().message;
    auto out = OutputFolder::open(folder);
    ASSERT_TRUE(out) << out.error().message;
    Status s = write_outputs(*out, merged->scene, merged->scene.bake, merged->result);
    ASSERT_TRUE(s) << s.error().message;
  }

 private:
  fs::path dir_;
};

// A scene of scenes/ small and quick, with every kind of output.
Scene quick(const std::string& file) {
  auto scene = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/" + file);
  EXPECT_TRUE(scene) << scene.error().message;
  if (!scene) throw std::runtime_error(scene.error().message);
  scene->bake.resolution = 24;
  scene->bake.texels_per_metre = 0;
  scene->bake.samples = 2;
  scene->bake.shadow_map = 256;
  scene->output.per_light = true;
  scene->output.shadowmask = true;
  scene->output.gltf = true;
  scene->output.atlas = AtlasSettings{128, 2};
  return *scene;
}

class EveryScene : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryScene, MergedShardsEqualTheSingleBake) {
  std::string name = GetParam();
  std::replace(name.begin(), name.end(), '/', '_');
  ShardsFixture f(name);
  const Scene scene = quick(GetParam());
  f.bake_whole(scene, f.dir() / "whole");
  for (int n = 1; n <= 8; ++n) {
    std::vector<fs::path> shards;
    for (int k = 0; k < n; ++k) {
      shards.push_back(f.dir() / ("shard_" + std::to_string(n) + "_" + std::to_string(k)));
      f.bake_shard(scene, {k, n, ShardBalance::cost}, shards.back());
    }
    const fs::path merged = f.dir() / ("merged_" + std::to_string(n));
    f.merge(shards, merged);
    const std::vector<std::string> diff = differences(f.dir() / "whole", merged);
    EXPECT_TRUE(diff.empty()) << GetParam() << ", N = " << n << ": " << diff.size()
                              << " file(s) differ, first " << (diff.empty() ? "" : diff[0]);
    for (const fs::path& s : shards) fs::remove_all(s);
    fs::remove_all(merged);
  }
}

std::vector<std::string> scene_files() {
  std::vector<std::string> files;
  for (const auto& folder : fs::directory_iterator(std::string(SB_SOURCE_DIR) + "/scenes"))
    if (folder.is_directory())
      for (const auto& file : fs::directory_iterator(folder.path()))
        if (file.path().extension() == ".toml")
          files.push_back(folder.path().filename().string() + "/" +
                          file.path().filename().string());
  std::sort(files.begin(), files.end());
  return files;
}

INSTANTIATE_TEST_SUITE_P(Scenes, EveryScene, ::testing::ValuesIn(scene_files()),
                         [](const auto& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

TEST(Shards, ARerunWritesTheSameBytesButTimings) {
  ShardsFixture f("rerun");
  const Scene scene = quick("hall/scene_six_lights.toml");
  f.bake_shard(scene, {1, 3, ShardBalance::cost}, f.dir() / "a");
  f.bake_shard(scene, {1, 3, ShardBalance::cost}, f.dir() / "b");
  std::vector<std::string> diff = differences(f.dir() / "a", f.dir() / "b");
  diff.erase(std::remove(diff.begin(), diff.end(), std::string(kShardTimingsFile)), diff.end());
  EXPECT_TRUE(diff.empty()) << diff[0];
}

TEST(Shards, MissingDuplicatedOrForeignShardsAreNamed) {
  ShardsFixture f("errors");
  const Scene scene = quick("room/scene.toml");
  const fs::path s0 = f.dir() / "s0", s1 = f.dir() / "s1", s2 = f.dir() / "s2";
  f.bake_shard(scene, {0, 3, ShardBalance::cost}, s0);
  f.bake_shard(scene, {1, 3, ShardBalance::cost}, s1);
  f.bake_shard(scene, {2, 3, ShardBalance::cost}, s2);
  const auto error = [](const std::vector<fs::path>& folders) {
    auto merged = merge_shards(folders);
    EXPECT_FALSE(merged);
    return merged ? std::string() : merged.error().message;
  };
  EXPECT_EQ(error({s0, s2}),
            "shard 1/3 is missing: none of the 2 folder(s) given holds it (bake it with --shard "
            "1/3)");
  EXPECT_EQ(error({s0, s1, s1, s2}),
            "shard 1/3 given twice: " + s1.string() + " and " + s1.string());
  EXPECT_EQ(error({s0, f.dir()}), f.dir().string() + ": not a shadowbake shard (no shard.json)");
  // A shard of the same scene with other settings.
  Scene other = scene;
  other.bake.samples = 3;
  f.bake_shard(other, {1, 3, ShardBalance::cost}, f.dir() / "other");
  const std::string foreign = error({s0, f.dir() / "other", s2});
  EXPECT_NE(foreign.find(": a shard of another scene, meshes or settings than"), std::string::npos)
      << foreign;
  // A shard of a split into 4.
  f.bake_shard(scene, {1, 4, ShardBalance::cost}, f.dir() / "four");
  EXPECT_NE(error({s0, f.dir() / "four", s2}).find("another split"), std::string::npos);
  // Damaged data: one byte of a texel changed, or the file cut short.
  fs::path data;
  for (const auto& e : fs::directory_iterator(s1))
    if (e.path().filename().string().rfind("receiver_", 0) == 0) data = e.path();
  ASSERT_FALSE(data.empty());
  const std::string original = slurp(data);
  std::string flipped = original;
  flipped[flipped.size() / 2] ^= 0x10;
  std::ofstream(data, std::ios::binary | std::ios::trunc) << flipped;
  std::string damaged = error({s0, s1, s2});
  EXPECT_NE(damaged.find("damaged shard data: its checksum"), std::string::npos) << damaged;
  std::ofstream(data, std::ios::binary | std::ios::trunc) << original.substr(0, 100);
  damaged = error({s0, s1, s2});
  EXPECT_NE(damaged.find("damaged shard data"), std::string::npos) << damaged;
  std::ofstream(data, std::ios::binary | std::ios::trunc) << original;
  EXPECT_TRUE(merge_shards({s0, s1, s2}));
}

TEST(ShardSpec, ParsesKOfNAndTakesAutoFromTheScheduler) {
  auto spec = parse_shard("2/5");
  ASSERT_TRUE(spec);
  EXPECT_EQ(spec->index, 2);
  EXPECT_EQ(spec->count, 5);
  EXPECT_FALSE(parse_shard("5/5"));
  EXPECT_FALSE(parse_shard("-1/5"));
  EXPECT_FALSE(parse_shard("1/0"));
  EXPECT_FALSE(parse_shard("1"));
  ::unsetenv("SLURM_ARRAY_TASK_ID");
  ::unsetenv("JOB_COMPLETION_INDEX");
  EXPECT_EQ(parse_shard("auto/4").error().message,
            "--shard auto/4: auto takes K from SLURM_ARRAY_TASK_ID or JOB_COMPLETION_INDEX, and "
            "neither is set");
  ::setenv("JOB_COMPLETION_INDEX", "3", 1);
  EXPECT_EQ(parse_shard("auto/4")->index, 3);
  ::setenv("SLURM_ARRAY_TASK_ID", "1", 1);
  EXPECT_EQ(parse_shard("auto/4")->index, 1);
  ::setenv("SLURM_ARRAY_TASK_ID", "7", 1);
  EXPECT_FALSE(parse_shard("auto/4"));
  ::unsetenv("SLURM_ARRAY_TASK_ID");
  ::unsetenv("JOB_COMPLETION_INDEX");
}

TEST(ShardBalance, CostDealsUnevenReceiversBetterThanRoundRobin) {
  // A floor that costs as much as the rest together, and props of every size.
  const std::vector<double> costs = {100, 4, 9, 50, 1, 1, 30, 2, 8, 25, 3, 60};
  double total = 0;
  for (double c : costs) total += c;
  for (int n = 2; n <= 4; ++n) {
    double by_cost = 0, by_count = 0;
    std::vector<int> seen(costs.size(), 0);
    for (int k = 0; k < n; ++k) {
      double a = 0, b = 0;
      for (std::size_t r : shard_receivers(costs, {k, n, ShardBalance::cost})) {
        a += costs[r];
        ++seen[r];
      }
      for (std::size_t r : shard_receivers(costs, {k, n, ShardBalance::count})) b += costs[r];
      by_cost = std::max(by_cost, a);
      by_count = std::max(by_count, b);
    }
    EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), std::ptrdiff_t(costs.size()));
    EXPECT_LE(by_cost, by_count) << n;
    EXPECT_LE(by_cost, std::max(total / n, 100.0) * 4.0 / 3.0) << n;  // LPT's bound
  }
}

}  // namespace
}  // namespace sb
