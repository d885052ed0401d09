// Tests of dilate (src/texels/dilation.cpp): ring-by-ring growth from covered texels, the margin
// limit, and independence from scan order.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <vector>

#include "texels/texel_space.h"

namespace sb {
namespace {

constexpr float kUntouched = -5.0f;  // background value, so an overwritten texel shows

std::size_t index_of(const Image& image, int x, int y) {
  return std::size_t(y) * std::size_t(image.width) + std::size_t(x);
}

// A straightforward reference: each ring reads a copy of the image and mask taken before it.
void dilate_reference(Image& image, std::vector<std::uint8_t> filled, int margin) {
  for (int ring = 0; ring < margin; ++ring) {
    const Image before = image;
    const std::vector<std::uint8_t> filled_before = filled;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) {
        if (filled_before[index_of(image, x, y)]) continue;
        std::vector<double> sum(std::size_t(image.channels), 0.0);
        int count = 0;
        for (int ny = y - 1; ny <= y + 1; ++ny)
          for (int nx = x - 1; nx <= x + 1; ++nx) {
            if (nx < 0 || ny < 0 || nx >= image.width || ny >= image.height) continue;
            if (!filled_before[index_of(image, nx, ny)]) continue;
            for (int c = 0; c < image.channels; ++c) sum[std::size_t(c)] += before.at(nx, ny)[c];
            ++count;
          }
        if (count == 0) continue;
        for (int c = 0; c < image.channels; ++c)
          image.at(x, y)[c] = float(sum[std::size_t(c)] / count);
        filled[index_of(image, x, y)] = 1;
      }
  }
}

TEST(Dilation, SingleTexelWithMarginTwoFillsFiveByFive) {
  Image image(9, 9, 3, kUntouched);
  std::vector<std::uint8_t> covered(81, 0);
  const float value[3] = {0.25f, 0.5f, 7.0f};
  for (int c = 0; c < 3; ++c) image.at(4, 4)[c] = value[c];
  covered[index_of(image, 4, 4)] = 1;
  dilate(image, covered, 2);
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 9; ++x) {
      const bool inside = std::abs(x - 4) <= 2 && std::abs(y - 4) <= 2;
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(image.at(x, y)[c], inside ? value[c] : kUntouched)
            << "(" << x << ", " << y << ") channel " << c;
    }
}

TEST(Dilation, MarginZeroChangesNothing) {
  Image image(6, 5, 1, kUntouched);
  std::vector<std::uint8_t> covered(30, 0);
  image.at(2, 2)[0] = 1.0f;
  covered[index_of(image, 2, 2)] = 1;
  const Image before = image;
  dilate(image, covered, 0);
  EXPECT_EQ(image.pixels, before.pixels);
}

TEST(Dilation, TexelsBeyondTheMarginAreUntouched) {
  Image image(12, 4, 1, kUntouched);
  std::vector<std::uint8_t> covered(48, 0);
  for (int y = 0; y < 4; ++y) {
    image.at(0, y)[0] = 2.0f;
    covered[index_of(image, 0, y)] = 1;
  }
  dilate(image, covered, 3);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 12; ++x)
      EXPECT_EQ(image.at(x, y)[0], x <= 3 ? 2.0f : kUntouched) << "(" << x << ", " << y << ")";
}

TEST(Dilation, RingsAverageOnlyEarlierRings) {
  // Column 0 covered with 1; column 4 covered with 4 in row 2 only. Ring 1 fills column 1 with 1,
  // and (3, 1), (3, 2), (3, 3), (4, 1), (4, 3) with 4. Texel (2, 2) is not filled in ring 1 (no
  // covered neighbour), and in ring 2 it takes the mean of its six ring-1 neighbours:
  // (1 + 1 + 1 + 4 + 4 + 4) / 6 = 2.5. A scan that let ring 1 read its own writes would give it 1
  // (left to right) or 4 (right to left) already in ring 1.
  Image image(5, 5, 1, kUntouched);
  std::vector<std::uint8_t> covered(25, 0);
  for (int y = 0; y < 5; ++y) {
    image.at(0, y)[0] = 1.0f;
    covered[index_of(image, 0, y)] = 1;
  }
  image.at(4, 2)[0] = 4.0f;
  covered[index_of(image, 4, 2)] = 1;

  Image one_ring = image;
  dilate(one_ring, covered, 1);
  EXPECT_EQ(one_ring.at(2, 2)[0], kUntouched);
  EXPECT_EQ(one_ring.at(1, 2)[0], 1.0f);
  EXPECT_EQ(one_ring.at(3, 2)[0], 4.0f);
  EXPECT_EQ(one_ring.at(4, 1)[0], 4.0f);
  EXPECT_EQ(one_ring.at(3, 0)[0], kUntouched);

  dilate(image, covered, 2);
  EXPECT_FLOAT_EQ(image.at(2, 2)[0], 2.5f);
  EXPECT_FLOAT_EQ(image.at(2, 1)[0], 2.2f);  // (1, 0..2) = 1 and (3, 1), (3, 2) = 4
  EXPECT_FLOAT_EQ(image.at(2, 0)[0], 2.0f);  // (1, 0), (1, 1) = 1 and (3, 1) = 4
  EXPECT_FLOAT_EQ(image.at(3, 0)[0], 4.0f);  // (3, 1), (4, 1) = 4
}

TEST(Dilation, MatchesACopyPerRingReferenceOnRandomMasks) {
  std::mt19937 random(7);
  std::uniform_real_distribution<float> value(0.0f, 10.0f);
  std::bernoulli_distribution is_covered(0.03);
  for (int trial = 0; trial < 5; ++trial) {
    Image image(61, 47, 2, kUntouched);
    std::vector<std::uint8_t> covered(std::size_t(61) * 47, 0);
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        if (is_covered(random)) {
          covered[index_of(image, x, y)] = 1;
          for (int c = 0; c < 2; ++c) image.at(x, y)[c] = value(random);
        }
    Image expected = image;
    dilate_reference(expected, covered, 4);
    dilate(image, covered, 4);
    ASSERT_EQ(image.pixels.size(), expected.pixels.size());
    for (std::size_t i = 0; i < image.pixels.size(); ++i)
      ASSERT_EQ(image.pixels[i], expected.pixels[i]) << "trial " << trial << ", value " << i;
  }
}

}  // namespace
}  // namespace sb
