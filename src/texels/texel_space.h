// Lightmap texel space: which texels of a receiver's UV layout are covered by its triangles, and
// for each covered texel the world position and normals that the bake methods shade. Built by
// rasterise_texels (uv_rasterizer.cpp); grown into the margin by dilate (dilation.cpp).
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/geometry.h"
#include "core/image.h"
#include "scene/mesh.h"

namespace sb {

// Single precision: a 2048² lightmap has 4 M texels, and their memory traffic, not arithmetic,
// bounds the fast methods; the methods compute in double from these.
struct Texel {
  int x = 0, y = 0;        // pixel; row 0 is v = 1
  Vec3f position;          // world space, on the triangle
  Vec3f normal;            // interpolated shading normal, unit
  Vec3f geometric_normal;  // the triangle's face normal, unit, on the side of `normal`
  // Where shadow rays leave from: `position` lifted onto the smooth surface the vertex normals
  // describe (uv_rasterizer.cpp), so a coarsely tessellated curved object does not shadow
  // itself along its terminator. Equal to `position` on flat faces.
  Vec3f shadow_origin;
  int face = -1;  // index of the covering triangle
};

// Rows [begin, end) of a lightmap.
struct RowRange {
  int begin = 0, end = std::numeric_limits<int>::max();
  bool operator==(const RowRange&) const = default;
};

// The texel records' allocator: std::allocator, but a record made without a value (resize) is
// left as the memory holds it, so that the rasteriser sizes the array without writing it and then
// writes each record once, in parallel. A 4096² receiver's records are a gigabyte, and a serial
// first write of them cost a second on a virtual machine whose every first touch of a page is a
// fault (perf: the kernel zeroing pages under std::vector::resize). Texel is an aggregate, an
// implicit-lifetime type: its storage holds one before the rasteriser assigns it.
static_assert(std::is_aggregate_v<Texel>, "RecordAllocator leaves Texel storage to be assigned");
template <typename T>
struct RecordAllocator : std::allocator<T> {
  template <typename U>
  struct rebind {
    using other = RecordAllocator<U>;
  };
  RecordAllocator() = default;
  template <typename U>
  RecordAllocator(const RecordAllocator<U>&) noexcept {}
  template <typename U>
  void construct(U*) noexcept {}
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

struct TexelSpace {
  int width = 0, height = 0;
  // Covered texels, in row-major order.
  std::vector<Texel, RecordAllocator<Texel>> texels;
  std::vector<std::uint8_t> covered;  // width * height; 1 where a texel of `texels` lies
  // Texels whose centre two UV triangles claim (inside one, inside or on the other): charts that
  // overlap in the lightmap, so one surface point stands for two (check_uv_layout reports it).
  std::int64_t overlapping_texels = 0;
  // A tile's texel space (pipeline/tiles.h) holds some rows only: the tile's own, `kept`, and a
  // halo around them that its method needs to value them as a bake of every row would. Methods
  // count the kept rows' texels alone (a tile's counts add up to the whole receiver's); the
  // halo's values are dropped. A whole receiver's keeps every row.
  RowRange kept;
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

}  // namespace sb
