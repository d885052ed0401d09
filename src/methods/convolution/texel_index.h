// A uniform grid over a frame's tangent coordinates holding receiver texel indices, with the
// bounds of each cell's and each block of cells' texels, so that the convolution planner finds a
// footprint's texels (and takes whole cells of them at once) without visiting the others.
#pragma once

#include <algorithm>
#include <vector>

#include "core/geometry.h"
#include "methods/convolution/virtual_configuration.h"
#include "occluders/tangent_bounds.h"

namespace sb {

// A uniform grid over tangent coordinates holding texel indices, so a footprint's texels are
// found without visiting the others.
struct TexelIndex {
  Vec2 lo = Vec2::Zero();
  double cell = 1;
  int nx = 0, ny = 0;
  std::vector<int> start;  // nx·ny + 1 offsets into items
  std::vector<int> items;  // frame texel indices, by cell

  // Per cell: the bounds of its texels' tangents, depths and positions, and their count, so a
  // footprint that holds a whole cell takes it at once (for_each_cell).
  struct Cell {
    TangentBounds tangents;
    DepthRange depth;
    Bounds3 box;
    int count = 0;
  };
  std::vector<Cell> cells;
  // Blocks of kBlock × kBlock cells with the same aggregates, so that a footprint covering most
  // of a large receiver takes it a block at a time (thousands of footprints are scanned while
  // planning).
  static constexpr int kBlock = 8;
  int bx = 0, by = 0;
  std::vector<Cell> blocks;

  void build(const std::vector<int>& texels, const std::vector<Vec2>& tangent,
             const std::vector<double>& depth, const std::vector<Vec3>& position);
  // Like for_each, but a block or cell whose texels all lie in the box and pass `whole(cell)`
  // goes to cell(cell) instead of texel by texel.
  template <class W, class C, class F>
  void for_each_cell(const Vec2& box_lo, const Vec2& box_hi, W&& whole, C&& cell, F&& f) const {
    if (nx == 0) return;
    const int x0 = std::max(0, int((box_lo.x() - lo.x()) / this->cell));
    const int y0 = std::max(0, int((box_lo.y() - lo.y()) / this->cell));
    const int x1 = std::min(nx - 1, int((box_hi.x() - lo.x()) / this->cell));
    const int y1 = std::min(ny - 1, int((box_hi.y() - lo.y()) / this->cell));
    if (x0 > x1 || y0 > y1) return;
    auto inside = [&](const Cell& k) {
      return (k.tangents.lo.array() >= box_lo.array()).all() &&
             (k.tangents.hi.array() <= box_hi.array()).all() && whole(k);
    };
    for (int yb = y0 / kBlock; yb <= y1 / kBlock; ++yb) {
      for (int xb = x0 / kBlock; xb <= x1 / kBlock; ++xb) {
        const Cell& b = blocks[std::size_t(yb) * bx + xb];
        if (b.count == 0) continue;
        if (inside(b)) {
          cell(b);
          continue;
        }
        const int cy1 = std::min(y1, yb * kBlock + kBlock - 1);
        const int cx1 = std::min(x1, xb * kBlock + kBlock - 1);
        for (int y = std::max(y0, yb * kBlock); y <= cy1; ++y) {
          for (int x = std::max(x0, xb * kBlock); x <= cx1; ++x) {
            const std::size_t c = std::size_t(y) * nx + x;
            const Cell& k = cells[c];
            if (k.count == 0) continue;
            if (inside(k)) {
              cell(k);
              continue;
            }
            for (int i = start[c]; i < start[c + 1]; ++i) f(items[std::size_t(i)]);
          }
        }
      }
    }
  }
  // Calls f(i) for every texel i whose cell meets the box [lo, hi] (callers test the box).
  template <class F>
  void for_each(const Vec2& box_lo, const Vec2& box_hi, F&& f) const {
    if (nx == 0) return;
    const int x0 = std::max(0, int((box_lo.x() - lo.x()) / cell));
    const int y0 = std::max(0, int((box_lo.y() - lo.y()) / cell));
    const int x1 = std::min(nx - 1, int((box_hi.x() - lo.x()) / cell));
    const int y1 = std::min(ny - 1, int((box_hi.y() - lo.y()) / cell));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x)
        for (int k = start[std::size_t(y) * nx + x]; k < start[std::size_t(y) * nx + x + 1]; ++k)
          f(items[std::size_t(k)]);
  }
};

}  // namespace sb
