// Tests of atlas packing (src/texels/atlas_packing.h): receivers fit as few atlases as they
// should, never overlap with their padding, land where their scale and offset say, and the same
// sides give the same layout.
#include "texels/atlas_packing.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace sb {
namespace {

// A level's worth of receivers: a few large (floors, walls), many small (props).
std::vector<int> level_sides() {
  std::vector<int> sides = {700, 520, 520, 380, 380, 300};
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> prop(24, 200);
  for (int i = 0; i < 40; ++i) sides.push_back(prop(rng));
  return sides;
}

struct Rect {
  int atlas, x0, y0, x1, y1;  // half-open, padding included
};

std::vector<Rect> padded_rects(const AtlasLayout& layout) {
  std::vector<Rect> rects;
  for (const AtlasPlacement& p : layout.placements)
    rects.push_back({p.atlas, p.x - layout.padding, p.y - layout.padding,
                     p.x + p.side + layout.padding, p.y + p.side + layout.padding});
  return rects;
}

TEST(AtlasPacking, PaddedRectanglesLieInsideTheirAtlasAndApart) {
  const AtlasSettings settings{2048, 2};
  const AtlasLayout layout = pack_atlases(level_sides(), settings);
  ASSERT_EQ(layout.placements.size(), level_sides().size());
  const std::vector<Rect> rects = padded_rects(layout);
  for (std::size_t i = 0; i < rects.size(); ++i) {
    const Rect& a = rects[i];
    ASSERT_GE(a.atlas, 0);
    ASSERT_LT(std::size_t(a.atlas), layout.sizes.size());
    const int size = layout.sizes[std::size_t(a.atlas)];
    EXPECT_GE(a.x0, 0);
    EXPECT_GE(a.y0, 0);
    EXPECT_LE(a.x1, size);
    EXPECT_LE(a.y1, size);
    for (std::size_t j = i + 1; j < rects.size(); ++j) {
      const Rect& b = rects[j];
      if (a.atlas != b.atlas) continue;
      const bool apart = a.x1 <= b.x0 || b.x1 <= a.x0 || a.y1 <= b.y0 || b.y1 <= a.y0;
      EXPECT_TRUE(apart) << "receivers " << i << " and " << j << " overlap";
    }
  }
}

TEST(AtlasPacking, FillsFewAtlases) {
  const std::vector<int> sides = level_sides();
  double area = 0;
  for (int s : sides) area += double(s + 4) * double(s + 4);
  const AtlasLayout layout = pack_atlases(sides, {2048, 2});
  // 2.0 M padded texels: they fit one 2048² atlas (4.2 M) with room to spare.
  ASSERT_LT(area, 0.6 * 2048.0 * 2048.0);
  EXPECT_EQ(layout.sizes.size(), 1u);
  // Twice the receivers need a second atlas, not more.
  std::vector<int> twice = sides;
  twice.insert(twice.end(), sides.begin(), sides.end());
  twice.insert(twice.end(), sides.begin(), sides.end());
  EXPECT_EQ(pack_atlases(twice, {2048, 2}).sizes.size(), 2u);
}

TEST(AtlasPacking, TheLastAtlasShrinksToWhatItHolds) {
  const AtlasLayout layout = pack_atlases({100, 60, 60}, {2048, 2});
  ASSERT_EQ(layout.sizes.size(), 1u);
  EXPECT_EQ(layout.sizes[0], 256);  // 104 + 64 wide fits 256, not 128
}

TEST(AtlasPacking, TheSameSidesGiveTheSameLayout) {
  const AtlasLayout a = pack_atlases(level_sides(), {1024, 3});
  const AtlasLayout b = pack_atlases(level_sides(), {1024, 3});
  ASSERT_EQ(a.sizes, b.sizes);
  for (std::size_t i = 0; i < a.placements.size(); ++i) {
    EXPECT_EQ(a.placements[i].atlas, b.placements[i].atlas);
    EXPECT_EQ(a.placements[i].x, b.placements[i].x);
    EXPECT_EQ(a.placements[i].y, b.placements[i].y);
  }
}

TEST(AtlasPacking, ScaleAndOffsetMapTheUnitSquareOntoTheRectangle) {
  const AtlasPlacement p{0, 100, 300, 50};
  const int size = 1024;
  // v up: uv (0, 1) is the rectangle's top-left texel corner (x, y), uv (1, 0) its bottom right.
  const auto up = atlas_scale_offset(p, size, true);
  EXPECT_DOUBLE_EQ(0 * up[0] + up[2], 100.0 / size);
  EXPECT_DOUBLE_EQ(1 * up[1] + up[3], 1.0 - 300.0 / size);
  EXPECT_DOUBLE_EQ(1 * up[0] + up[2], 150.0 / size);
  EXPECT_DOUBLE_EQ(0 * up[1] + up[3], 1.0 - 350.0 / size);
  // v down (glTF): v' = 0 is the top row.
  const auto down = atlas_scale_offset(p, size, false);
  EXPECT_DOUBLE_EQ(0 * down[1] + down[3], 300.0 / size);
  EXPECT_DOUBLE_EQ(1 * down[1] + down[3], 350.0 / size);
  EXPECT_DOUBLE_EQ(down[0], up[0]);
  EXPECT_DOUBLE_EQ(down[2], up[2]);
}

}  // namespace
}  // namespace sb
