// Images of one size kept by tiles of kSide × kSide pixels: an image holds values only at the
// tiles it was given (or that differ from the fill), and every other pixel reads as the fill.
// A level's per-light images: each light reaches a few rooms of a lightmap a thousand lights
// share, so a full image per light (1,916 of them on OpenArena's oacmpctf3: 12 GB) would hold
// mostly the fill; these hold what the lights reach. One image is made whole (dense) when a
// stage needs it whole (dilation, seams, a file), and given back (assign) after.
// Even by tiles, a thousand lights' images together outgrow the bake (oacmpctf3's per-light
// images: 750 MB, against a bake of 240 MB). Images made to spill (Spill::to_file) move each
// image's values to a scratch file as it is given back (assign, restore, park), so that what
// memory holds is the images a stage works on, one light at a time, whatever the number of
// lights; reading one back (dense, each_pixel, values) costs a read of its tiles.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/image.h"

namespace sb {

class TiledImages {
 public:
  static constexpr int kSide = 8;

  // Whether images given back move to a scratch file (where one cannot be written, they stay).
  enum class Spill { no, to_file };

  TiledImages() = default;
  // `count` images of width × height, fill.size() channels, each all fill.
  TiledImages(std::size_t count, int width, int height, std::vector<float> fill,
              Spill spill = Spill::no);
  // `count` images of width × height with this one's fill and spilling, each all fill.
  TiledImages like(std::size_t count, int width, int height) const;

  std::size_t size() const { return images_.size(); }
  bool empty() const { return images_.empty(); }
  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return int(fill_.size()); }
  const std::vector<float>& fill() const { return fill_; }
  int tiles_x() const { return (width_ + kSide - 1) / kSide; }
  int tiles_y() const { return (height_ + kSide - 1) / kSide; }

  // Image i's values at `tiles` (ascending indices, row-major over tiles_x()), each pixel
  // `start` (a value per channel); what it held before is dropped.
  void reserve(std::size_t i, std::span<const std::uint32_t> tiles, std::span<const float> start);
  // Pixel (x, y) of image i where its tile holds values, else null (the pixel is the fill).
  // Image i must be in memory (reserved, or not yet given back to a scratch file).
  float* at(std::size_t i, int x, int y);
  const float* at(std::size_t i, int x, int y) const;
  // Image i whole, its pixels outside its tiles `outside` (the fill where empty).
  Image dense(std::size_t i, std::span<const float> outside = {}) const;
  // Image i from `image` (this size and channel count): the tiles with a pixel other than the fill.
  void assign(std::size_t i, const Image& image);
  // Image i's tiles (ascending) and their values (per tile kSide² pixels, row-major, interleaved).
  std::span<const std::uint32_t> tiles(std::size_t i) const { return images_[i].tiles; }
  std::vector<float> values(std::size_t i) const;
  // Image i from tiles and values as tiles() and values() give them (a file's); false, and
  // image i left all fill, where they are not an image's (out of order, beyond the image, sizes).
  bool restore(std::size_t i, std::vector<std::uint32_t> tiles, std::vector<float> values);
  // Image i's values to the scratch file, where these images spill (else they stay).
  void park(std::size_t i);
  // visit(x, y, values) for each pixel of image i's tiles that lies inside the image.
  template <class Visit>
  void each_pixel(std::size_t i, Visit&& visit) const {
    const Tiles& t = images_[i];
    std::vector<float> read;
    const float* values = values_of(i, read);
    const std::size_t c = fill_.size();
    for (std::size_t s = 0; s < t.tiles.size(); ++s) {
      const int x0 = int(t.tiles[s] % std::uint32_t(tiles_x())) * kSide;
      const int y0 = int(t.tiles[s] / std::uint32_t(tiles_x())) * kSide;
      for (int j = 0; j < kSide * kSide; ++j) {
        const int x = x0 + j % kSide, y = y0 + j / kSide;
        if (x < width_ && y < height_)
          visit(x, y, &values[(s * std::size_t(kSide * kSide) + std::size_t(j)) * c]);
      }
    }
  }
  // The bytes the tiles hold in memory (not those in the scratch file).
  std::size_t bytes() const;

  class ScratchFile;  // tiled_images.cpp

 private:
  struct Tiles {
    std::vector<std::uint32_t> tiles;
    std::vector<float> values;    // empty while parked
    std::int64_t parked_at = -1;  // the values' offset in the scratch file, where parked
  };
  std::size_t slot(const Tiles& t, int x, int y) const;  // t.tiles.size() where absent
  std::size_t value_count(const Tiles& t) const;
  // Image i's values: in memory, or read from the scratch file into `read`.
  const float* values_of(std::size_t i, std::vector<float>& read) const;
  int width_ = 0, height_ = 0;
  std::vector<float> fill_;
  std::vector<Tiles> images_;
  // Shared by copies: what is parked is never written over (a light parked again is appended).
  std::shared_ptr<ScratchFile> scratch_;
};

}  // namespace sb
