// TexelIndex (texel_index.h): the grid of a frame's texels by tangent coordinates, its cells and
// its blocks of cells with their bounds.
#include "methods/convolution/texel_index.h"

#include <cmath>

namespace sb {

void TexelIndex::build(const std::vector<int>& texels, const std::vector<Vec2>& tangent,
                       const std::vector<double>& depth, const std::vector<Vec3>& position) {
  if (texels.empty()) return;
  TangentBounds bounds;
  for (int i : texels) bounds.extend(tangent[std::size_t(i)]);
  lo = bounds.lo;
  // About 16 texels per cell.
  const Vec2 span = (bounds.hi - lo).cwiseMax(1e-12);
  cell = std::sqrt(span.x() * span.y() * 16.0 / double(texels.size()));
  cell = std::max({cell, span.maxCoeff() / 4096.0, 1e-12});
  nx = std::max(1, int(span.x() / cell) + 1);
  ny = std::max(1, int(span.y() / cell) + 1);
  auto cell_of = [&](int i) {
    const Vec2& t = tangent[std::size_t(i)];
    const int x = std::min(nx - 1, int((t.x() - lo.x()) / cell));
    const int y = std::min(ny - 1, int((t.y() - lo.y()) / cell));
    return std::size_t(y) * nx + x;
  };
  start.assign(std::size_t(nx) * ny + 1, 0);
  for (int i : texels) ++start[cell_of(i) + 1];
  for (std::size_t c = 1; c < start.size(); ++c) start[c] += start[c - 1];
  items.resize(texels.size());
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (int i : texels) items[std::size_t(fill[cell_of(i)]++)] = i;
  cells.assign(std::size_t(nx) * ny, Cell{});
  for (int i : texels) {
    Cell& c = cells[cell_of(i)];
    c.tangents.extend(tangent[std::size_t(i)]);
    c.depth.extend(depth[std::size_t(i)]);
    c.box.extend(position[std::size_t(i)]);
    ++c.count;
  }
  bx = (nx + kBlock - 1) / kBlock;
  by = (ny + kBlock - 1) / kBlock;
  blocks.assign(std::size_t(bx) * by, Cell{});
  for (int y = 0; y < ny; ++y) {
    for (int x = 0; x < nx; ++x) {
      const Cell& c = cells[std::size_t(y) * nx + x];
      if (c.count == 0) continue;
      Cell& b = blocks[std::size_t(y / kBlock) * bx + x / kBlock];
      b.tangents.extend(c.tangents);
      b.depth.extend(c.depth.lo);
      b.depth.extend(c.depth.hi);
      b.box.extend(c.box.lo);
      b.box.extend(c.box.hi);
      b.count += c.count;
    }
  }
}

}  // namespace sb
