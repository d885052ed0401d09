// Image (image.h): its pixels filled in parallel.
#include "core/image.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

namespace sb {

Image::Image(int w, int h, int c, float fill)
    : width(w), height(h), channels(c), pixels(std::size_t(w) * std::size_t(h) * std::size_t(c)) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pixels.size(), std::size_t(1) << 18),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      std::fill(pixels.begin() + std::ptrdiff_t(r.begin()),
                                pixels.begin() + std::ptrdiff_t(r.end()), fill);
                    });
}

}  // namespace sb
