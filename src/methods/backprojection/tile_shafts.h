// Stage 1 of the `backprojection` bake (backprojection_bake.cpp), per light: every tile of
// TileShafts::kTile² texels tested as one box of its texels' ray origins (tile_shafts.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "core/geometry.h"
#include "methods/backprojection/texel_refinement.h"
#include "occluders/ray_scene.h"
#include "occluders/shaft_culling.h"
#include "scene/lights.h"
#include "texels/texel_space.h"

namespace sb {

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
