// Huge-page advice: the advised range is marked for huge pages where the kernel offers them (the
// mapping's "hg" flag in /proc/self/smaps), a range that holds no whole huge page is left alone,
// any range is accepted (unaligned, short, empty, null), and advised memory keeps what is written
// to it, before and after the advice.
#include "core/huge_pages.h"

#include <gtest/gtest.h>
#include <sys/mman.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

namespace sb {
namespace {

// The VmFlags of the mapping of /proc/self/smaps that holds `address`; empty if none is found.
std::string vm_flags_at(const void* address) {
  const auto a = reinterpret_cast<std::uintptr_t>(address);
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> lo >> dash >> hi && dash == '-' &&
        line.find(' ') != std::string::npos && line.find(':') > line.find(' ')) {
      inside = lo <= a && a < hi;
      continue;
    }
    if (inside && line.rfind("VmFlags:", 0) == 0) return line.substr(8) + " ";
  }
  return {};
}

bool kernel_offers_huge_pages() {
  return std::filesystem::exists("/sys/kernel/mm/transparent_hugepage/enabled") &&
         std::ifstream("/proc/self/smaps").good();
}

// A fresh anonymous mapping of `bytes`, its own mapping in smaps until advised.
struct Mapping {
  void* data = nullptr;
  std::size_t bytes = 0;
  explicit Mapping(std::size_t n) : bytes(n) {
    data = mmap(nullptr, n, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (data == MAP_FAILED) data = nullptr;
  }
  ~Mapping() {
    if (data) munmap(data, bytes);
  }
};

TEST(HugePages, AdvisedRangeIsMarkedAndAShortOneIsNot) {
  if (!kernel_offers_huge_pages()) GTEST_SKIP() << "no transparent huge pages here";
  constexpr std::size_t kHuge = std::size_t(2) << 20;
  Mapping large(6 * kHuge);
  ASSERT_NE(large.data, nullptr);
  auto* bytes = static_cast<unsigned char*>(large.data);
  // The first 2 MiB-aligned address inside, and a point past the first whole huge page there.
  const auto first = (reinterpret_cast<std::uintptr_t>(bytes) + kHuge - 1) & ~(kHuge - 1);
  const void* inside = reinterpret_cast<const void*>(first + kHuge + 4096);
  EXPECT_EQ(vm_flags_at(inside).find(" hg "), std::string::npos) << vm_flags_at(inside);
  advise_huge_pages(bytes, large.bytes);
  EXPECT_NE(vm_flags_at(inside).find(" hg "), std::string::npos) << vm_flags_at(inside);

  Mapping small(kHuge);  // shorter than a whole aligned huge page, wherever it lies
  ASSERT_NE(small.data, nullptr);
  advise_huge_pages(static_cast<unsigned char*>(small.data) + 4096, kHuge - 8192);
  EXPECT_EQ(vm_flags_at(small.data).find(" hg "), std::string::npos) << vm_flags_at(small.data);
}

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
