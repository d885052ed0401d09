#include <gtest/gtest.h>

#include <set>

#include "core/sampling.h"

namespace sb {
namespace {

TEST(Sampling, PerfectSquareHasOnePointPerCell) {
  Rng rng(1);
  std::vector<Vec2> u;
  stratified_samples(64, rng, u);
  ASSERT_EQ(u.size(), 64u);
  std::set<int> cells;
  for (const auto& p : u) {
    ASSERT_GE(p.x(), 0.0);
    ASSERT_LT(p.x(), 1.0);
    cells.insert(int(p.x() * 8) + 8 * int(p.y() * 8));
  }
  EXPECT_EQ(cells.size(), 64u);
}

TEST(Sampling, OtherCountsUseDistinctCells) {
  Rng rng(2);
  std::vector<Vec2> u;
  stratified_samples(50, rng, u);  // 8 × 7 cells, 50 of them
  ASSERT_EQ(u.size(), 50u);
  std::set<int> cells;
  for (const auto& p : u) cells.insert(int(p.x() * 8) + 8 * int(p.y() * 7));
  EXPECT_EQ(cells.size(), 50u);
}

TEST(Sampling, SameSeedSameSamples) {
  std::vector<Vec2> a, b, c;
  Rng r1(stream_seed(5, 1, 2)), r2(stream_seed(5, 1, 2)), r3(stream_seed(5, 1, 3));
  stratified_samples(16, r1, a);
  stratified_samples(16, r2, b);
  stratified_samples(16, r3, c);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
}

TEST(Sampling, UniformMean) {
  Rng rng(3);
  double sum = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) sum += rng.next_double();
  EXPECT_NEAR(sum / n, 0.5, 0.003);
}

}  // namespace
}  // namespace sb
