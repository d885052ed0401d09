// The receiver's covered texels by pixel (texel_grid.h), from its coverage mask.
#include "methods/backprojection/texel_grid.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace sb {

TexelGrid::TexelGrid(const TexelSpace& space)
    : width(space.width),
      height(space.height),
      words_per_row_(std::size_t(space.width + 63) / 64),
      bits_(words_per_row_ * std::size_t(space.height), 0),
      first_(bits_.size(), 0) {
  // From the coverage mask, which marks exactly the texels' pixels: each row's count, their
  // running sum (the index of each row's first texel), then each row's words.
  const auto row_pixels = [&](int y) {
    return space.covered.data() + std::size_t(y) * std::size_t(width);
  };
  std::vector<std::int32_t> row_first(std::size_t(height) + 1, 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const auto& r) {
    for (int y = r.begin(); y != r.end(); ++y) {
      const std::uint8_t* row = row_pixels(y);
      row_first[std::size_t(y) + 1] = std::int32_t(std::count(row, row + width, std::uint8_t(1)));
    }
  });
  for (int y = 0; y < height; ++y) row_first[std::size_t(y) + 1] += row_first[std::size_t(y)];
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const auto& r) {
    for (int y = r.begin(); y != r.end(); ++y) {
      const std::uint8_t* row = row_pixels(y);
      std::int32_t next = row_first[std::size_t(y)];
      for (std::size_t w = 0; w < words_per_row_; ++w) {
        const std::size_t word = std::size_t(y) * words_per_row_ + w;
        first_[word] = next;
        std::uint64_t bits = 0;
        const int x1 = std::min(width, int(w + 1) * 64);
        for (int x = int(w) * 64; x < x1; ++x)
          if (row[x]) bits |= std::uint64_t(1) << (x & 63);
        bits_[word] = bits;
        next += std::popcount(bits);
      }
    }
  });
}

}  // namespace sb
