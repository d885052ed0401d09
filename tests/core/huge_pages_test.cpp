// Huge-page advice: any range is accepted (unaligned, shorter than a huge page, empty, null), and
// advised memory keeps what is written to it, before and after the advice.
#include "core/huge_pages.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <vector>

namespace sb {
namespace {

TEST(HugePages, AdviceKeepsContentsOfAnyRange) {
  std::vector<std::uint32_t> large(std::size_t(3) << 20);  // 12 MiB: whole huge pages inside
  std::iota(large.begin(), large.end(), 7u);
  advise_huge_pages(large.data(), large.size() * sizeof(std::uint32_t));
  advise_huge_pages(large.data() + 1, 4096);  // shorter than a huge page: left alone
  advise_huge_pages(large.data() + 3, 0);
  advise_huge_pages(nullptr, 1 << 22);
  for (std::size_t i = 0; i < large.size(); i += 4099) ASSERT_EQ(large[i], std::uint32_t(i + 7));
  for (std::size_t i = 0; i < large.size(); i += 4099) large[i] = 1;
  for (std::size_t i = 0; i < large.size(); i += 4099) ASSERT_EQ(large[i], 1u);
  EXPECT_EQ(large[1], 8u);
}

}  // namespace
}  // namespace sb
