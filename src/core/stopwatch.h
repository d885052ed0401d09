// Wall-clock seconds since a point of the steady clock, for the timings that reports print.
#pragma once

#include <chrono>

namespace sb {

inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace sb
