// TiledImages (tiled_images.h).
#include "core/tiled_images.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>

namespace sb {

// An unnamed file in the temporary folder ($TMPDIR, else /tmp), made at the first write and gone
// with the last images that share it. Many threads may write and read it at once: each write
// takes its own range at the end (pwrite, pread at offsets).
class TiledImages::ScratchFile {
 public:
  ScratchFile() = default;
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;
  ~ScratchFile() {
    if (fd_ >= 0) ::close(fd_);
  }

  // The offset the values were written at; -1 where no file can be made or written.
  std::int64_t write(const float* values, std::size_t count) {
    std::call_once(opened_, [this] { open(); });
    if (fd_ < 0) return -1;
    const std::size_t bytes = count * sizeof(float);
    const std::int64_t at = end_.fetch_add(std::int64_t(bytes));
    const char* from = reinterpret_cast<const char*>(values);
    for (std::size_t done = 0; done < bytes;) {
      const ssize_t n = ::pwrite(fd_, from + done, bytes - done, off_t(at + std::int64_t(done)));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return -1;  // a full disk: the image stays in memory
      done += std::size_t(n);
    }
    return at;
  }

  void read(std::int64_t at, float* values, std::size_t count) const {
    const std::size_t bytes = count * sizeof(float);
    char* to = reinterpret_cast<char*>(values);
    for (std::size_t done = 0; done < bytes;) {
      const ssize_t n = ::pread(fd_, to + done, bytes - done, off_t(at + std::int64_t(done)));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0)
        throw std::runtime_error(std::string("per-light images' scratch file: cannot read back (") +
                                 (n < 0 ? std::strerror(errno) : "it is shorter than written") +
                                 ")");
      done += std::size_t(n);
    }
  }

 private:
  void open() {
    std::error_code error;
    const std::filesystem::path folder = std::filesystem::temp_directory_path(error);
    if (error) return;
    std::string path = (folder / "shadowbake-per-light-XXXXXX").string();
    fd_ = ::mkstemp(path.data());
    if (fd_ >= 0) ::unlink(path.c_str());  // gone from the folder now, from the disk at close
  }

  std::once_flag opened_;
  int fd_ = -1;
  std::atomic<std::int64_t> end_{0};
};

TiledImages::TiledImages(std::size_t count, int width, int height, std::vector<float> fill,
                         Spill spill)
    : width_(width),
      height_(height),
      fill_(std::move(fill)),
      images_(count),
      scratch_(spill == Spill::to_file ? std::make_shared<ScratchFile>() : nullptr) {}

TiledImages TiledImages::like(std::size_t count, int width, int height) const {
  TiledImages out(count, width, height, fill_);
  out.scratch_ = scratch_;
  return out;
}

std::size_t TiledImages::value_count(const Tiles& t) const {
  return t.tiles.size() * std::size_t(kSide * kSide) * fill_.size();
}

const float* TiledImages::values_of(std::size_t i, std::vector<float>& read) const {
  const Tiles& t = images_[i];
  if (t.parked_at < 0) return t.values.data();
  read.resize(value_count(t));
  scratch_->read(t.parked_at, read.data(), read.size());
  return read.data();
}

std::vector<float> TiledImages::values(std::size_t i) const {
  std::vector<float> read;
  const float* v = values_of(i, read);
  if (images_[i].parked_at < 0) read.assign(v, v + value_count(images_[i]));
  return read;
}

void TiledImages::park(std::size_t i) {
  Tiles& t = images_[i];
  if (!scratch_ || t.parked_at >= 0 || t.values.empty()) return;
  const std::int64_t at = scratch_->write(t.values.data(), t.values.size());
  if (at < 0) return;
  t.parked_at = at;
  t.values = std::vector<float>();
}

void TiledImages::reserve(std::size_t i, std::span<const std::uint32_t> tiles,
                          std::span<const float> start) {
  Tiles& t = images_[i];
  t.parked_at = -1;
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
  if (t.parked_at >= 0) throw std::logic_error("TiledImages::at: the image is in its scratch file");
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
  std::vector<float> read;
  const float* values = values_of(i, read);
  for (std::size_t s = 0; s < t.tiles.size(); ++s) {
    const int x0 = int(t.tiles[s] % std::uint32_t(tiles_x())) * kSide;
    const int y0 = int(t.tiles[s] / std::uint32_t(tiles_x())) * kSide;
    for (int dy = 0; dy < kSide && y0 + dy < height_; ++dy) {
      const int w = std::min(kSide, width_ - x0);
      const float* from = &values[(s * kSide * kSide + std::size_t(dy) * kSide) * std::size_t(c)];
      std::copy(from, from + std::size_t(w) * std::size_t(c), image.at(x0, y0 + dy));
    }
  }
  return image;
}

void TiledImages::assign(std::size_t i, const Image& image) {
  Tiles& t = images_[i];
  t.tiles.clear();
  t.values.clear();
  t.parked_at = -1;
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
  park(i);
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
  park(i);
  return true;
}

std::size_t TiledImages::bytes() const {
  std::size_t sum = 0;
  for (const Tiles& t : images_) sum += t.values.size() * sizeof(float) + t.tiles.size() * 4;
  return sum;
}

}  // namespace sb
