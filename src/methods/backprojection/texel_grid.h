// The receiver's covered texels by pixel, as every stage of the `backprojection` bake
// (backprojection_bake.cpp) finds them: built once per receiver (texel_grid.cpp).
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "texels/texel_space.h"

namespace sb {

// Texel indices by pixel, -1 where no texel is covered: a bit per pixel and, per word of 64
// pixels, the index of its first covered texel (texels are in row-major order, so the rest follow
// by counting bits). A 4096² receiver's grid is 3 MB, where an index per pixel would be 67 MB of
// fresh memory, zeroed and written for every light.
class TexelGrid {
 public:
  int width = 0, height = 0;
  explicit TexelGrid(const TexelSpace& space);
  std::int32_t texel(int x, int y) const {
    if (x < 0 || y < 0 || x >= width || y >= height) return -1;
    const std::size_t word = std::size_t(y) * words_per_row_ + std::size_t(x >> 6);
    const std::uint64_t bit = std::uint64_t(1) << (x & 63);
    if (!(bits_[word] & bit)) return -1;
    return first_[word] + std::popcount(bits_[word] & (bit - 1));
  }
  // The texels of the tile of kSide × kSide pixels whose corner is (kSide·tx, kSide·ty), by
  // pixel (row-major within the tile), -1 where none: a count of bits per row, not per pixel.
  static constexpr int kSide = 8;
  void tile_texels(int tx, int ty, std::array<std::int32_t, kSide * kSide>& out) const {
    const int x0 = tx * kSide;
    const std::size_t shift = std::size_t(x0 & 63);
    for (int row = 0; row < kSide; ++row) {
      const int y = ty * kSide + row;
      std::int32_t* at = out.data() + row * kSide;
      if (y >= height) {
        std::fill(at, at + kSide, -1);
        continue;
      }
      const std::size_t word = std::size_t(y) * words_per_row_ + std::size_t(x0 >> 6);
      std::int32_t next =
          first_[word] + std::popcount(bits_[word] & ((std::uint64_t(1) << shift) - 1));
      const std::uint64_t bits = bits_[word] >> shift;
      for (int k = 0; k < kSide; ++k) at[k] = (bits >> k & 1) ? next++ : -1;
    }
  }
  // Calls f(texel, x, y) for each covered pixel of rows [y0, y1), in row-major order: the texels
  // with their pixels, without reading their records.
  template <class F>
  void for_each(int y0, int y1, F&& f) const {
    for (int y = y0; y < y1; ++y)
      for (std::size_t w = 0; w < words_per_row_; ++w) {
        const std::size_t word = std::size_t(y) * words_per_row_ + w;
        std::size_t t = std::size_t(first_[word]);
        for (std::uint64_t bits = bits_[word]; bits != 0; bits &= bits - 1)
          f(t++, int(w * 64) + std::countr_zero(bits), y);
      }
  }

 private:
  std::size_t words_per_row_ = 0;
  std::vector<std::uint64_t> bits_;
  std::vector<std::int32_t> first_;
};

}  // namespace sb
