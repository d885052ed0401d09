// TiledImages (tiled_images.h).
#include "core/tiled_images.h"

#include <algorithm>
#include <utility>

namespace sb {

TiledImages::TiledImages(std::size_t count, int width, int height, std::vector<float> fill)
    : width_(width), height_(height), fill_(std::move(fill)), images_(count) {}

void TiledImages::reserve(std::size_t i, std::span<const std::uint32_t> tiles,
                          std::span<const float> start) {
  Tiles& t = images_[i];
  t.tiles.assign(tiles.begin(), tiles.end());
  const std::size_t c = fill_.size(), per_tile = std::size_t(kSide * kSide) * c;
  t.values.resize(t.tiles.size() * per_tile);
  for (std::size_t k = 0; k < t.values.size(); ++k) t.values[k] = start[k % c];
}

std::size_t TiledImages::slot(const Tiles& t, int x, int y) const {
  const std::uint32_t tile =
      std::uint32_t(y / kSide) * std::uint32_t(tiles_x()) + std::uint32_t(x / kSide);
  const auto it = std::lower_bound(t.tiles.begin(), t.tiles.end(), tile);
  return it != t.tiles.end() && *it == tile ? std::size_t(it - t.tiles.begin()) : t.tiles.size();
}

float* TiledImages::at(std::size_t i, int x, int y) {
  Tiles& t = images_[i];
  const std::size_t s = slot(t, x, y);
  if (s == t.tiles.size()) return nullptr;
  const std::size_t pixel = std::size_t(y % kSide) * kSide + std::size_t(x % kSide);
  return &t.values[(s * kSide * kSide + pixel) * fill_.size()];
}

const float* TiledImages::at(std::size_t i, int x, int y) const {
  return const_cast<TiledImages*>(this)->at(i, x, y);
}

Image TiledImages::dense(std::size_t i, std::span<const float> outside) const {
  const std::span<const float> background =
      outside.empty() ? std::span<const float>(fill_) : outside;
  const int c = channels();
  // Image's constructor fills with one value; a per-channel background is written pixel by pixel.
  bool uniform = true;
  for (float v : background) uniform = uniform && v == background[0];
  Image image(width_, height_, c, uniform ? background[0] : 0.0f);
  if (!uniform)
    for (std::size_t k = 0; k < image.pixels.size(); k += std::size_t(c))
      std::copy(background.begin(), background.end(), &image.pixels[k]);
  const Tiles& t = images_[i];
  for (std::size_t s = 0; s < t.tiles.size(); ++s) {
    const int x0 = int(t.tiles[s] % std::uint32_t(tiles_x())) * kSide;
    const int y0 = int(t.tiles[s] / std::uint32_t(tiles_x())) * kSide;
    for (int dy = 0; dy < kSide && y0 + dy < height_; ++dy) {
      const int w = std::min(kSide, width_ - x0);
      const float* from = &t.values[(s * kSide * kSide + std::size_t(dy) * kSide) * std::size_t(c)];
      std::copy(from, from + std::size_t(w) * std::size_t(c), image.at(x0, y0 + dy));
    }
  }
  return image;
}

void TiledImages::assign(std::size_t i, const Image& image) {
  Tiles& t = images_[i];
  t.tiles.clear();
  t.values.clear();
  const std::size_t c = fill_.size();
  for (int ty = 0; ty < tiles_y(); ++ty)
    for (int tx = 0; tx < tiles_x(); ++tx) {
      const int x0 = tx * kSide, y0 = ty * kSide, w = std::min(kSide, width_ - x0);
      bool differs = false;
      for (int dy = 0; dy < kSide && y0 + dy < height_ && !differs; ++dy) {
        const float* px = image.at(x0, y0 + dy);
        for (std::size_t k = 0; k < std::size_t(w) * c && !differs; ++k)
          differs = px[k] != fill_[k % c];
      }
      if (!differs) continue;
      t.tiles.push_back(std::uint32_t(ty) * std::uint32_t(tiles_x()) + std::uint32_t(tx));
      const std::size_t at = t.values.size();
      t.values.resize(at + std::size_t(kSide * kSide) * c);
      for (std::size_t k = at; k < t.values.size(); ++k) t.values[k] = fill_[(k - at) % c];
      for (int dy = 0; dy < kSide && y0 + dy < height_; ++dy) {
        const float* px = image.at(x0, y0 + dy);
        std::copy(px, px + std::size_t(w) * c, &t.values[at + std::size_t(dy) * kSide * c]);
      }
    }
}

bool TiledImages::restore(std::size_t i, std::vector<std::uint32_t> tiles,
                          std::vector<float> values) {
  Tiles& t = images_[i];
  t = Tiles();
  const std::size_t all = std::size_t(tiles_x()) * std::size_t(tiles_y());
  for (std::size_t k = 0; k < tiles.size(); ++k)
    if (tiles[k] >= all || (k > 0 && tiles[k] <= tiles[k - 1])) return false;
  if (values.size() != tiles.size() * std::size_t(kSide * kSide) * fill_.size()) return false;
  t.tiles = std::move(tiles);
  t.values = std::move(values);
  return true;
}

std::size_t TiledImages::bytes() const {
  std::size_t sum = 0;
  for (const Tiles& t : images_) sum += t.values.size() * sizeof(float) + t.tiles.size() * 4;
  return sum;
}

}  // namespace sb
