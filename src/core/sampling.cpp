#include "core/sampling.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

namespace sb {

std::uint64_t name_stream(std::string_view name) {
  std::uint64_t stream = 0xcbf29ce484222325ull;
  for (const unsigned char c : name) stream = (stream ^ c) * 0x100000001b3ull;
  return stream;
}

std::uint64_t stream_seed(std::uint64_t seed, std::uint64_t a, std::uint64_t b) {
  Rng mix(seed ^ 0x5851F42D4C957F2Dull);
  std::uint64_t s = mix.next_u64() ^ a;
  Rng mix2(s);
  s = mix2.next_u64() ^ b;
  Rng mix3(s);
  return mix3.next_u64();
}

void stratified_samples(int count, Rng& rng, std::vector<Vec2>& out) {
  out.clear();
  if (count <= 0) return;
  const int nx = int(std::ceil(std::sqrt(double(count))));
  const int ny = (count + nx - 1) / nx;
  const int cells = nx * ny;
  out.reserve(count);
  if (cells == count) {
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        out.emplace_back((i + rng.next_double()) / nx, (j + rng.next_double()) / ny);
    return;
  }
  // Partial Fisher–Yates: the first `count` entries become a uniform random subset of cells.
  std::vector<int> order(cells);
  std::iota(order.begin(), order.end(), 0);
  for (int k = 0; k < count; ++k) {
    const int pick = k + int(rng.next_below(std::uint32_t(cells - k)));
    std::swap(order[k], order[pick]);
    const int i = order[k] % nx, j = order[k] / nx;
    out.emplace_back((i + rng.next_double()) / nx, (j + rng.next_double()) / ny);
  }
}

Vec3 cosine_direction(const Vec3& n, const Vec2& u) {
  const double r = std::sqrt(u.x()), phi = 2.0 * std::numbers::pi * u.y();
  const Vec3 a = n.unitOrthogonal(), b = n.cross(a);
  return r * std::cos(phi) * a + r * std::sin(phi) * b + std::sqrt(std::max(0.0, 1.0 - u.x())) * n;
}

}  // namespace sb
