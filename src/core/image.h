// A float image in lightmap layout: row 0 is v = 1, pixel (x, y) covers
// u in [x/w, (x+1)/w], v in [1-(y+1)/h, 1-y/h]. Channels are interleaved.
#pragma once

#include <cstddef>
#include <vector>

#include "core/fresh_memory.h"

namespace sb {

struct Image {
  int width = 0;
  int height = 0;
  int channels = 3;
  // width * height * channels, row-major, interleaved. FreshVector: the constructor fills it in
  // parallel, where a serial fill of a 4096² lightmap's 200 MB was a tenth of a second of page
  // faults before any value was set.
  FreshVector<float> pixels;

  Image() = default;
  Image(int w, int h, int c, float fill = 0.0f);

  float* at(int x, int y) { return &pixels[(std::size_t(y) * width + x) * channels]; }
  const float* at(int x, int y) const { return &pixels[(std::size_t(y) * width + x) * channels]; }
};

}  // namespace sb
