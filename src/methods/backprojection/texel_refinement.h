// Adaptive texel sampling for one light over one receiver (texel_refinement.cpp): the exact
// estimate at the corners and centres of cells of 8, 4 and 2 texels, interpolated inside a cell
// only where its checks pass, and evaluated texel by texel where they fail. Possible only because
// the estimates have no noise: a sample that disagrees with its neighbours' prediction is a real
// change in the field, not chance.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/geometry.h"
#include "methods/backprojection/texel_routes.h"
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

// The shaft test of each tile of kTile × kTile texels (ShaftCuller::tile_candidates) for one
// light: what the refinement's cells start from. A tile's texels the light reaches are tested in
// patches, each one piece of surface (texels joined to their neighbours in the tile where they
// lie no farther apart on the surface than their faces' texel steps allow): a tile of an atlas
// of many small charts holds pieces of surface from all over a level, whose joint box's shaft
// would cross much of it.
struct TileShafts {
  static constexpr int kTile = 8;
  // Tiles are first tested kGroup × kGroup together: one clear group clears them all.
  static constexpr int kGroup = 4;
  // A tile has at most this many patches (the last takes whatever pieces remain).
  static constexpr int kMaxPatches = 16;
  enum class Kind : std::uint8_t {
    empty,   // no covered texel the light reaches
    clear,   // nothing can block the light from any of its texels
    listed,  // `candidates` holds every triangle that may
    all,     // too many to list, or the light reaches only part of it: each texel searches all
    umbra    // one of `candidates` hides all of the light from every texel: V = 0
  };
  struct Patch {
    Kind kind = Kind::empty;
    std::vector<std::uint32_t> candidates;  // sorted
    Bounds3 origins;                        // the box of its texels' ray origins
  };
  int tiles_x = 0, tiles_y = 0;
  // Per tile: its patches' kind where they all have one; listed where they differ.
  std::vector<Kind> kind;
  std::vector<Patch> patches;
  std::vector<std::uint32_t> first_patch;  // per tile and one more: tile i's are [i], [i + 1])
  // Per tile of more than one patch, its place in `patch_at`, else -1; there, per pixel of the
  // tile (row-major), its texel's patch within the tile.
  std::vector<std::int32_t> mixed;
  std::vector<std::array<std::uint8_t, kTile * kTile>> patch_at;
  // Per tile, a bit per pixel (row-major within the tile): 1 where a covered texel lies that the
  // light reaches (H0 > 0); 0 throughout a tile the light's lists leave out.
  std::vector<std::uint64_t> reached;
  std::size_t tile_of(int x, int y) const {
    return std::size_t(y / kTile) * std::size_t(tiles_x) + std::size_t(x / kTile);
  }
  static std::uint64_t bit_of(int x, int y) {
    return std::uint64_t(1) << ((y % kTile) * kTile + x % kTile);
  }
  // Whether the light reaches the texel at pixel (x, y), which lies in the lightmap.
  bool reached_at(int x, int y) const { return (reached[tile_of(x, y)] & bit_of(x, y)) != 0; }
  // The patch of the texel at pixel (x, y), covered and reached.
  const Patch& patch(int x, int y) const {
    const std::size_t tile = tile_of(x, y);
    const std::int32_t m = mixed.empty() ? -1 : mixed[tile];
    const std::uint32_t within =
        m < 0 ? 0u : patch_at[std::size_t(m)][std::size_t((y % kTile) * kTile + x % kTile)];
    return patches[first_patch[tile] + within];
  }
  Kind kind_at(int x, int y) const { return patch(x, y).kind; }
};

// One exact evaluation of the light at a texel.
struct PairSample {
  float visibility = 1;
  TexelRoute route = TexelRoute::none;  // clear, exact or traced; none: the light does not reach
  // Lower bound on the distance to the nearest blocker of its shaft, metres (infinity: none).
  float nearest = std::numeric_limits<float>::infinity();
  // The blockers (ShaftCuller::blocker_key: triangles, or convex solids) that reach the light
  // from the texel, sorted, when listed.
  std::vector<std::uint32_t> triangles;
  // False where the blockers were not listed (a shaft traced past the estimator's budget):
  // then the distance bound is all the refinement has to go on.
  bool listed = true;
  // A convex solid or one polygon that hides all of the light by itself, or
  // PenumbraSample::kNoUmbra.
  std::uint32_t umbra = 0xffffffffu;
};

// What the refinement asks of the light and the blockers (the bake implements it).
class PairSource {
 public:
  virtual ~PairSource() = default;
  virtual void evaluate(std::size_t t, PairSample& out) const = 0;
  // The light's narrowest apparent width seen from texel t, radians: a blocker at distance d
  // from the texel casts no penumbra on it narrower than this times d.
  virtual double angular_width(std::size_t t) const = 0;
  // Whether a blocker not among `listed` (keys, sorted) may lie in the shaft of one of `texels`
  // (a cell's, all in one tile): one that none of the cell's samples saw.
  virtual bool sees_unlisted(const std::vector<std::size_t>& texels,
                             const std::vector<std::uint32_t>& listed) const = 0;
  // Whether one triangle of the blockers `seen` (keys, sorted) hides all of the light from each
  // of `samples` (a cell's five, the first in its tile): a triangle's umbra is convex, so it holds
  // every point between them. False where the source cannot tell.
  virtual bool one_triangle_hides(const std::array<std::size_t, 5>& samples,
                                  const std::vector<std::uint32_t>& seen) const {
    (void)samples, (void)seen;
    return false;
  }
  // Whether a ball inside one closed blocker of `seen` hides all of the light from every point
  // of the box of `texels`' ray origins (a cell's, all outside the blocker): the ball's umbra is
  // convex, and a ray into the ball from outside the blocker meets the blocker's surface. False
  // where the source cannot tell.
  virtual bool ball_hides(const std::vector<std::size_t>& texels,
                          const std::vector<std::uint32_t>& seen) const {
    (void)texels, (void)seen;
    return false;
  }
};

struct RefinementSettings {
  int max_cell = 8;         // texels between the coarsest samples (a power of two, ≤ kTile)
  double tolerance = 2e-3;  // largest |V(centre) − V predicted from the corners| interpolated
  double normal_cos = std::cos(15.0 * 3.14159265358979 / 180.0);  // normals of one smooth piece
  double position_texels = 1.0;  // a texel's distance from the cell's bilinear surface, in texels
  double feature_cells = 2.0;    // the narrowest penumbra allowed, in cells
  double midpoint_cells = 4.0;   // under this, the cell's edge midpoints are checked too
};

// One light's visibility at every covered texel of a receiver, and the route each came by, by
// tile: a clear or umbra tile all of whose covered texels the light reaches holds one value for
// them all (1 or 0), an empty one none; the rest — the cells' tiles, the umbrae whose texels are
// their corners, the tiles the light reaches in part — hold their texels' own, kTile² each. Under
// a sun at 4096² that is a fifth of the texels: the refinement's per-texel arrays (these, and its
// own state and samples) are written for those alone.
struct LightField {
  int tiles_x = 0;
  std::vector<std::int32_t> slot;      // per tile: its place in `visibility` and `route`, or -1
  std::vector<TexelRoute> tile_route;  // per tile without a place: its texels' route
  // Per texel of the tiles with a place, row-major within the tile; 1 where the route is none.
  FreshVector<float> visibility;
  FreshVector<TexelRoute> route;

  // The texel at pixel (x, y): its index in the arrays above, or -1 where its tile has none.
  std::int64_t index(int x, int y) const {
    constexpr int k = TileShafts::kTile;
    const std::int32_t s = slot[std::size_t(y / k) * std::size_t(tiles_x) + std::size_t(x / k)];
    return s < 0 ? -1 : std::int64_t(s) * k * k + (y % k) * k + x % k;
  }
  TexelRoute route_at(int x, int y) const {
    constexpr int k = TileShafts::kTile;
    const std::int64_t i = index(x, y);
    return i >= 0 ? route[std::size_t(i)]
                  : tile_route[std::size_t(y / k) * std::size_t(tiles_x) + std::size_t(x / k)];
  }
  float visibility_at(int x, int y) const {
    const std::int64_t i = index(x, y);
    return i >= 0 ? visibility[std::size_t(i)] : route_at(x, y) == TexelRoute::umbra ? 0.0f : 1.0f;
  }
};

LightField refine_light(const TexelSpace& space, const TexelGrid& grid, const TileShafts& tiles,
                        const PairSource& source, const RefinementSettings& settings);

}  // namespace sb
