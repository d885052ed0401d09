// Stage 1 of the `backprojection` bake (backprojection_bake.cpp), per light: every tile of
// TileShafts::kTile² texels tested as one box of its texels' ray origins (tile_shafts.cpp).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "core/geometry.h"
#include "methods/backprojection/texel_grid.h"
#include "occluders/ray_scene.h"
#include "occluders/shaft_culling.h"
#include "scene/lights.h"
#include "texels/texel_space.h"

namespace sb {

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

// Whether the triangle `corners` hides all of the light from every one of `points`, the first
// likeliest to fail first (triangle_hides_light).
bool hides_from_all(const Light& light, const Vec3* corners, std::span<const Vec3> points,
                    double offset);

// Which neighbouring texels of each tile lie on one piece of surface (no farther apart than
// their faces' texel steps allow; every neighbour where the space has no steps): what splits a
// tile into patches, whatever the light; and those pieces, which say for a light whether it
// reaches all or none of a piece's texels without their records. Built once per receiver
// (tile_shafts.cpp), for ray origins `offset` off their surfaces.
struct TileJoins {
  int tiles_x = 0;
  // Per tile, a bit per pixel j (row-major within the tile): j joined to j + 1 (`right`, never
  // in the tile's last column) or to j + kTile (`down`).
  std::vector<std::uint64_t> right, down;
  // One piece of a tile's covered texels, joined: its pixels, the boxes of its texels'
  // positions and shading normals (Light::reaches_all and reaches_none read them), of their
  // ray origins, and the largest texel step of their faces.
  struct Piece {
    std::uint64_t pixels = 0;
    Bounds3 positions, normals, origins;
    float step = 0;
  };
  // Tile i's pieces: pieces[first[i], first[i + 1]), none where it has TileShafts::kMaxPatches
  // or more (its texels are then read one by one).
  std::vector<std::uint32_t> first;
  std::vector<Piece> pieces;
  std::span<const Piece> pieces_of(std::size_t tile) const {
    return {pieces.data() + first[tile], pieces.data() + first[tile + 1]};
  }
  TileJoins(const TexelSpace& space, const TexelGrid& grid, double offset);
};

// The most candidates a tile lists before its texels search the hierarchy one by one.
inline constexpr std::size_t kTileCandidates = 1 << 16;

// The shaft test of each of the tiles `in_reach` (indices, ascending: the blocks the light's
// lists give it, methods/light_lists.h; every other tile is empty) for `light`, patch by patch
// (TileShafts; ShaftCuller::tile_candidates, at most `max` candidates a patch): clear, listed,
// all, or, with `umbrae`, an umbra where a triangle hides all of the light from the eight
// corners of its box of ray origins (so from every one of them: a triangle's umbra is convex):
// the triangle the ray from the box's centre to the light's centre meets, or one of its
// candidates. `rays`: those rays, and the surface offset.
// `joins` are the receiver's.
TileShafts tile_shafts(const TexelSpace& space, const TexelGrid& grid, const TileJoins& joins,
                       const ShaftCuller& culler, const RayScene& rays, const Light& light,
                       std::size_t max, bool umbrae, std::span<const std::uint32_t> in_reach);

}  // namespace sb
