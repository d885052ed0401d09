#include "core/tiled_images.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

namespace sb {
namespace {

TEST(TiledImages, PixelsOutsideTheTilesReadAsTheFill) {
  // 20 × 10 pixels: 3 × 2 tiles, the last column and row of tiles partial.
  TiledImages images(2, 20, 10, {1.0f, 0.0f});
  const std::vector<std::uint32_t> tiles = {1, 5};
  const float start[2] = {0.5f, 0.25f};
  images.reserve(0, tiles, start);
  EXPECT_EQ(images.at(0, 0, 0), nullptr);  // tile 0
  ASSERT_NE(images.at(0, 9, 3), nullptr);  // tile 1
  EXPECT_EQ(images.at(0, 9, 3)[0], 0.5f);
  images.at(0, 19, 9)[0] = 0.75f;  // tile 5, the last pixel
  EXPECT_EQ(images.at(1, 9, 3), nullptr);
  const Image whole = images.dense(0);
  EXPECT_EQ(whole.at(0, 0)[0], 1.0f);
  EXPECT_EQ(whole.at(0, 0)[1], 0.0f);
  EXPECT_EQ(whole.at(9, 3)[1], 0.25f);
  EXPECT_EQ(whole.at(19, 9)[0], 0.75f);
  const float outside[2] = {-1.0f, -1.0f};
  EXPECT_EQ(images.dense(0, outside).at(0, 0)[0], -1.0f);
  EXPECT_EQ(images.dense(1).at(19, 9)[0], 1.0f);
}

TEST(TiledImages, AssignKeepsTheTilesThatDifferFromTheFill) {
  TiledImages images(1, 20, 10, {0.0f, 0.0f, 0.0f});
  Image image(20, 10, 3, 0.0f);
  image.at(17, 9)[2] = 2.0f;  // tile 5 (partial)
  image.at(3, 2)[0] = 1.0f;   // tile 0
  images.assign(0, image);
  ASSERT_EQ(images.tiles(0).size(), 2u);
  EXPECT_EQ(images.tiles(0)[0], 0u);
  EXPECT_EQ(images.tiles(0)[1], 5u);
  const Image back = images.dense(0);
  EXPECT_EQ(back.pixels.size(), image.pixels.size());
  for (std::size_t i = 0; i < image.pixels.size(); ++i) EXPECT_EQ(back.pixels[i], image.pixels[i]);
  EXPECT_EQ(images.bytes(), 2 * (64 * 3 * sizeof(float) + 4));
}

TEST(TiledImages, RestoreRefusesWhatNoImageHolds) {
  TiledImages images(1, 16, 16, {0.0f});
  EXPECT_TRUE(images.restore(0, {0, 3}, std::vector<float>(2 * 64, 1.0f)));
  EXPECT_EQ(images.dense(0).at(15, 15)[0], 1.0f);
  EXPECT_FALSE(images.restore(0, {3, 0}, std::vector<float>(2 * 64)));  // out of order
  EXPECT_FALSE(images.restore(0, {4}, std::vector<float>(64)));         // beyond the image
  EXPECT_FALSE(images.restore(0, {1}, std::vector<float>(63)));         // short
  EXPECT_TRUE(images.tiles(0).empty());
}

Image test_image(float seed) {
  Image image(20, 10, 3, 0.0f);
  image.at(17, 9)[2] = seed;        // tile 5 (partial)
  image.at(3, 2)[0] = seed + 1.0f;  // tile 0
  image.at(9, 4)[1] = seed + 2.0f;  // tile 1
  return image;
}

void expect_same(const Image& a, const Image& b) {
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  for (std::size_t i = 0; i < a.pixels.size(); ++i) ASSERT_EQ(a.pixels[i], b.pixels[i]) << i;
}

// Spilled images leave memory as they are given back and read back as they were given, each
// after its latest assignment (a light given back twice, as finishing it does).
TEST(TiledImages, SpilledImagesReadBackAsGiven) {
  TiledImages images(3, 20, 10, {0.0f, 0.0f, 0.0f}, TiledImages::Spill::to_file);
  images.assign(0, test_image(1.0f));
  images.assign(1, test_image(5.0f));
  EXPECT_EQ(images.bytes(), 2 * 3 * 4u);  // the tiles' indices alone
  images.assign(0, test_image(9.0f));
  expect_same(images.dense(0), test_image(9.0f));
  expect_same(images.dense(1), test_image(5.0f));
  EXPECT_EQ(images.dense(2).at(3, 2)[0], 0.0f);
  const std::vector<float> values = images.values(1);
  ASSERT_EQ(values.size(), 3u * 64 * 3);
  EXPECT_EQ(values[(2 * 64 + 1 * 8 + 1) * 3 + 2], 5.0f);  // tile 5, pixel (1, 1): (17, 9)
  int seen = 0;
  images.each_pixel(1,
                    [&](int x, int y, const float* v) { seen += x == 9 && y == 4 && v[1] == 7; });
  EXPECT_EQ(seen, 1);
  // A parked image is not written in place: at() refuses it.
  EXPECT_THROW(images.at(0, 3, 2), std::logic_error);
  // Images made like these share their scratch file; restored ones spill too.
  TiledImages cropped = images.like(1, 20, 10);
  ASSERT_TRUE(
      cropped.restore(0, std::vector<std::uint32_t>(images.tiles(1).begin(), images.tiles(1).end()),
                      images.values(1)));
  EXPECT_EQ(cropped.bytes(), 3 * 4u);
  expect_same(cropped.dense(0), test_image(5.0f));
  // Reserved images are in memory, written in place, until parked.
  const std::uint32_t tile[1] = {5};
  const float start[3] = {0.5f, 0.5f, 0.5f};
  images.reserve(2, tile, start);
  images.at(2, 16, 8)[0] = 4.0f;
  EXPECT_GT(images.bytes(), 64 * 3 * sizeof(float));
  images.park(2);
  EXPECT_EQ(images.dense(2).at(16, 8)[0], 4.0f);
  EXPECT_EQ(images.dense(2).at(17, 8)[0], 0.5f);
}

// Where no scratch file can be made, spilled images stay in memory and read the same.
TEST(TiledImages, ImagesStayInMemoryWithoutAScratchFolder) {
  const char* before = std::getenv("TMPDIR");
  const std::string kept = before ? before : "";
  ::setenv("TMPDIR", "/nonexistent/shadowbake-test", 1);
  TiledImages images(1, 20, 10, {0.0f, 0.0f, 0.0f}, TiledImages::Spill::to_file);
  images.assign(0, test_image(2.0f));
  if (before)
    ::setenv("TMPDIR", kept.c_str(), 1);
  else
    ::unsetenv("TMPDIR");
  EXPECT_EQ(images.bytes(), 3 * (64 * 3 * sizeof(float) + 4));
  expect_same(images.dense(0), test_image(2.0f));
}

}  // namespace
}  // namespace sb
