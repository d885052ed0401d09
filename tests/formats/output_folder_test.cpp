// Tests of OutputFolder (output_folder.cpp): files appear all together or not at all, an
// unpublished bake leaves the previous files, a publish killed half way is finished by the next
// process, the lock keeps a second writer out, and names held by folders are refused first.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "formats/output_folder.h"

namespace sb {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

class OutputFolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("shadowbake_output_folder_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A folder holding a previous bake's a.txt and b.txt.
  void previous_bake() {
    fs::create_directories(dir_);
    std::ofstream(dir_ / "a.txt") << "old a";
    std::ofstream(dir_ / "b.txt") << "old b";
  }

  fs::path dir_;
};

TEST_F(OutputFolderTest, PublishesEveryFileAndLeavesNoStaging) {
  previous_bake();
  {
    auto folder = OutputFolder::open(dir_);
    ASSERT_TRUE(folder) << folder.error().message;
    ASSERT_TRUE(write_text_file(folder->staged("a.txt"), "new a"));
    ASSERT_TRUE(write_text_file(folder->staged("images/c.txt"), "new c"));
    // Nothing is visible before publishing.
    EXPECT_EQ(slurp(dir_ / "a.txt"), "old a");
    EXPECT_FALSE(fs::exists(dir_ / "images"));
    ASSERT_TRUE(folder->publish({"a.txt", "images/c.txt"}));
  }
  EXPECT_EQ(slurp(dir_ / "a.txt"), "new a");
  EXPECT_EQ(slurp(dir_ / "b.txt"), "old b");  // not ours to remove
  EXPECT_EQ(slurp(dir_ / "images" / "c.txt"), "new c");
  EXPECT_EQ(listing(dir_), (std::vector<std::string>{"a.txt", "b.txt", "images"}));
}

TEST_F(OutputFolderTest, UnpublishedBakeLeavesThePreviousFiles) {
  previous_bake();
  {
    auto folder = OutputFolder::open(dir_);
    ASSERT_TRUE(folder);
    ASSERT_TRUE(write_text_file(folder->staged("a.txt"), "new a"));
    // A file that was never written cannot be published, and nothing is.
    EXPECT_FALSE(folder->publish({"a.txt", "missing.txt"}));
  }
  EXPECT_EQ(slurp(dir_ / "a.txt"), "old a");
  EXPECT_EQ(listing(dir_), (std::vector<std::string>{"a.txt", "b.txt"}));
}

TEST_F(OutputFolderTest, FolderItMadeIsRemovedWhenNothingWasPublished) {
  {
    auto folder = OutputFolder::open(dir_);
    ASSERT_TRUE(folder);
    ASSERT_TRUE(write_text_file(folder->staged("a.txt"), "new a"));
  }
  EXPECT_FALSE(fs::exists(dir_));
}

TEST_F(OutputFolderTest, InterruptedPublishIsFinishedByTheNextOpen) {
  previous_bake();
  // What a process killed between its first and second rename leaves: a staging folder with a
  // journal, a.txt already renamed (new), b.txt still staged.
  const fs::path staging = dir_ / ".shadowbake-staging.999999.dead";
  fs::create_directories(staging);
  std::ofstream(dir_ / "a.txt", std::ios::trunc) << "new a";
  std::ofstream(staging / "b.txt") << "new b";
  std::ofstream(staging / ".publish") << "a.txt\nb.txt\n";
  {
    auto folder = OutputFolder::open(dir_);
    ASSERT_TRUE(folder) << folder.error().message;
  }
  EXPECT_EQ(slurp(dir_ / "a.txt"), "new a");
  EXPECT_EQ(slurp(dir_ / "b.txt"), "new b");
  EXPECT_EQ(listing(dir_), (std::vector<std::string>{"a.txt", "b.txt"}));
}

TEST_F(OutputFolderTest, StagingOfAKilledBakeIsRemoved) {
  previous_bake();
  const fs::path staging = dir_ / ".shadowbake-staging.999999.dead";
  fs::create_directories(staging / "images");
  std::ofstream(staging / "a.txt") << "half a";
  std::ofstream(staging / "images" / "c.txt") << "half c";
  {
    auto folder = OutputFolder::open(dir_);
    ASSERT_TRUE(folder);
  }
  EXPECT_EQ(slurp(dir_ / "a.txt"), "old a");
  EXPECT_EQ(listing(dir_), (std::vector<std::string>{"a.txt", "b.txt"}));
}

TEST_F(OutputFolderTest, SecondWriterIsRefusedWhileTheFirstHoldsTheFolder) {
  auto first = OutputFolder::open(dir_);
  ASSERT_TRUE(first);
  auto second = OutputFolder::open(dir_);
  ASSERT_FALSE(second);
  EXPECT_NE(second.error().message.find("another shadowbake process (pid " +
                                        std::to_string(::getpid()) + ")"),
            std::string::npos)
      << second.error().message;
  EXPECT_EQ(second.error().kind, ErrorKind::output);
}

TEST_F(OutputFolderTest, RefusesNamesHeldByFoldersBeforeWriting) {
  fs::create_directories(dir_ / "manifest.json");
  auto folder = OutputFolder::open(dir_);
  ASSERT_TRUE(folder);
  const Status targets = folder->check_targets({"a.txt", "manifest.json"});
  ASSERT_FALSE(targets);
  EXPECT_NE(targets.error().message.find("manifest.json: cannot write: a folder"),
            std::string::npos)
      << targets.error().message;
}

TEST_F(OutputFolderTest, RefusesAFileAsTheFolder) {
  std::ofstream(dir_.string()) << "not a folder";
  auto folder = OutputFolder::open(dir_);
  ASSERT_FALSE(folder);
  EXPECT_NE(folder.error().message.find("not a folder"), std::string::npos);
  fs::remove(dir_);
}

}  // namespace
}  // namespace sb
