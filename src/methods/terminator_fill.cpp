// fill_terminators (terminator_fill.h): texels whose square the terminator crosses take the lit
// neighbours' visibility.
#include "methods/terminator_fill.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <utility>

namespace sb {
namespace {

// Half the side of the square of a texel whose points count, in texels: Blender's bake samples a
// texel over the middle quarter of its area (bake_differentials, beside RE_bake_pixels_populate
// in Blender's render/intern/bake, halves the UV derivatives Cycles jitters its samples by).
constexpr double kFootprintHalfSide = 0.25;

bool counted(const float* px, UncountedMark mark) {
  return mark == UncountedMark::value ? px[0] >= 0.0f : px[1] > 0.0f;
}

// The index of the texel at pixel (x, y), which is covered: texels are in row-major order.
std::size_t texel_at(const TexelSpace& space, int x, int y) {
  const auto it =
      std::lower_bound(space.texels.begin(), space.texels.end(), std::pair<int, int>(y, x),
                       [](const Texel& t, const std::pair<int, int>& key) {
                         return std::pair<int, int>(t.y, t.x) < key;
                       });
  return std::size_t(it - space.texels.begin());
}

// Texels where no light counts: 0.
void clear_uncounted(Image& image) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, image.pixels.size(), 1 << 16),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i)
                        if (image.pixels[i] < 0.0f) image.pixels[i] = 0.0f;
                    });
}

// Whether some point of texel t's square, as Blender bakes it (kFootprintHalfSide about its
// centre, within its triangle), has a shading normal under which h0 > 0.
template <class H0>
bool square_reaches(const TexelSpace& space, const Texel& texel, const H0& h0) {
  const TexelSpace::FaceShading& face = space.face_shading[std::size_t(texel.face)];
  const Vec2 a = face.corner[0].cast<double>(), b = face.corner[1].cast<double>(),
             c = face.corner[2].cast<double>();
  const double area = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  if (!(std::abs(area) > 0)) return false;
  // The square clipped to the triangle (Sutherland–Hodgman against its three edges).
  const Vec2 centre(texel.x + 0.5, texel.y + 0.5);
  const double h = kFootprintHalfSide;
  std::vector<Vec2> polygon = {centre + Vec2(-h, -h), centre + Vec2(h, -h), centre + Vec2(h, h),
                               centre + Vec2(-h, h)};
  const Vec2 corners[3] = {a, b, c};
  std::vector<Vec2> clipped;
  for (int e = 0; e < 3 && !polygon.empty(); ++e) {
    const Vec2 from = corners[e], to = corners[(e + 1) % 3];
    // Inside: on the triangle's side of the edge.
    const auto side = [&](const Vec2& q) {
      return ((to - from).x() * (q - from).y() - (to - from).y() * (q - from).x()) * area;
    };
    clipped.clear();
    for (std::size_t i = 0; i < polygon.size(); ++i) {
      const Vec2 &p = polygon[i], &q = polygon[(i + 1) % polygon.size()];
      const double sp = side(p), sq = side(q);
      if (sp >= 0) clipped.push_back(p);
      if ((sp >= 0) != (sq >= 0)) clipped.push_back(p + (q - p) * (sp / (sp - sq)));
    }
    polygon.swap(clipped);
  }
  // The unnormalised interpolated normal is linear across the face, so its extremes towards any
  // light lie at the clipped square's corners.
  for (const Vec2& q : polygon) {
    const double wa = ((b - q).x() * (c - q).y() - (b - q).y() * (c - q).x()) / area;
    const double wb = ((c - q).x() * (a - q).y() - (c - q).y() * (a - q).x()) / area;
    const Vec3 normal = wa * face.normal[0].cast<double>() + wb * face.normal[1].cast<double>() +
                        (1 - wa - wb) * face.normal[2].cast<double>();
    if (normal.norm() > 0 && h0(normal) > 0) return true;
  }
  return false;
}

// A texel's fill: its pixel's index and the values it takes. Each texel's fill is found first and
// written after (fill_terminators).
struct Fill {
  std::size_t pixel;
  float v[3];
};

// The covered texels of the blocks `blocks` (LightLists::kSide² texels each), block by block.
std::vector<std::size_t> texels_of_blocks(const TexelSpace& space,
                                          std::span<const std::uint32_t> blocks) {
  std::vector<std::size_t> visited;
  const int blocks_x = (space.width + LightLists::kSide - 1) / LightLists::kSide;
  for (const std::uint32_t b : blocks) {
    const int x0 = int(b % std::uint32_t(blocks_x)) * LightLists::kSide;
    const int y0 = int(b / std::uint32_t(blocks_x)) * LightLists::kSide;
    for (int y = y0; y < std::min(y0 + LightLists::kSide, space.height); ++y)
      for (int x = x0; x < std::min(x0 + LightLists::kSide, space.width); ++x)
        if (space.covered[std::size_t(y) * std::size_t(space.width) + std::size_t(x)])
          visited.push_back(texel_at(space, x, y));
  }
  return visited;
}

// Whether a light counts at the texel or at one of its 8 neighbours in the lightmap.
bool counted_around(const TexelSpace& space, const Image& image, const Texel& texel,
                    UncountedMark mark) {
  bool any_counted = false;
  for (int dy = -1; dy <= 1 && !any_counted; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const int x = texel.x + dx, y = texel.y + dy;
      if (x >= 0 && y >= 0 && x < space.width && y < space.height &&
          space.covered[std::size_t(y) * space.width + x] && counted(image.at(x, y), mark))
        any_counted = true;
    }
  }
  return any_counted;
}

// The texel's 8 neighbours on the same piece of surface as it (at `p`) into `around`, by offset
// (dy + 1, dx + 1); null where there is none.
void same_surface_neighbours(const TexelSpace& space, const Texel& texel, const Vec3& p,
                             const Texel* (&around)[3][3]) {
  // The 8 neighbours on the same piece of surface: no farther apart than their faces'
  // texel steps allow (a neighbour in the lightmap across a chart's border lies
  // elsewhere).
  const double step = space.face_texel_sizes[std::size_t(texel.face)];
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const int x = texel.x + dx, y = texel.y + dy;
      if ((dx == 0 && dy == 0) || x < 0 || y < 0 || x >= space.width || y >= space.height ||
          !space.covered[std::size_t(y) * space.width + x])
        continue;
      const Texel& other = space.texels[texel_at(space, x, y)];
      const double reach = 1.5 * std::hypot(dx, dy) *
                           std::max(step, double(space.face_texel_sizes[std::size_t(other.face)]));
      if ((other.position.cast<double>() - p).norm() <= reach) around[dy + 1][dx + 1] = &other;
    }
  }
}

// Sums the lit neighbours' first `values` values into `v`, each weighted by the lights' H0 under
// the normal on the border between them and the texel (normal `n`); the weights' sum.
template <class H0>
double weigh_lit_neighbours(const Image& image, UncountedMark mark, int values,
                            const Texel* const (&around)[3][3], const Vec3& n, const H0& h0,
                            double (&v)[3]) {
  // The lit neighbours' values, each weighted by the lights' H0 under the normal on the
  // two texels' border (their mean where none is lit there: only a corner reaches).
  double weight = 0;
  for (const bool by_border : {true, false}) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const Texel* other = around[dy + 1][dx + 1];
        if (!other) continue;
        const float* px = image.at(other->x, other->y);
        if (!counted(px, mark)) continue;
        const double w = by_border ? h0(n + other->normal.cast<double>()) : 1.0;
        if (!(w > 0)) continue;
        weight += w;
        for (int c = 0; c < values; ++c) v[c] += w * double(px[c]);
      }
    }
    if (weight > 0) break;
  }
  return weight;
}

// Writes the fills into the image: the values, and with a coverage mark the mark set.
void write_fills(const tbb::enumerable_thread_specific<std::vector<Fill>>& fills,
                 UncountedMark mark, Image& image) {
  for (const std::vector<Fill>& mine : fills) {
    for (const Fill& fill : mine) {
      float* px = &image.pixels[fill.pixel * std::size_t(image.channels)];
      if (mark == UncountedMark::value) {
        for (int c = 0; c < 3; ++c) px[c] = fill.v[c];
      } else {
        px[0] = fill.v[0];
        px[1] = 1.0f;
      }
    }
  }
}

}  // namespace

void fill_terminators(const TexelSpace& space, const std::vector<Light>& all,
                      const std::vector<std::size_t>& lights, UncountedMark mark, Image& image,
                      const LightLists* lists,
                      std::optional<std::span<const std::uint32_t>> blocks) {
  const int values = mark == UncountedMark::value ? 3 : 1;
  if (space.face_shading.empty()) {
    if (mark == UncountedMark::value) clear_uncounted(image);
    return;
  }
  // The texels visited: all, or those of `blocks`.
  std::vector<std::size_t> visited;
  if (blocks) visited = texels_of_blocks(space, *blocks);
  const std::size_t count = blocks ? visited.size() : space.texels.size();
  // Each texel's fill is found first and written after, so that no texel reads a neighbour
  // filled in the same pass: the result does not depend on the order texels are visited in.
  tbb::enumerable_thread_specific<std::vector<Fill>> fills;
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, count, 1024),
      [&](const tbb::blocked_range<std::size_t>& range) {
        std::vector<Fill>& mine = fills.local();
        std::vector<std::size_t> listed;  // the texel's block's among `lights`
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
          const Texel& texel = space.texels[blocks ? visited[k] : k];
          if (counted(image.at(texel.x, texel.y), mark)) continue;
          const Vec3 p = texel.position.cast<double>(), n = texel.normal.cast<double>();
          const std::vector<std::size_t>* weighed = &lights;
          if (lists) {
            const auto block = lists->lights_of(lists->block_of(texel.x, texel.y));
            listed.clear();
            std::set_intersection(lights.begin(), lights.end(), block.begin(), block.end(),
                                  std::back_inserter(listed));
            weighed = &listed;
          }
          const auto h0 = [&](const Vec3& normal) {
            double sum = 0;
            for (const std::size_t l : *weighed)
              sum += all[l].unoccluded_irradiance(p, normal.normalized()).sum();
            return sum;
          };
          // Most texels where no light counts lie among others (a sphere's dark side): their
          // pixels alone say so.
          if (!counted_around(space, image, texel, mark)) continue;
          const Texel* around[3][3] = {};
          same_surface_neighbours(space, texel, p, around);
          if (!square_reaches(space, texel, h0)) continue;
          double v[3] = {0, 0, 0};
          const double weight = weigh_lit_neighbours(image, mark, values, around, n, h0, v);
          if (!(weight > 0)) continue;  // its lit neighbours lie on other pieces of surface
          Fill fill{std::size_t(texel.y) * std::size_t(space.width) + texel.x, {0, 0, 0}};
          for (int c = 0; c < values; ++c) fill.v[c] = float(v[c] / weight);
          mine.push_back(fill);
        }
      });
  write_fills(fills, mark, image);
  if (mark == UncountedMark::value) clear_uncounted(image);
}

}  // namespace sb
