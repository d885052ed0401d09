// Tests of shards and their merge (src/pipeline/shards.h): for every scene of scenes/ and
// N = 1…8 shards, the merge writes what one bake of the whole scene writes, byte for byte (the
// manifest but for its timings), per-light images, shadow masks, atlases and glTF included; a
// rerun of a shard writes the same bytes; a missing, duplicated or foreign shard is a one-line
// error; cost balancing deals uneven receivers better than round robin; receivers split into tiles
// of rows merge to the single bake too.
#include "pipeline/shards.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "formats/manifest.h"
#include "formats/outputs.h"
#include "pipeline/bake.h"
#include "pipeline/tiles.h"

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
  set_setting(scene->bake, "shadow_map", 256);
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

// Tiles (pipeline/tiles.h): receivers dearer than a shard's share split into tiles of rows, for
// each method that allows it, merge to the single bake byte for byte (seams, dilation, per-light
// images, shadow masks and glTF included); some receiver must have been split.
struct TiledCase {
  std::string scene, method;
};

void PrintTo(const TiledCase& c, std::ostream* os) { *os << c.scene << " by " << c.method; }

class TiledScenes : public ::testing::TestWithParam<TiledCase> {};

TEST_P(TiledScenes, MergeToTheSingleBake) {
  const TiledCase& c = GetParam();
  std::string name = c.scene + "_" + c.method;
  for (char& ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  ShardsFixture f("tiles_" + name);
  Scene scene = quick(c.scene);
  scene.bake.resolution = 96;  // three blocks of rows: tiles of 32 and 64 rows
  scene.bake.method = c.method;
  if (c.method == "ambient-occlusion") {
    scene.bake.quantity = Quantity::ambient_occlusion;
    scene.output.per_light = scene.output.shadowmask = false;
  }
  f.bake_whole(scene, f.dir() / "whole");
  int tiles = 0;
  for (int n = 2; n <= 4; ++n) {
    std::vector<fs::path> shards;
    for (int k = 0; k < n; ++k) {
      shards.push_back(f.dir() / ("shard_" + std::to_string(n) + "_" + std::to_string(k)));
      f.bake_shard(scene, {k, n, ShardBalance::cost}, shards.back());
      for (const auto& e : fs::directory_iterator(shards.back()))
        tiles += e.path().filename().string().find("_rows_") != std::string::npos;
    }
    const fs::path merged = f.dir() / ("merged_" + std::to_string(n));
    f.merge(shards, merged);
    const std::vector<std::string> diff = differences(f.dir() / "whole", merged);
    EXPECT_TRUE(diff.empty()) << name << ", N = " << n << ": " << diff.size()
                              << " file(s) differ, first " << (diff.empty() ? "" : diff[0]);
    for (const fs::path& s : shards) fs::remove_all(s);
    fs::remove_all(merged);
  }
  EXPECT_GT(tiles, 0) << "no receiver was split";
}

INSTANTIATE_TEST_SUITE_P(Methods, TiledScenes,
                         ::testing::Values(TiledCase{"room/scene.toml", "backprojection"},
                                           TiledCase{"seams/scene.toml", "backprojection"},
                                           TiledCase{"room/scene.toml", "reference"},
                                           TiledCase{"seams/scene.toml", "ambient-occlusion"}),
                         [](const auto& info) {
                           std::string name = info.param.scene + "_" + info.param.method;
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

TEST(Tiles, AReceiverDearerThanAShareIsSplitIntoRowsThatCoverItOnce) {
  // One 4096² receiver of uniform cost in 8 shards: a tile of 512 rows each.
  const std::vector<std::vector<double>> one(1, std::vector<double>(128, 1.0));
  for (int k = 0; k < 8; ++k) {
    const std::vector<ShardUnit> units = shard_units(one, {4096}, true, {k, 8});
    ASSERT_EQ(units.size(), 1u) << k;
    ASSERT_TRUE(units[0].rows) << k;
    EXPECT_EQ(units[0].rows->end - units[0].rows->begin, 512) << k;
  }
  // Without tiles, or with a method that cannot be split, it stays whole in one shard.
  EXPECT_EQ(shard_units(one, {4096}, false, {0, 8}), (std::vector<ShardUnit>{{0, std::nullopt}}));
  EXPECT_TRUE(shard_units(one, {4096}, false, {1, 8}).empty());
  // A floor dearer than the rest, a wall, props: every receiver's rows once over the shards, the
  // props whole, and the dearest shard within LPT's bound of a share.
  std::vector<std::vector<double>> costs = {
      std::vector<double>(64, 3.0), {5, 1, 2}, std::vector<double>(16, 2.0), {1}, {0.5, 0.5}};
  costs[0][10] = 40;  // a dense corner
  const std::vector<int> sides = {2048, 96, 512, 32, 50};
  double total = 0;
  for (const auto& blocks : costs)
    for (double c : blocks) total += c;
  for (int n = 2; n <= 6; ++n) {
    std::vector<std::vector<int>> rows(costs.size());
    double dearest = 0;
    for (int k = 0; k < n; ++k) {
      double load = 0;
      for (const ShardUnit& u : shard_units(costs, sides, true, {k, n})) {
        const RowRange r = u.rows.value_or(RowRange{0, sides[u.receiver]});
        EXPECT_EQ(r.begin % kTileRows, 0);
        for (int y = r.begin; y < r.end; ++y) rows[u.receiver].push_back(y);
        for (int b = r.begin / kTileRows; b * kTileRows < r.end; ++b) load += costs[u.receiver][b];
        if (u.receiver == 3 || u.receiver == 4) {
          EXPECT_FALSE(u.rows) << "a prop was split";
        }
      }
      dearest = std::max(dearest, load);
    }
    for (std::size_t r = 0; r < costs.size(); ++r) {
      std::sort(rows[r].begin(), rows[r].end());
      std::vector<int> all(std::size_t(sides[r]));
      for (int y = 0; y < sides[r]; ++y) all[std::size_t(y)] = y;
      EXPECT_EQ(rows[r], all) << "receiver " << r << ", N = " << n;
    }
    EXPECT_LE(dearest, 1.5 * total / n + 40) << n;
  }
}

TEST(Tiles, AJoinWithRowsMissingOrTwiceIsAnError) {
  ShardsFixture f("tile_errors");
  Scene scene = quick("room/scene.toml");
  scene.bake.resolution = 96;
  std::vector<ReceiverBake> tiles;
  for (int k = 0; k < 3; ++k) {
    BakeOptions options;
    options.shard = ShardSpec{k, 3};
    auto result = bake(scene, options);
    ASSERT_TRUE(result) << result.error().message;
    for (ReceiverBake& r : result->receivers)
      if (r.tile && r.name == "floor") tiles.push_back(std::move(r));
  }
  ASSERT_GE(tiles.size(), 2u);  // the floor costs more than a shard's share
  std::sort(tiles.begin(), tiles.end(), [](const ReceiverBake& a, const ReceiverBake& b) {
    return a.tile->begin < b.tile->begin;
  });
  auto joined = join_tiles(scene, {tiles}, "here");
  ASSERT_TRUE(joined) << joined.error().message;
  EXPECT_EQ(joined->at(0).image.height, 96);
  const RowRange first = *tiles[0].tile, second = *tiles[1].tile;
  std::vector<ReceiverBake> gap = tiles, twice = tiles, short_of = tiles;
  gap.erase(gap.begin());
  twice.push_back(tiles[1]);
  short_of.pop_back();
  EXPECT_EQ(join_tiles(scene, {gap}, "here").error().message,
            fmt::format("here: receiver 'floor': its tiles leave rows {} to {} out (a shard is "
                        "missing)",
                        first.begin, first.end - 1));
  EXPECT_EQ(join_tiles(scene, {twice}, "here").error().message,
            fmt::format("here: receiver 'floor': its tiles overlap at row {}", second.begin));
  EXPECT_EQ(join_tiles(scene, {short_of}, "here").error().message,
            fmt::format("here: receiver 'floor': its tiles end at row {} of 96",
                        short_of.back().tile->end));
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
