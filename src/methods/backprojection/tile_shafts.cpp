// Stage 1 of the `backprojection` bake: the tiles' shaft tests (tile_shafts.h).
#include "methods/backprojection/tile_shafts.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <numeric>
#include <vector>

#include "methods/backprojection/penumbra_estimator.h"

namespace sb {

namespace {

using Kind = TileShafts::Kind;
constexpr int kTile = TileShafts::kTile;

// Two texels one pixel apart lie on one piece of surface where they are no farther apart than
// this many times the larger of their faces' texel steps (TexelSpace::face_texel_sizes): a texel
// that takes its face's nearest point (a chart's border) may lie a step beyond it.
constexpr float kJoinSteps = 2.0f;
// The most candidates a patch tries one by one as the triangle its umbra is (below).
constexpr std::size_t kUmbraCandidates = 256;

// A tile's patches as one band's task finds them.
struct TilePatches {
  std::vector<TileShafts::Patch> patches;
  std::array<std::uint8_t, kTile * kTile> at{};  // per pixel, where there are several
  float step = 0;      // the largest texel step of its texels' faces (TexelSpace::face_texel_sizes)
  bool whole = false;  // one patch from its block's summary: the light reaches all its texels
};

int root_of(std::array<std::uint8_t, kTile * kTile>& parent, int i) {
  while (parent[std::size_t(i)] != i) {
    parent[std::size_t(i)] = parent[std::size_t(parent[std::size_t(i)])];
    i = parent[std::size_t(i)];
  }
  return i;
}

}  // namespace

bool hides_from_all(const Light& light, const Vec3* corners, std::span<const Vec3> points,
                    double offset) {
  for (const Vec3& p : points)
    if (!triangle_hides_light(light, corners, p, offset)) return false;
  return true;
}

namespace {

// What the tiles' shaft tests read, and the steps of tile_shafts: one tile's patches, a patch's
// test, a band's groups of tiles tested together.
struct TileTester {
  const TexelSpace& space;
  const TexelGrid& grid;
  const ShaftCuller& culler;
  const RayScene& rays;
  const Light& light;
  std::size_t max;
  bool umbrae;
  double offset;
  bool blocks;  // the texel space has a summary per tile (TexelBlock)
  bool sizes;   // and its faces' texel steps

  void find_patches(TileShafts& tiles, int tx, int ty, TilePatches& tile) const;
  void test(TileShafts::Patch& patch, const std::vector<std::uint32_t>* among) const;
  void test_groups(const TileShafts& tiles, int ty0, int ty1, std::vector<TilePatches>& out) const;
};

// Tile (tx, ty)'s patches: one from its block's summary where that serves (below), else its
// texels' pieces of surface, the texels the light reaches among them (tiles.reached).
void TileTester::find_patches(TileShafts& tiles, int tx, int ty, TilePatches& tile) const {
  const std::size_t i = std::size_t(ty) * std::size_t(tiles.tiles_x) + std::size_t(tx);
  if (blocks) {
    const TexelBlock& b = space.blocks[i];
    if (b.empty()) return;
    const Vec3 lo = b.lo.cast<double>(), hi = b.hi.cast<double>();
    Bounds3 positions;
    positions.extend(lo);
    positions.extend(hi);
    const double reach = double(b.texel_size) * kJoinSteps * kTile * std::sqrt(3.0);
    if (b.uniform && (!sizes || (hi - lo).norm() <= reach) &&
        light.reaches_all(positions, b.normal.cast<double>())) {
      const Vec3 shift = offset * b.geometric.cast<double>();
      tile.step = b.texel_size;
      TileShafts::Patch& patch = tile.patches.emplace_back();
      patch.origins.extend(Vec3(lo + shift));
      patch.origins.extend(Vec3(hi + shift));
      tile.whole = true;  // its texels' `reached` set by tile_shafts, row by row
      return;
    }
  }
  // Texel by texel: which the light reaches, and their pieces of surface.
  std::array<std::int32_t, kTile * kTile> texel;
  std::array<std::uint8_t, kTile * kTile> parent;
  for (int j = 0; j < kTile * kTile; ++j) {
    parent[std::size_t(j)] = std::uint8_t(j);
    const std::int32_t t = grid.texel(tx * kTile + j % kTile, ty * kTile + j / kTile);
    texel[std::size_t(j)] = -1;
    if (t < 0) continue;
    const Texel& record = space.texels[std::size_t(t)];
    tiles.reached[std::size_t(t)] =
        light.reaches(record.position.cast<double>(), record.normal.cast<double>());
    if (tiles.reached[std::size_t(t)]) texel[std::size_t(j)] = t;
  }
  const auto joined = [&](std::int32_t a, std::int32_t b) {
    if (!sizes) return true;
    const Texel& ta = space.texels[std::size_t(a)];
    const Texel& tb = space.texels[std::size_t(b)];
    const float step = std::max(space.face_texel_sizes[std::size_t(ta.face)],
                                space.face_texel_sizes[std::size_t(tb.face)]);
    return (ta.position - tb.position).norm() <= kJoinSteps * step;
  };
  for (int j = 0; j < kTile * kTile; ++j) {
    if (texel[std::size_t(j)] < 0) continue;
    for (const int k : {j % kTile + 1 < kTile ? j + 1 : -1, j + kTile})
      if (k >= 0 && k < kTile * kTile && texel[std::size_t(k)] >= 0 &&
          joined(texel[std::size_t(j)], texel[std::size_t(k)]))
        parent[std::size_t(root_of(parent, k))] = std::uint8_t(root_of(parent, j));
  }
  // Patches in order of their first pixel; past kMaxPatches, the rest join the last.
  std::array<std::int8_t, kTile * kTile> patch_of_root;
  patch_of_root.fill(-1);
  for (int j = 0; j < kTile * kTile; ++j) {
    if (texel[std::size_t(j)] < 0) continue;
    const int root = root_of(parent, j);
    if (patch_of_root[std::size_t(root)] < 0) {
      if (int(tile.patches.size()) < TileShafts::kMaxPatches) tile.patches.emplace_back();
      patch_of_root[std::size_t(root)] = std::int8_t(tile.patches.size() - 1);
    }
    const std::uint8_t p = std::uint8_t(patch_of_root[std::size_t(root)]);
    if (sizes)
      tile.step = std::max(tile.step, space.face_texel_sizes[std::size_t(
                                          space.texels[std::size_t(texel[std::size_t(j)])].face)]);
    tile.at[std::size_t(j)] = p;
    tile.patches[p].origins.extend(space.ray_origin(std::size_t(texel[std::size_t(j)]), offset));
  }
}

void TileTester::test(TileShafts::Patch& patch, const std::vector<std::uint32_t>* among) const {
  std::vector<std::uint32_t>& list = patch.candidates;
  if (!culler.tile_candidates(patch.origins, light, max, list, among)) {
    patch.kind = Kind::clear;
    return;
  }
  patch.kind = list.empty() ? Kind::all : Kind::listed;
  std::sort(list.begin(), list.end());
  if (!umbrae) return;
  // An umbra: a triangle that hides all of the light from the box's corners. Each candidate is
  // tried where they are few; where they are many (a dense mesh's small triangles, none of
  // which hides a light alone: trying them all cost the dense scene a third of its bake), or
  // not listed, the one the ray from the box's centre to the light's centre meets first.
  std::array<Vec3, 8> corners;
  for (int k = 0; k < 8; ++k) corners[std::size_t(k)] = patch.origins.corner(k);
  const auto hides = [&](std::uint32_t triangle) {
    return hides_from_all(light, culler.triangle_corners(triangle), corners, offset);
  };
  if (patch.kind == Kind::listed && list.size() <= kUmbraCandidates) {
    if (std::any_of(list.begin(), list.end(), hides)) patch.kind = Kind::umbra;
    return;
  }
  const Vec3 from = patch.origins.centre();
  const RayScene::Hit hit = rays.first_hit_face(from, light.centre() - from, 1.0);
  if (hit.face >= 0 && hides(culler.triangle_of_face(hit.face))) patch.kind = Kind::umbra;
}

// A group of g × g tiles on one piece of surface (its joint box no larger than one piece of its
// texel steps could fill) whose joint box's shaft is clear is clear throughout (each patch's
// shaft lies inside it); otherwise its patches are tested one by one, among the group's
// candidates where it listed them (a patch's shaft lies inside the group's, so every triangle in
// it is among them) rather than down the whole hierarchy again. A group of pieces from all over
// a level is not tested: its shaft would cross much of it.
void TileTester::test_groups(const TileShafts& tiles, int ty0, int ty1,
                             std::vector<TilePatches>& out) const {
  constexpr int g = TileShafts::kGroup;
  thread_local std::vector<std::uint32_t> group_list;
  for (int gx = 0; gx < tiles.tiles_x; gx += g) {
    const int x1 = std::min(gx + g, tiles.tiles_x);
    Bounds3 joint;
    int filled = 0;
    float step = 0;
    for (int ty = ty0; ty < ty1; ++ty)
      for (int tx = gx; tx < x1; ++tx) {
        const TilePatches& tile =
            out[std::size_t(ty - ty0) * std::size_t(tiles.tiles_x) + std::size_t(tx)];
        step = std::max(step, tile.step);
        for (const TileShafts::Patch& p : tile.patches) {
          joint.extend(p.origins);
          ++filled;
        }
      }
    if (filled == 0) continue;
    const bool coherent =
        !sizes || joint.diagonal() <= double(step) * kJoinSteps * g * kTile * std::sqrt(3.0);
    group_list.clear();
    const bool clear =
        filled > 1 && coherent && !culler.tile_candidates(joint, light, max, group_list);
    for (int ty = ty0; ty < ty1; ++ty)
      for (int tx = gx; tx < x1; ++tx)
        for (TileShafts::Patch& p :
             out[std::size_t(ty - ty0) * std::size_t(tiles.tiles_x) + std::size_t(tx)].patches) {
          if (clear)
            p.kind = Kind::clear;
          else
            test(p, filled > 1 && !group_list.empty() ? &group_list : nullptr);
        }
  }
}

}  // namespace

TileShafts tile_shafts(const TexelSpace& space, const TexelGrid& grid, const ShaftCuller& culler,
                       const RayScene& rays, const Light& light, std::size_t max, bool umbrae) {
  const double offset = rays.surface_offset();
  static_assert(TileShafts::kTile == TexelBlock::kSide, "a tile is a block of the texel space");
  TileShafts tiles;
  tiles.tiles_x = (space.width + kTile - 1) / kTile;
  tiles.tiles_y = (space.height + kTile - 1) / kTile;
  const std::size_t count = std::size_t(tiles.tiles_x) * std::size_t(tiles.tiles_y);
  tiles.kind.assign(count, Kind::empty);
  tiles.reached.resize(space.texels.size());  // every texel's written below
  const bool blocks = space.blocks.size() == count;
  const bool sizes = !space.face_texel_sizes.empty();
  // Bands of kGroup tile rows in parallel. A tile whose block shares one normal, lies within the
  // box one piece of surface of its texel steps could fill, and that the light reaches all of (the
  // sun over flat ground) is one patch that takes its box from the block, shifted as each ray
  // origin is (the same box: rounding is monotonic), and its texels' records are not read.
  constexpr int g = TileShafts::kGroup;
  const int bands = (tiles.tiles_y + g - 1) / g;
  std::vector<std::vector<TilePatches>> found(static_cast<std::size_t>(bands));
  const TileTester tester{space, grid, culler, rays, light, max, umbrae, offset, blocks, sizes};
  tbb::parallel_for(tbb::blocked_range<int>(0, bands), [&](const auto& r) {
    for (int band = r.begin(); band != r.end(); ++band) {
      const int ty0 = band * g, ty1 = std::min(ty0 + g, tiles.tiles_y);
      std::vector<TilePatches>& out = found[std::size_t(band)];
      out.assign(std::size_t(ty1 - ty0) * std::size_t(tiles.tiles_x), TilePatches());
      for (int ty = ty0; ty < ty1; ++ty)
        for (int tx = 0; tx < tiles.tiles_x; ++tx) {
          const std::size_t i = std::size_t(ty) * std::size_t(tiles.tiles_x) + std::size_t(tx);
          tester.find_patches(tiles, tx, ty,
                              out[i - std::size_t(ty0) * std::size_t(tiles.tiles_x)]);
        }
      // The whole tiles' texels are reached, in one pass over the band's rows.
      grid.for_each(
          ty0 * kTile, std::min(space.height, ty1 * kTile), [&](std::size_t t, int x, int y) {
            if (out[tiles.tile_of(x, y) - std::size_t(ty0) * std::size_t(tiles.tiles_x)].whole)
              tiles.reached[t] = 1;
          });
      tester.test_groups(tiles, ty0, ty1, out);
    }
  });
  // The bands' patches in tile order.
  tiles.first_patch.assign(count + 1, 0);
  tiles.mixed.assign(count, -1);
  std::size_t i = 0;
  for (std::vector<TilePatches>& band : found)
    for (TilePatches& tile : band) {
      tiles.first_patch[i] = std::uint32_t(tiles.patches.size());
      if (tile.patches.size() > 1) {
        tiles.mixed[i] = std::int32_t(tiles.patch_at.size());
        tiles.patch_at.push_back(tile.at);
      }
      if (!tile.patches.empty()) {
        Kind kind = tile.patches[0].kind;
        for (const TileShafts::Patch& p : tile.patches)
          if (p.kind != kind) kind = Kind::listed;
        tiles.kind[i] = kind;
      }
      for (TileShafts::Patch& p : tile.patches) tiles.patches.push_back(std::move(p));
      ++i;
    }
  tiles.first_patch[count] = std::uint32_t(tiles.patches.size());
  return tiles;
}

}  // namespace sb
