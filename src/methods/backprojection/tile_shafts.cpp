// Stage 1 of the `backprojection` bake: the tiles' shaft tests (tile_shafts.h).
#include "methods/backprojection/tile_shafts.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <numeric>
#include <vector>

#include "methods/backprojection/umbra_proofs.h"
#include "occluders/plane_occlusion.h"

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
  float step = 0;  // the largest texel step of its texels' faces (TexelSpace::face_texel_sizes)
  std::uint64_t reached = 0;  // its texels the light reaches (TileShafts::reached)
};

// Whether the segment from a to b meets the triangle `corners` (its barycentric coordinates and
// the segment's parameter within a millionth of their ranges; parallel to its plane counts):
// a triangle that hides all of a light from a box meets the segment from the box's centre to
// the light's centre, and this costs a tenth of the test of hiding.
bool segment_meets(const Vec3* corners, const Vec3& a, const Vec3& b) {
  constexpr double margin = 1e-6;
  const Vec3 d = b - a, e1 = corners[1] - corners[0], e2 = corners[2] - corners[0];
  const Vec3 p = d.cross(e2);
  const double det = e1.dot(p);
  if (det == 0) return true;
  const Vec3 s = a - corners[0];
  const double u = s.dot(p) / det;
  if (!(u >= -margin && u <= 1 + margin)) return false;
  const Vec3 q = s.cross(e1);
  const double v = d.dot(q) / det;
  if (!(v >= -margin && u + v <= 1 + margin)) return false;
  const double t = e2.dot(q) / det;
  return t >= -margin && t <= 1 + margin;
}

int root_of(std::array<std::uint8_t, kTile * kTile>& parent, int i) {
  while (parent[std::size_t(i)] != i) {
    parent[std::size_t(i)] = parent[std::size_t(parent[std::size_t(i)])];
    i = parent[std::size_t(i)];
  }
  return i;
}

// Numbers the pieces of surface among tile `at`'s pixels `reached`, joined as `joins` says:
// in order of their first pixel, past kMaxPatches the rest with the last. Returns how many;
// patch[j] for each pixel j reached.
int number_pieces(const TileJoins& joins, std::size_t at, std::uint64_t reached,
                  std::array<std::uint8_t, kTile * kTile>& patch) {
  std::array<std::uint8_t, kTile * kTile> parent;
  for (int j = 0; j < kTile * kTile; ++j) parent[std::size_t(j)] = std::uint8_t(j);
  const std::uint64_t right = joins.right[at] & reached & (reached >> 1);
  const std::uint64_t down = joins.down[at] & reached & (reached >> kTile);
  for (int j = 0; j < kTile * kTile; ++j) {
    if (right >> j & 1)
      parent[std::size_t(root_of(parent, j + 1))] = std::uint8_t(root_of(parent, j));
    if (down >> j & 1)
      parent[std::size_t(root_of(parent, j + kTile))] = std::uint8_t(root_of(parent, j));
  }
  std::array<std::int8_t, kTile * kTile> patch_of_root;
  patch_of_root.fill(-1);
  int count = 0;
  for (int j = 0; j < kTile * kTile; ++j) {
    if (!(reached >> j & 1)) continue;
    const int root = root_of(parent, j);
    if (patch_of_root[std::size_t(root)] < 0) {
      if (count < TileShafts::kMaxPatches) ++count;
      patch_of_root[std::size_t(root)] = std::int8_t(count - 1);
    }
    patch[std::size_t(j)] = std::uint8_t(patch_of_root[std::size_t(root)]);
  }
  return count;
}

}  // namespace

bool hides_from_all(const Light& light, const Vec3* corners, std::span<const Vec3> points,
                    double offset) {
  // First what hiding needs and costs little: the triangle's plane between each point and all
  // of the light (most of a patch's candidates fail it).
  Vec3 n = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
  if (!(n.norm() > 0)) return false;
  n.normalize();
  const double h_centre = n.dot(light.centre() - corners[0]);
  double half = -1;  // how far the light reaches along n from its centre; < 0: unknown
  switch (light.shape()) {
    case LightShape::sphere:
      half = light.desc().radius;
      break;
    case LightShape::rectangle:
      half = 0.5 * light.desc().width * std::abs(n.dot(light.right())) +
             0.5 * light.desc().height * std::abs(n.dot(light.up()));
      break;
    case LightShape::disk:
      half = light.desc().radius * (n - n.dot(light.normal()) * light.normal()).norm();
      break;
    default:
      break;
  }
  if (half >= 0) {
    for (const Vec3& p : points) {
      const double h = n.dot(p - corners[0]);
      if (!(h > 0 ? h_centre + half < 0 : h < 0 && h_centre - half > 0)) return false;
    }
  }
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
  const TileJoins& joins;
  const ShaftCuller& culler;
  const RayScene& rays;
  const Light& light;
  std::size_t max;
  bool umbrae;
  double offset;
  bool blocks;  // the texel space has a summary per tile (TexelBlock)
  bool sizes;   // and its faces' texel steps

  void find_patches(int tx, int ty, TilePatches& tile) const;
  void test(TileShafts::Patch& patch, const std::vector<std::uint32_t>* among) const;
  template <class Hides>
  bool dark(const Bounds3& origins, const Hides& hides) const;
  void split(int tx, int ty, TilePatches& tile) const;
  void test_groups(const TileShafts& tiles, int ty0, int ty1, std::vector<TilePatches>& out) const;
};

// Tile (tx, ty)'s patches: one from its block's summary where that serves (below), else its
// texels' pieces of surface, the texels the light reaches among them (TilePatches::reached).
void TileTester::find_patches(int tx, int ty, TilePatches& tile) const {
  if (blocks) {
    const std::size_t i = std::size_t(ty) * std::size_t(space.blocks_x) + std::size_t(tx);
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
      // Every covered texel of it is reached.
      std::array<std::int32_t, kTile * kTile> texel;
      grid.tile_texels(tx, ty, texel);
      for (int j = 0; j < kTile * kTile; ++j)
        if (texel[std::size_t(j)] >= 0) tile.reached |= std::uint64_t(1) << j;
      return;
    }
  }
  // Piece by piece: which texels the light reaches, read one by one only where the piece's
  // boxes cannot tell.
  const std::size_t at = std::size_t(ty) * std::size_t(joins.tiles_x) + std::size_t(tx);
  std::array<std::int32_t, kTile * kTile> texel;
  bool read = false;  // texel[] filled
  const auto texels = [&] {
    if (!read) grid.tile_texels(tx, ty, texel);
    read = true;
    return std::span<const std::int32_t, kTile * kTile>(texel);
  };
  const auto test_texels = [&](std::uint64_t pixels) {
    for (int j = 0; j < kTile * kTile; ++j) {
      if (!(pixels >> j & 1)) continue;
      const Texel& record = space.texels[std::size_t(texels()[std::size_t(j)])];
      if (light.reaches(record.position.cast<double>(), record.normal.cast<double>()))
        tile.reached |= std::uint64_t(1) << j;
    }
  };
  const std::span<const TileJoins::Piece> pieces = joins.pieces_of(at);
  std::uint64_t whole = 0;  // the pixels of pieces reached throughout
  for (const TileJoins::Piece& piece : pieces) {
    if (light.reaches_none(piece.positions, piece.normals)) continue;
    if (light.reaches_all(piece.positions, piece.normals))
      whole |= piece.pixels;
    else
      test_texels(piece.pixels);
  }
  tile.reached |= whole;
  if (pieces.empty()) {
    std::uint64_t covered = 0;
    for (int j = 0; j < kTile * kTile; ++j)
      if (texels()[std::size_t(j)] >= 0) covered |= std::uint64_t(1) << j;
    test_texels(covered);
  }
  // Their pieces of surface (the receiver's joins between texels it reaches) as patches: a
  // piece reached throughout is one (unless patches ran out) whose box is known.
  const int count = number_pieces(joins, at, tile.reached, tile.at);
  tile.patches.resize(std::size_t(count));
  if (count >= TileShafts::kMaxPatches) whole = 0;
  for (const TileJoins::Piece& piece : pieces) {
    if ((piece.pixels & whole) == 0) continue;
    tile.patches[tile.at[std::size_t(std::countr_zero(piece.pixels))]].origins = piece.origins;
    tile.step = std::max(tile.step, piece.step);
  }
  for (int j = 0; j < kTile * kTile; ++j) {
    if (!((tile.reached & ~whole) >> j & 1)) continue;
    const std::size_t t = std::size_t(texels()[std::size_t(j)]);
    if (sizes)
      tile.step = std::max(tile.step, space.face_texel_sizes[std::size_t(space.texels[t].face)]);
    tile.patches[tile.at[std::size_t(j)]].origins.extend(space.ray_origin(t, offset));
  }
}

// A patch's test: first, where it is tested down the whole hierarchy (`among` null) and an
// umbra is wanted, whether it lies in one, found without its candidates (a room behind a wall
// from a light: a third of the patches OpenArena's oacmpctf3 tests, whose candidates would be
// listed for nothing); then its candidates, or clear; then, among few candidates, whether one of
// them hides all of the light (one the centre's ray misses).
void TileTester::test(TileShafts::Patch& patch, const std::vector<std::uint32_t>* among) const {
  std::vector<std::uint32_t>& list = patch.candidates;
  std::array<Vec3, 8> corners;
  for (int k = 0; k < 8; ++k) corners[std::size_t(k)] = patch.origins.corner(k);
  const auto hides = [&](std::uint32_t triangle) {
    return hides_from_all(light, culler.triangle_corners(triangle), corners, offset);
  };
  if (umbrae && !among && dark(patch.origins, hides)) {
    list.clear();
    patch.kind = Kind::umbra;
    return;
  }
  if (!culler.tile_candidates(patch.origins, light, max, list, among)) {
    patch.kind = Kind::clear;
    return;
  }
  patch.kind = list.empty() ? Kind::all : Kind::listed;
  std::sort(list.begin(), list.end());
  if (!umbrae) return;
  // An umbra: a triangle that hides all of the light from the box's corners. Each candidate is
  // tried where they are few; where they are many (a dense mesh's small triangles, none of
  // which hides a light alone: trying them all cost the dense scene a third of its bake), only
  // the one the ray from the box's centre meets (above, for a patch tested down the hierarchy).
  const Vec3 from = patch.origins.centre(), to = light.centre();
  if (patch.kind == Kind::listed && list.size() <= kUmbraCandidates &&
      std::any_of(list.begin(), list.end(), [&](std::uint32_t triangle) {
        return segment_meets(culler.triangle_corners(triangle), from, to) && hides(triangle);
      }))
    patch.kind = Kind::umbra;
  else if (among && dark(patch.origins, hides))
    patch.kind = Kind::umbra;
}

// Whether the box lies in an umbra: of the triangle the ray from its centre to the light's
// centre meets first (`hides` says whether a triangle hides all of the light from the box), or
// of the triangles of a plane together (a wall between rooms, plane_occlusion.h).
template <class Hides>
bool TileTester::dark(const Bounds3& origins, const Hides& hides) const {
  const Vec3 from = origins.centre();
  const RayScene::Hit hit = rays.first_hit_face(from, light.centre() - from, 1.0);
  if (hit.face < 0) return false;  // the box's centre sees the light's
  return hides(culler.triangle_of_face(hit.face)) ||
         plane_hides_light(culler, rays, light, origins, &hit);
}

// Each listed patch of tile (tx, ty) cut by the tile's quadrants of kTile/2 × kTile/2 pixels,
// each part tested on its own among the patch's candidates: a quarter of the box has a narrower
// shaft, which holds fewer triangles, is often clear beside a blocker whose tile it shares, or
// in the umbra of one. (Measured on OpenArena's oacmpctf3: four in five texels the estimator
// evaluated in listed tiles came out exactly 1.) A patch stays whole where it lies in one
// quadrant, or where the tile has no room for more patches.
void TileTester::split(int tx, int ty, TilePatches& tile) const {
  constexpr int half = kTile / 2;
  const std::size_t original = tile.patches.size();
  for (std::size_t p = 0; p < original; ++p) {
    if (tile.patches[p].kind != Kind::listed) continue;
    // The patch's reached texels' ray origins, by quadrant.
    std::array<TileShafts::Patch, 4> parts;
    std::array<std::uint64_t, 4> pixels{};
    for (int j = 0; j < kTile * kTile; ++j) {
      if (!(tile.reached >> j & 1)) continue;
      if (tile.patches.size() > 1 && tile.at[std::size_t(j)] != p) continue;
      const int x = tx * kTile + j % kTile, y = ty * kTile + j / kTile;
      const std::size_t q = std::size_t((j % kTile) / half + 2 * ((j / kTile) / half));
      parts[q].origins.extend(space.ray_origin(std::size_t(grid.texel(x, y)), offset));
      pixels[q] |= std::uint64_t(1) << j;
    }
    const int used = int(
        std::count_if(pixels.begin(), pixels.end(), [](std::uint64_t bits) { return bits != 0; }));
    if (used < 2 ||
        tile.patches.size() + std::size_t(used - 1) > std::size_t(TileShafts::kMaxPatches))
      continue;
    // Each part tested among the parent's candidates, then put in: the first in the parent's
    // place, the others after the tile's patches.
    for (std::size_t q = 0; q < 4; ++q)
      if (pixels[q]) test(parts[q], &tile.patches[p].candidates);
    bool first = true;
    for (std::size_t q = 0; q < 4; ++q) {
      if (!pixels[q]) continue;
      const std::size_t at = first ? p : tile.patches.size();
      if (!first) tile.patches.emplace_back();
      first = false;
      for (int j = 0; j < kTile * kTile; ++j)
        if (pixels[q] >> j & 1) tile.at[std::size_t(j)] = std::uint8_t(at);
      tile.patches[at] = std::move(parts[q]);
    }
  }
}

// A group of g × g tiles on one piece of surface (its joint box no larger than one piece of its
// texel steps could fill) whose joint box's shaft is clear is clear throughout (each patch's
// shaft lies inside it): the test stops at the first triangle it finds. Otherwise its patches
// are tested one by one, and the listed ones cut in quadrants (split). A group of pieces from
// all over a level is not tested: its shaft would cross much of it. (Listing a group's
// candidates for its patches to be tested among cost OpenArena's oacmpctf3 a seventh of its
// shaft tests and saved none: 123,000 groups listed, 800 clear.)
void TileTester::test_groups(const TileShafts& tiles, int ty0, int ty1,
                             std::vector<TilePatches>& out) const {
  constexpr int g = TileShafts::kGroup;
  thread_local std::vector<std::uint32_t> scratch;
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
    const bool clear = filled > 1 && coherent && !culler.tile_candidates(joint, light, 0, scratch);
    for (int ty = ty0; ty < ty1; ++ty)
      for (int tx = gx; tx < x1; ++tx) {
        TilePatches& tile =
            out[std::size_t(ty - ty0) * std::size_t(tiles.tiles_x) + std::size_t(tx)];
        for (TileShafts::Patch& p : tile.patches) {
          if (clear)
            p.kind = Kind::clear;
          else
            test(p, nullptr);
        }
        if (!clear) split(tx, ty, tile);
      }
  }
}

}  // namespace

TileJoins::TileJoins(const TexelSpace& space, const TexelGrid& grid, double offset)
    : tiles_x((space.width + kTile - 1) / kTile) {
  const int tiles_y = (space.height + kTile - 1) / kTile;
  const std::size_t count = std::size_t(tiles_x) * std::size_t(tiles_y);
  right.assign(count, 0);
  down.assign(count, 0);
  const bool sizes = !space.face_texel_sizes.empty();
  const auto joined = [&](std::int32_t a, std::int32_t b) {
    if (!sizes) return true;
    const Texel& ta = space.texels[std::size_t(a)];
    const Texel& tb = space.texels[std::size_t(b)];
    const float step = std::max(space.face_texel_sizes[std::size_t(ta.face)],
                                space.face_texel_sizes[std::size_t(tb.face)]);
    return (ta.position - tb.position).norm() <= kJoinSteps * step;
  };
  std::vector<std::vector<Piece>> found(count);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count), [&](const auto& r) {
    std::array<std::int32_t, kTile * kTile> texel;
    std::array<std::uint8_t, kTile * kTile> piece_of;
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      grid.tile_texels(int(i % std::size_t(tiles_x)), int(i / std::size_t(tiles_x)), texel);
      std::uint64_t covered = 0;
      for (int j = 0; j < kTile * kTile; ++j) {
        const std::int32_t a = texel[std::size_t(j)];
        if (a < 0) continue;
        covered |= std::uint64_t(1) << j;
        if (j % kTile + 1 < kTile && texel[std::size_t(j + 1)] >= 0 &&
            joined(a, texel[std::size_t(j + 1)]))
          right[i] |= std::uint64_t(1) << j;
        if (j + kTile < kTile * kTile && texel[std::size_t(j + kTile)] >= 0 &&
            joined(a, texel[std::size_t(j + kTile)]))
          down[i] |= std::uint64_t(1) << j;
      }
      // Its pieces: the patches of a light that reaches every texel (find_patches).
      const int pieces = number_pieces(*this, i, covered, piece_of);
      if (pieces >= TileShafts::kMaxPatches) continue;
      found[i].resize(std::size_t(pieces));
      for (int j = 0; j < kTile * kTile; ++j) {
        if (!(covered >> j & 1)) continue;
        const std::size_t t = std::size_t(texel[std::size_t(j)]);
        Piece& piece = found[i][piece_of[std::size_t(j)]];
        piece.pixels |= std::uint64_t(1) << j;
        piece.positions.extend(space.texels[t].position.cast<double>());
        piece.normals.extend(space.texels[t].normal.cast<double>());
        piece.origins.extend(space.ray_origin(t, offset));
        if (sizes)
          piece.step =
              std::max(piece.step, space.face_texel_sizes[std::size_t(space.texels[t].face)]);
      }
    }
  });
  first.assign(count + 1, 0);
  for (std::size_t i = 0; i < count; ++i) {
    first[i] = std::uint32_t(pieces.size());
    pieces.insert(pieces.end(), found[i].begin(), found[i].end());
  }
  first[count] = std::uint32_t(pieces.size());
}

TileShafts tile_shafts(const TexelSpace& space, const TexelGrid& grid, const TileJoins& joins,
                       const ShaftCuller& culler, const RayScene& rays, const Light& light,
                       std::size_t max, bool umbrae, std::span<const std::uint32_t> in_reach) {
  const double offset = rays.surface_offset();
  static_assert(TileShafts::kTile == TexelBlock::kSide && kTile == TexelGrid::kSide,
                "a tile is a block of the texel space and of its grid");
  TileShafts tiles;
  tiles.tiles_x = (space.width + kTile - 1) / kTile;
  tiles.tiles_y = (space.height + kTile - 1) / kTile;
  const std::size_t count = std::size_t(tiles.tiles_x) * std::size_t(tiles.tiles_y);
  tiles.kind.assign(count, Kind::empty);
  tiles.reached.assign(count, 0);
  tiles.first_patch.assign(count + 1, 0);
  tiles.mixed.assign(count, -1);
  const bool blocks = space.blocks.size() == count;
  const bool sizes = !space.face_texel_sizes.empty();
  // Bands of kGroup tile rows that hold a tile in reach, in parallel; the rest are empty. A tile
  // whose block shares one normal, lies within the box one piece of surface of its texel steps
  // could fill, and that the light reaches all of (the sun over flat ground) is one patch that
  // takes its box from the block, shifted as each ray origin is (the same box: rounding is
  // monotonic), and its texels' records are not read.
  constexpr int g = TileShafts::kGroup;
  std::vector<int> bands;  // ascending
  for (const std::uint32_t i : in_reach) {
    const int band = int(i / std::size_t(tiles.tiles_x)) / g;
    if (bands.empty() || bands.back() != band) bands.push_back(band);
  }
  std::vector<std::vector<TilePatches>> found(bands.size());
  const TileTester tester{space, grid,   joins,  culler, rays, light,
                          max,   umbrae, offset, blocks, sizes};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, bands.size()), [&](const auto& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k) {
      const int ty0 = bands[k] * g, ty1 = std::min(ty0 + g, tiles.tiles_y);
      const std::size_t first = std::size_t(ty0) * std::size_t(tiles.tiles_x);
      std::vector<TilePatches>& out = found[k];
      out.assign(std::size_t(ty1 - ty0) * std::size_t(tiles.tiles_x), TilePatches());
      // The band's tiles in reach.
      const auto from = std::lower_bound(in_reach.begin(), in_reach.end(), std::uint32_t(first));
      const auto to = std::lower_bound(
          from, in_reach.end(), std::uint32_t(std::size_t(ty1) * std::size_t(tiles.tiles_x)));
      for (auto i = from; i != to; ++i)
        tester.find_patches(int(*i % std::uint32_t(tiles.tiles_x)),
                            int(*i / std::uint32_t(tiles.tiles_x)), out[*i - first]);
      tester.test_groups(tiles, ty0, ty1, out);
    }
  });
  // The bands' patches in tile order.
  std::size_t next_band = 0;
  for (std::size_t i = 0; i < count; ++i) {
    tiles.first_patch[i] = std::uint32_t(tiles.patches.size());
    const int band = int(i / std::size_t(tiles.tiles_x)) / g;
    while (next_band < bands.size() && bands[next_band] < band) ++next_band;
    if (next_band == bands.size() || bands[next_band] != band) continue;  // none in reach
    TilePatches& tile = found[next_band][i - std::size_t(band * g) * std::size_t(tiles.tiles_x)];
    tiles.reached[i] = tile.reached;
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
  }
  tiles.first_patch[count] = std::uint32_t(tiles.patches.size());
  return tiles;
}

}  // namespace sb
