#include "core/tiled_images.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace sb
