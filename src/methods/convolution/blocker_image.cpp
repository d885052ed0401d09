// The blocker image (docs/design.md §2–3; docs/design.md [S1], "Transforming
// into Parallel Configuration"): the blockers seen from the light's centre, as a coverage image
// P on the blocker plane. Coverage rather than a binary point sample per pixel, because the
// convolution turns a staircase in P into a staircase in every penumbra (docs/design.md §2
// measured it); 4 × 4 samples per pixel, as an OR of 16-bit masks so that overlapping triangles
// (the front and back of a closed mesh) count once.
#include "methods/convolution/blocker_image.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>

#include "occluders/depth_clipping.h"
#include "occluders/tangent_bounds.h"

namespace sb {

namespace {

constexpr int kSamplesPerSide = 4;  // 16 samples: one bit each of a uint16_t

// Edge functions of a convex counter-clockwise polygon: inside where every a·x + b·y + c >= 0.
struct Edges {
  std::vector<Vec3> lines;  // (a, b, c)
  explicit Edges(const std::vector<Vec2>& pts) {
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Vec2& p = pts[i];
      const Vec2& q = pts[(i + 1) % pts.size()];
      const Vec2 n(-(q.y() - p.y()), q.x() - p.x());  // left normal: inside for CCW
      lines.emplace_back(n.x(), n.y(), -n.dot(p));
    }
  }
  bool contains(double px, double py) const {
    for (const Vec3& e : lines)
      if (e.x() * px + e.y() * py + e.z() < 0) return false;
    return true;
  }
  // Like contains, but a point on an edge belongs to one side only (the usual top-left rule,
  // by the sign of the edge's normal): two polygons sharing an edge with opposite windings
  // never both hold it, so parities of overlapping polygons count each crossing once.
  bool contains_once(double px, double py) const {
    for (const Vec3& e : lines) {
      const double v = e.x() * px + e.y() * py + e.z();
      if (v < 0 || (v == 0 && !(e.x() > 0 || (e.x() == 0 && e.y() > 0)))) return false;
    }
    return true;
  }
  // Pixel [x, x+1] × [y, y+1] from its corners: −1 wholly outside one edge, +1 wholly inside
  // every edge, 0 straddling (needs samples).
  int classify(int x, int y) const {
    bool all_inside = true;
    for (const Vec3& e : lines) {
      const double c00 = e.x() * x + e.y() * y + e.z();
      const double c10 = c00 + e.x(), c01 = c00 + e.y(), c11 = c10 + e.y();
      if (std::max(std::max(c00, c10), std::max(c01, c11)) < 0) return -1;
      if (std::min(std::min(c00, c10), std::min(c01, c11)) < 0) all_inside = false;
    }
    return all_inside ? 1 : 0;
  }
};

// A projected polygon in pixel units of a grid (pixel (i, j) spans [i, i+1] × [j, j+1]) with the
// pixels its bounding box covers; false when it misses the grid.
struct PixelPolygon {
  Edges edges;
  int x0, x1, y0, y1;
};

bool to_pixels(const ProjectedBlockers::Polygon& pg, const TangentGrid& grid, PixelPolygon* out) {
  const Vec2 lo = (pg.lo - grid.origin) / grid.pixel, hi = (pg.hi - grid.origin) / grid.pixel;
  const int x0 = std::max(0, int(std::floor(lo.x()))), x1 = std::min(grid.width - 1, int(hi.x()));
  const int y0 = std::max(0, int(std::floor(lo.y()))), y1 = std::min(grid.height - 1, int(hi.y()));
  if (x0 > x1 || y0 > y1) return false;
  std::vector<Vec2> pts;
  pts.reserve(pg.points.size());
  for (const Vec2& p : pg.points) pts.push_back((p - grid.origin) / grid.pixel);
  *out = PixelPolygon{Edges(pts), x0, x1, y0, y1};
  return true;
}

}  // namespace

ProjectedBlockers project_faces(const std::vector<FaceRef>& faces, const ProjectionFrame& frame,
                                double near, double far, const ShadowCaster& caster) {
  ProjectedBlockers out;
  const Vec3& lo = caster.receiver.lo;
  const Vec3& hi = caster.receiver.hi;
  const double scale = std::max(1.0, (hi - lo).norm());
  std::vector<Vec3> poly;
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const TriMesh& mesh = faces[i].mesh->mesh;
    poly.clear();
    for (auto v : mesh.fv_range(mesh.face_handle(faces[i].face))) {
      const auto& p = mesh.point(v);
      poly.emplace_back(p[0], p[1], p[2]);
    }
    const Vec3 normal = (poly[1] - poly[0]).cross(poly[2] - poly[0]);
    if (normal.norm() > 0 && !caster.receiver.empty()) {
      const Vec3 n = normal.normalized();
      const double light_side = n.dot(frame.origin - poly[0]);
      if (std::abs(light_side) > caster.light_radius) {
        // The receiver's extreme distance to the plane on the side away from the light; the
        // receiver may touch the plane (a box standing on the floor).
        const double sign = light_side > 0 ? 1.0 : -1.0;
        double lowest = std::numeric_limits<double>::infinity();
        for (int corner = 0; corner < 8; ++corner) {
          const Vec3 c(corner & 1 ? hi.x() : lo.x(), corner & 2 ? hi.y() : lo.y(),
                       corner & 4 ? hi.z() : lo.z());
          lowest = std::min(lowest, sign * n.dot(c - poly[0]));
        }
        if (lowest >= -1e-6 * scale) continue;  // light and receiver on one side
      }
    }
    std::vector<Vec3> clipped = clip_to_depth(poly, frame, near, KeepDepth::at_least);
    if (clipped.size() >= 3) clipped = clip_to_depth(clipped, frame, far, KeepDepth::at_most);
    if (clipped.size() < 3) continue;
    ProjectedBlockers::Polygon pg;
    pg.source = int(i);
    pg.depth_lo = std::numeric_limits<double>::infinity();
    pg.depth_hi = -pg.depth_lo;
    for (const Vec3& p : clipped) {
      pg.points.push_back(frame.tangent(p));
      const double d = frame.depth(p);
      pg.depth_lo = std::min(pg.depth_lo, d);
      pg.depth_hi = std::max(pg.depth_hi, d);
    }
    double area2 = 0;
    for (std::size_t k = 0; k < pg.points.size(); ++k) {
      const Vec2& a = pg.points[k];
      const Vec2& b = pg.points[(k + 1) % pg.points.size()];
      area2 += a.x() * b.y() - a.y() * b.x();
    }
    if (std::abs(area2) < 1e-18) continue;  // seen edge-on: covers nothing
    if (area2 < 0) std::reverse(pg.points.begin(), pg.points.end());
    // 1/depth along the ray o + λ(D + t1·e1 + t2·e2) meeting the plane n·(x − p0) = 0.
    const double h = normal.dot(poly[0] - frame.origin);
    if (std::abs(h) > 0) {
      pg.inverse_depth =
          Vec3(normal.dot(frame.e1), normal.dot(frame.e2), normal.dot(frame.axis)) / h;
    }
    const TangentBounds bounds = tangent_bounds(pg.points);
    pg.lo = bounds.lo;
    pg.hi = bounds.hi;
    out.polygons.push_back(std::move(pg));
  }
  return out;
}

std::vector<float> nearest_layer_coverage(const ProjectedBlockers& layer,
                                          const std::vector<std::uint8_t>& mine, double depth_lo,
                                          double depth_hi, const TangentGrid& grid) {
  const int w = grid.width, h = grid.height;
  std::vector<float> coverage(std::size_t(w) * h, 0.0f);
  struct Raster {
    PixelPolygon pixels;
    Vec3 inverse_depth;  // 1/depth in pixel coordinates
    bool mine;
  };
  // Only samples inside one of the cluster's polygons within the slab can count: every raster
  // is clipped to their pixel bounds, outside which the image stays 0 whatever lies there.
  int mx0 = w, mx1 = -1, my0 = h, my1 = -1;
  for (std::size_t i = 0; i < layer.polygons.size(); ++i) {
    const auto& pg = layer.polygons[i];
    if (!mine[i] || pg.depth_lo > depth_hi || pg.depth_hi < depth_lo) continue;
    PixelPolygon box{Edges({}), 0, 0, 0, 0};
    if (!to_pixels(pg, grid, &box)) continue;
    mx0 = std::min(mx0, box.x0);
    mx1 = std::max(mx1, box.x1);
    my0 = std::min(my0, box.y0);
    my1 = std::max(my1, box.y1);
  }
  if (mx0 > mx1 || my0 > my1) return coverage;
  std::vector<Raster> rasters;
  bool any_mine = false;
  for (std::size_t i = 0; i < layer.polygons.size(); ++i) {
    const auto& pg = layer.polygons[i];
    // A polygon wholly beyond the slab only ever wins samples that then count for nobody, and
    // any nearer polygon wins over it anyway: leaving it out changes nothing.
    if (pg.depth_lo > depth_hi) continue;
    Raster r{PixelPolygon{Edges({}), 0, 0, 0, 0}, Vec3::Zero(), mine[i] != 0};
    if (!to_pixels(pg, grid, &r.pixels)) continue;
    r.pixels.x0 = std::max(r.pixels.x0, mx0);
    r.pixels.x1 = std::min(r.pixels.x1, mx1);
    r.pixels.y0 = std::max(r.pixels.y0, my0);
    r.pixels.y1 = std::min(r.pixels.y1, my1);
    if (r.pixels.x0 > r.pixels.x1 || r.pixels.y0 > r.pixels.y1) continue;
    // t = origin + pixel·q turns 1/depth = a·t + c into a function of pixel coordinates q.
    const Vec3& a = pg.inverse_depth;
    r.inverse_depth = Vec3(a.x() * grid.pixel, a.y() * grid.pixel,
                           a.x() * grid.origin.x() + a.y() * grid.origin.y() + a.z());
    rasters.push_back(std::move(r));
    any_mine = any_mine || mine[i];
  }
  if (!any_mine) return coverage;
  const double inv_lo = depth_hi > 0 ? 1.0 / depth_hi : 0.0;  // depth < depth_hi
  const double inv_hi = depth_lo > 0 ? 1.0 / depth_lo : std::numeric_limits<double>::infinity();
  constexpr int kS = kSamplesPerSide * kSamplesPerSide;
  constexpr int kBand = 8;
  tbb::parallel_for(tbb::blocked_range<int>(0, (my1 - my0) / kBand + 1), [&](const auto& bands) {
    std::vector<float> nearest;       // per sample: largest 1/depth so far
    std::vector<std::uint8_t> owner;  // per sample: whether that polygon is mine
    for (int band = bands.begin(); band != bands.end(); ++band) {
      const int row0 = my0 + band * kBand, row1 = std::min(my1 + 1, row0 + kBand);
      nearest.assign(std::size_t(row1 - row0) * w * kS, 0.0f);
      owner.assign(nearest.size(), 0);
      for (const Raster& r : rasters) {
        const PixelPolygon& px_poly = r.pixels;
        const int y0 = std::max(px_poly.y0, row0), y1 = std::min(px_poly.y1, row1 - 1);
        // 1/depth at each sample of a pixel is its value at the pixel's corner plus a fixed
        // offset per sample.
        std::array<float, kS> sample_inv;
        for (int k = 0; k < kS; ++k) {
          sample_inv[std::size_t(k)] =
              float(r.inverse_depth.x() * (k % kSamplesPerSide + 0.5) / kSamplesPerSide +
                    r.inverse_depth.y() * (k / kSamplesPerSide + 0.5) / kSamplesPerSide);
        }
        for (int y = y0; y <= y1; ++y) {
          for (int x = px_poly.x0; x <= px_poly.x1; ++x) {
            const int cls = px_poly.edges.classify(x, y);
            if (cls < 0) continue;
            const std::size_t base = (std::size_t(y - row0) * w + x) * kS;
            const float corner =
                float(r.inverse_depth.x() * x + r.inverse_depth.y() * y + r.inverse_depth.z());
            for (int k = 0; k < kS; ++k) {
              if (cls == 0 &&
                  !px_poly.edges.contains(x + (k % kSamplesPerSide + 0.5) / kSamplesPerSide,
                                          y + (k / kSamplesPerSide + 0.5) / kSamplesPerSide))
                continue;
              const float inv = corner + sample_inv[std::size_t(k)];
              if (inv > nearest[base + std::size_t(k)]) {
                nearest[base + std::size_t(k)] = inv;
                owner[base + std::size_t(k)] = r.mine ? 1 : 0;
              }
            }
          }
        }
      }
      for (int y = row0; y < row1; ++y) {
        for (int x = mx0; x <= mx1; ++x) {
          const std::size_t base = (std::size_t(y - row0) * w + x) * kS;
          int count = 0;
          for (int k = 0; k < kS; ++k) {
            const double inv = nearest[base + k];
            if (owner[base + k] && inv > inv_lo && inv <= inv_hi) ++count;
          }
          coverage[std::size_t(y) * w + x] = float(count) / kS;
        }
      }
    }
  });
  return coverage;
}

std::vector<float> blocker_coverage(const ProjectedBlockers& blockers, const TangentGrid& grid,
                                    const ProjectedBlockers* section) {
  const int w = grid.width, h = grid.height;
  std::vector<float> coverage(std::size_t(w) * h, 0.0f);
  auto rasterise = [&](const ProjectedBlockers& from) {
    std::vector<PixelPolygon> out;
    out.reserve(from.polygons.size());
    for (const auto& pg : from.polygons) {
      PixelPolygon r{Edges({}), 0, 0, 0, 0};
      if (to_pixels(pg, grid, &r)) out.push_back(std::move(r));
    }
    return out;
  };
  const std::vector<PixelPolygon> rasters = rasterise(blockers);
  const std::vector<PixelPolygon> crossings =
      section ? rasterise(*section) : std::vector<PixelPolygon>{};

  constexpr int kBand = 16;
  tbb::parallel_for(tbb::blocked_range<int>(0, (h + kBand - 1) / kBand), [&](const auto& bands) {
    std::vector<std::uint16_t> masks, parity;
    for (int band = bands.begin(); band != bands.end(); ++band) {
      const int row0 = band * kBand, row1 = std::min(h, row0 + kBand);
      masks.assign(std::size_t(row1 - row0) * w, 0);
      for (const PixelPolygon& r : rasters) {
        const int y0 = std::max(r.y0, row0), y1 = std::min(r.y1, row1 - 1);
        if (y0 > y1) continue;
        for (int y = y0; y <= y1; ++y) {
          for (int x = r.x0; x <= r.x1; ++x) {
            std::uint16_t& mask = masks[std::size_t(y - row0) * w + x];
            if (mask == 0xFFFF) continue;
            // Corners first: a pixel wholly inside or wholly outside one edge needs no samples.
            const int cls = r.edges.classify(x, y);
            if (cls < 0) continue;
            if (cls > 0) {
              mask = 0xFFFF;
              continue;
            }
            std::uint16_t bits = 0;
            for (int sy = 0; sy < kSamplesPerSide; ++sy) {
              for (int sx = 0; sx < kSamplesPerSide; ++sx) {
                const double px = x + (sx + 0.5) / kSamplesPerSide;
                const double py = y + (sy + 0.5) / kSamplesPerSide;
                if (r.edges.contains(px, py))
                  bits |= std::uint16_t(1u << (sy * kSamplesPerSide + sx));
              }
            }
            mask |= bits;
          }
        }
      }
      // The section: a sample is inside the solid at the section's depth when its ray from the
      // light's centre has crossed the solid's surface an odd number of times before it.
      if (!crossings.empty()) {
        parity.assign(masks.size(), 0);
        for (const PixelPolygon& r : crossings) {
          const int y0 = std::max(r.y0, row0), y1 = std::min(r.y1, row1 - 1);
          for (int y = y0; y <= y1; ++y) {
            for (int x = r.x0; x <= r.x1; ++x) {
              const int cls = r.edges.classify(x, y);
              if (cls < 0) continue;
              std::uint16_t bits = 0xFFFF;
              if (cls == 0) {
                bits = 0;
                for (int k = 0; k < kSamplesPerSide * kSamplesPerSide; ++k) {
                  if (r.edges.contains_once(x + (k % kSamplesPerSide + 0.5) / kSamplesPerSide,
                                            y + (k / kSamplesPerSide + 0.5) / kSamplesPerSide))
                    bits |= std::uint16_t(1u << k);
                }
              }
              parity[std::size_t(y - row0) * w + x] ^= bits;
            }
          }
        }
        for (std::size_t i = 0; i < masks.size(); ++i) masks[i] |= parity[i];
      }
      for (int y = row0; y < row1; ++y)
        for (int x = 0; x < w; ++x)
          coverage[std::size_t(y) * w + x] =
              float(std::popcount(masks[std::size_t(y - row0) * w + x])) / 16.0f;
    }
  });
  return coverage;
}

}  // namespace sb
