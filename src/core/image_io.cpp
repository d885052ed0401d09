#include "core/image_io.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/strutil.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <mutex>

#include <fmt/format.h>

#include <system_error>
#include "core/memory_size.h"

namespace sb {

namespace fs = std::filesystem;

namespace {

// OIIO's messages may span lines; errors are one line.
std::string one_line(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r' || c == '\t') c = ' ';
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

// libpng prints its errors and warnings ("libpng error: cHRM: Read error") on stderr itself, as
// OpenImageIO 2.4 installs no handler of its own, and OIIO's error message repeats them. So while
// OIIO reads or writes an image, file descriptor 2 points at /dev/null. One image is read or
// written at a time (kStderrMutex); bakes do not read or write images while they work.
std::mutex kStderrMutex;

class QuietStderr {
 public:
  QuietStderr() : lock_(kStderrMutex) {
    std::fflush(stderr);
    const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    saved_ = null >= 0 ? ::dup(STDERR_FILENO) : -1;
    if (saved_ >= 0) ::dup2(null, STDERR_FILENO);
    if (null >= 0) ::close(null);
  }
  ~QuietStderr() {
    if (saved_ < 0) return;
    std::fflush(stderr);
    ::dup2(saved_, STDERR_FILENO);
    ::close(saved_);
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;

 private:
  std::lock_guard<std::mutex> lock_;
  int saved_ = -1;
};

// A sibling of `path` that no other writer uses: hidden, with the process id.
fs::path temporary_sibling(const fs::path& path) {
  // Built by appending: GCC 12 gives a false -Wrestrict on `"." + std::string` at -O3.
  std::string name(".");
  name.append(path.filename().string()).append(".tmp").append(std::to_string(::getpid()));
  return path.parent_path() / name;
}

}  // namespace

namespace {

void remove_quietly(const fs::path& path) {
  std::error_code ec;
  fs::remove(path, ec);
}

}  // namespace

namespace {

// The 8-bit values write_image stores: value·255 rounded, clamped to [0, 255], NaN as 0.
std::vector<std::uint8_t> to_bytes(const Image& image) {
  std::vector<std::uint8_t> bytes(image.pixels.size());
  std::transform(image.pixels.begin(), image.pixels.end(), bytes.begin(), [](float v) {
    const float c = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
    return std::uint8_t(std::lround(c * 255.0f));
  });
  return bytes;
}

}  // namespace

Expected<std::vector<std::uint8_t>> png_bytes(const Image& image, const std::string& what) {
  QuietStderr quiet;
  std::vector<unsigned char> buffer;
  OIIO::Filesystem::IOVecOutput proxy(buffer);
  auto out = OIIO::ImageOutput::create("png");
  if (!out) return output_error(what + ": cannot encode PNG: " + OIIO::geterror());
  OIIO::ImageSpec spec(image.width, image.height, image.channels, OIIO::TypeDesc::UINT8);
  spec.attribute("DateTime", "");
  spec.attribute("oiio:UnassociatedAlpha", 1);
  if (!out->set_ioproxy(&proxy) || !out->open("memory.png", spec)) {
    return output_error(what + ": cannot encode PNG: " + out->geterror());
  }
  const std::vector<std::uint8_t> bytes = to_bytes(image);
  bool ok = out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
  ok = out->close() && ok;
  if (!ok) return output_error(what + ": cannot encode PNG: " + out->geterror());
  return std::vector<std::uint8_t>(buffer.begin(), buffer.end());
}

Status write_image(const fs::path& path, const Image& image, PixelFormat format) {
  QuietStderr quiet;
  const fs::path tmp = temporary_sibling(path);
  // The format comes from the final name's extension; the temporary name has none OIIO knows.
  auto out = OIIO::ImageOutput::create(path.string());
  if (!out) {
    return output_error(path.string() + ": cannot write images of this type: " + OIIO::geterror());
  }
  const auto type = format == PixelFormat::float32   ? OIIO::TypeDesc::FLOAT
                    : format == PixelFormat::float16 ? OIIO::TypeDesc::HALF
                                                     : OIIO::TypeDesc::UINT8;
  OIIO::ImageSpec spec(image.width, image.height, image.channels, type);
  if (format != PixelFormat::uint8) spec.attribute("compression", "zip");
  // A fourth channel is data (RGBM's multiplier, a shadow mask's fourth light), not an alpha
  // the colour was multiplied by: stored as given, never divided by it.
  spec.attribute("oiio:UnassociatedAlpha", 1);
  // OIIO stamps EXR files with the current time unless DateTime is set; an empty one writes
  // none, so the same bake gives the same bytes.
  spec.attribute("DateTime", "");
  if (!out->open(tmp.string(), spec)) {
    std::string why = out->geterror();
    remove_quietly(tmp);
    return output_error(path.string() + ": cannot write: " + why);
  }
  bool ok;
  if (format != PixelFormat::uint8) {
    // OIIO converts the floats to half itself.
    ok = out->write_image(OIIO::TypeDesc::FLOAT, image.pixels.data());
  } else {
    const std::vector<std::uint8_t> bytes = to_bytes(image);
    ok = out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
  }
  ok = out->close() && ok;
  if (!ok) {
    std::string why = out->geterror();
    remove_quietly(tmp);
    return output_error(path.string() + ": cannot write: " + why);
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    remove_quietly(tmp);
    return output_error(path.string() + ": cannot write: " + ec.message());
  }
  return Ok{};
}

Expected<Image> read_image(const fs::path& path, bool linearise, std::uint64_t max_bytes) {
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (ec) return input_error(path.string() + ": cannot read image: " + ec.message());
  if (!fs::is_regular_file(status)) {
    return input_error(path.string() + ": cannot read image: " +
                       (fs::is_directory(status) ? "it is a folder"
                                                 : "not a regular file (a device, a FIFO or a "
                                                   "socket)"));
  }
  QuietStderr quiet;
  // A fourth channel comes back as stored: OIIO would otherwise multiply the colour of a PNG by
  // its alpha, which for RGBM or a shadow mask is data.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path.string(), &config);
  if (!in) return input_error(path.string() + ": cannot read image: " + one_line(OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  const double bytes = double(spec.width) * spec.height * spec.nchannels * sizeof(float);
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || bytes > double(max_bytes)) {
    return input_error(fmt::format(
        "{}: cannot read image: its header says {}x{} pixels of {} channel(s), {} as float; at "
        "most {} is read",
        path.string(), spec.width, spec.height, spec.nchannels, format_bytes(bytes),
        format_bytes(double(max_bytes))));
  }
  Image image(spec.width, spec.height, spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data())) {
    return input_error(path.string() + ": cannot read image: " + one_line(in->geterror()));
  }
  if (linearise && OIIO::Strutil::iequals(spec.get_string_attribute("oiio:ColorSpace"), "sRGB")) {
    const int alpha = spec.alpha_channel;
    for (std::size_t i = 0; i < image.pixels.size(); ++i) {
      if (int(i % std::size_t(spec.nchannels)) == alpha) continue;
      float& v = image.pixels[i];
      v = v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
    }
  }
  return image;
}

}  // namespace sb
