// Lightmap texel space: which texels of a receiver's UV layout are covered by its triangles, and
// for each covered texel the world position and normals that the bake methods shade. Built by
// rasterise_texels (uv_rasterizer.cpp); grown into the margin by dilate (dilation.cpp).
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "core/fresh_memory.h"
#include "core/geometry.h"
#include "core/image.h"
#include "scene/mesh.h"

namespace sb {

// Single precision: a 2048² lightmap has 4 M texels, and their memory traffic, not arithmetic,
// bounds the fast methods; the methods compute in double from these. 32 bytes: a 4096² receiver's
// 16.8 M records are half a gigabyte, each page of it a fault on first touch, and every method
// passes over them. What a texel shares with its triangle is kept per face (TexelSpace), and its
// shadow origin only where it differs from its position.
struct Texel {
  std::uint16_t x = 0, y = 0;  // pixel; row 0 is v = 1 (a lightmap is at most 16384 wide)
  Vec3f position;              // world space, on the triangle
  Vec3f normal;                // interpolated shading normal, unit
  int face = -1;               // index of the covering triangle
};
static_assert(sizeof(Texel) == 32, "a texel record is 32 bytes");

// What a square of kSide × kSide pixels of a texel space holds, for a method that tests texels
// block by block without reading their records: the box of their positions and, where they
// share them, their shading and face normals (a flat receiver's blocks all do).
struct TexelBlock {
  static constexpr int kSide = 8;
  Vec3f lo{1, 1, 1}, hi{0, 0, 0};  // lo > hi: no texel
  // Whether every texel has `normal` as its shading normal, `geometric` as its geometric_normal
  // and no lift (its shadow origin is its position).
  bool uniform = false;
  Vec3f normal = Vec3f::Zero(), geometric = Vec3f::Zero();
  // The largest texel step on the surface among its texels' faces (TexelSpace::face_texel_sizes).
  float texel_size = 0;
  bool empty() const { return lo.x() > hi.x(); }
};

// Rows [begin, end) of a lightmap.
struct RowRange {
  int begin = 0, end = std::numeric_limits<int>::max();
  bool operator==(const RowRange&) const = default;
};

struct TexelSpace {
  int width = 0, height = 0;
  // Covered texels, in row-major order.
  FreshVector<Texel> texels;
  // Per face of the mesh: its unit normal (from its corners' positions).
  std::vector<Vec3f> face_normals;
  // Per face: the farthest apart two of its texels one pixel apart in the lightmap can lie on
  // the surface, metres (the largest stretch of its UV-to-surface map, at most its longest
  // side): two neighbouring texels farther apart than their faces' steps lie on different
  // pieces of surface (a UV chart border). 0 for a face that covers no texel.
  std::vector<float> face_texel_sizes;
  // Per face, where some face's corners' shading normals differ (a smooth-shaded receiver; empty
  // where none's do): its corners in texel coordinates (x = u·width, y = (1 − v)·height, texel
  // (x, y) the unit square from (x, y)) and their shading normals, which texel normals
  // interpolate. What a texel's square holds beyond its centre (methods/terminator_fill.h).
  struct FaceShading {
    Vec2f corner[3];
    Vec3f normal[3];
  };
  std::vector<FaceShading> face_shading;
  // Per texel, where some texel's shadow origin is not its position (a curved mesh's, below):
  // shadow origin − position; empty where every texel's is its position.
  FreshVector<Vec3f> lifts;
  std::vector<std::uint8_t> covered;  // width * height; 1 where a texel of `texels` lies
  // Per block of TexelBlock::kSide² pixels, row-major (blocks_x per row): what its texels hold.
  int blocks_x = 0;
  std::vector<TexelBlock> blocks;
  // Texels whose centre two UV triangles claim (inside one, inside or on the other): charts that
  // overlap in the lightmap, so one surface point stands for two (check_uv_layout reports it).
  std::int64_t overlapping_texels = 0;
  // A tile's texel space (pipeline/tiles.h) holds some rows only: the tile's own, `kept`, and a
  // halo around them that its method needs to value them as a bake of every row would. Methods
  // count the kept rows' texels alone (a tile's counts add up to the whole receiver's); the
  // halo's values are dropped. A whole receiver's keeps every row.
  RowRange kept;

  // Texel i's face normal, on the side of its shading normal.
  Vec3f geometric_normal(std::size_t i) const {
    const Texel& t = texels[i];
    const Vec3f& n = face_normals[std::size_t(t.face)];
    return n.dot(t.normal) < 0 ? Vec3f(-n) : n;
  }
  // Where texel i's shadow rays leave from: its position lifted onto the smooth surface the
  // vertex normals describe (uv_rasterizer.cpp), so a coarsely tessellated curved object does not
  // shadow itself along its terminator; its position on flat faces.
  Vec3f shadow_origin(std::size_t i) const {
    return lifts.empty() ? texels[i].position : Vec3f(texels[i].position + lifts[i]);
  }
  // The shadow origin moved `offset` metres off the surface along the face normal: where the
  // methods' shadow rays start.
  Vec3 ray_origin(std::size_t i, double offset) const {
    return shadow_origin(i).cast<double>() + offset * geometric_normal(i).cast<double>();
  }
};

// The kept rows' texels: indices [first, second) into space.texels (row-major).
inline std::pair<std::size_t, std::size_t> kept_texels(const TexelSpace& space) {
  const auto at = [&](int row) {
    return std::size_t(std::lower_bound(space.texels.begin(), space.texels.end(), row,
                                        [](const Texel& t, int y) { return t.y < y; }) -
                       space.texels.begin());
  };
  return {at(space.kept.begin), at(space.kept.end)};
}

// Rasterises mesh's triangles in UV space at width × height. A texel whose centre lies inside a
// triangle takes that point; a texel that a triangle touches but whose centre no triangle covers
// (thin triangles, chart borders) takes the triangle's point nearest its centre (conservative
// coverage), so thin geometry is never lost. UVs outside [0, 1] are clipped. With `rows`, only
// those rows are rasterised (their texels are those a whole rasterisation gives them); `covered`
// is still width × height.
TexelSpace rasterise_texels(const Mesh& mesh, int width, int height, RowRange rows = {});

// Grows image values outward from covered texels by `margin` texels: each ring of uncovered
// texels takes the mean of its already-filled 8-neighbours, so bilinear filtering and mip-mapping
// near chart borders do not pull in black. Texels further than `margin` stay as they are.
void dilate(Image& image, const std::vector<std::uint8_t>& covered, int margin);

// The same where the image holds one value at every pixel but those within 2 · margin + 2 of
// the tiles (of tile × tile pixels, row-major) that `visit` marks (a light's own image beyond the
// tiles it reaches): there dilation takes the mean of equal values, so only the marked tiles'
// pixels are visited, with the same result.
void dilate(Image& image, const std::vector<std::uint8_t>& covered, int margin,
            const std::vector<std::uint8_t>& visit, int tile);

}  // namespace sb
