// Shadow maps (Williams, "Casting curved shadows on curved surfaces", SIGGRAPH 1978, as used by
// every filtering method of docs/design.md's sources: Reeves et al.'s PCF in [S2], Uralsky's
// adaptive PCF in [S3], Fernando's PCSS as summarised in [S4], Chun & Oh in [S5]): a depth image of
// the blockers rendered from the light's centre, against which a receiver point's depth is
// compared.
//
// The z-buffer is written here by hand: the project's libraries trace rays (Embree) or rasterise
// coverage in UV space (uv_rasterizer.cpp), and none on the CPU rasterises triangles into a
// float depth buffer without a GPU context. Depth is the distance along the frustum's axis, not
// a normalised z, so the filters can read blocker and receiver depths in metres (PCSS's
// parallel-planes estimate needs them) and a bias is a length.
#include "methods/shadow_map.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "occluders/depth_clipping.h"
#include "occluders/light_frusta.h"
#include "occluders/tangent_bounds.h"

namespace sb {

namespace {

// A triangle in pixel coordinates, ready to scan: three edge functions that are >= 0 inside,
// and 1/depth as an affine function of the pixel (exact for a perspective projection).
struct ScreenTriangle {
  std::array<Vec3, 3> edges;  // (A, B, C): inside where A·x + B·y + C >= 0
  Vec3 inverse_depth;         // (a, b, c): 1/depth = a·x + b·y + c
  int x0, x1, y0, y1;         // pixel bounding box, clamped to the map
};

bool make_screen_triangle(const std::array<Vec2, 3>& p, const std::array<double, 3>& w, int size,
                          ScreenTriangle& t) {
  const double area2 =
      (p[1].x() - p[0].x()) * (p[2].y() - p[0].y()) - (p[2].x() - p[0].x()) * (p[1].y() - p[0].y());
  if (!(std::abs(area2) > 1e-12)) return false;  // seen edge-on (or not finite)
  const double sign = area2 > 0 ? 1.0 : -1.0;
  for (int i = 0; i < 3; ++i) {
    const Vec2& a = p[i];
    const Vec2& b = p[(i + 1) % 3];
    const double A = -(b.y() - a.y()), B = b.x() - a.x();
    t.edges[i] = sign * Vec3(A, B, -A * a.x() - B * a.y());
  }
  const double ia =
      ((w[1] - w[0]) * (p[2].y() - p[0].y()) - (w[2] - w[0]) * (p[1].y() - p[0].y())) / area2;
  const double ib =
      ((w[2] - w[0]) * (p[1].x() - p[0].x()) - (w[1] - w[0]) * (p[2].x() - p[0].x())) / area2;
  t.inverse_depth = Vec3(ia, ib, w[0] - ia * p[0].x() - ib * p[0].y());
  double lo_x = p[0].x(), hi_x = lo_x, lo_y = p[0].y(), hi_y = lo_y;
  for (int i = 1; i < 3; ++i) {
    lo_x = std::min(lo_x, p[i].x()), hi_x = std::max(hi_x, p[i].x());
    lo_y = std::min(lo_y, p[i].y()), hi_y = std::max(hi_y, p[i].y());
  }
  // Pixel centres are at integers: the covered centres lie in [ceil(lo), floor(hi)].
  t.x0 = int(std::max(0.0, std::ceil(lo_x)));
  t.x1 = int(std::min(double(size - 1), std::floor(hi_x)));
  t.y0 = int(std::max(0.0, std::ceil(lo_y)));
  t.y1 = int(std::min(double(size - 1), std::floor(hi_y)));
  return t.x0 <= t.x1 && t.y0 <= t.y1;
}

// Scans one row of a triangle into the depth image: the span of x where all three edge
// functions are >= 0 (each is linear in x along the row), then one division per pixel.
void scan_row(const ScreenTriangle& t, int y, int size, float* row) {
  double lo = t.x0, hi = t.x1;
  for (const Vec3& e : t.edges) {
    const double rest = e.y() * y + e.z();  // A·x + rest >= 0
    if (e.x() > 0) {
      lo = std::max(lo, -rest / e.x());
    } else if (e.x() < 0) {
      hi = std::min(hi, -rest / e.x());
    } else if (rest < 0) {
      return;
    }
  }
  const int x_begin = std::max(t.x0, int(std::ceil(lo)));
  const int x_end = std::min({t.x1, size - 1, int(std::floor(hi))});
  for (int x = x_begin; x <= x_end; ++x) {
    const double inverse = t.inverse_depth.x() * x + t.inverse_depth.y() * y + t.inverse_depth.z();
    if (!(inverse > 0)) continue;
    const float depth = float(1.0 / inverse);
    if (depth < row[x]) row[x] = depth;
  }
}

constexpr int kBandRows = 16;  // rows per parallel task; each task owns its rows outright

// The depth bias beyond the receiver's own plane, in shadow-map pixels' world footprints at the
// receiver's depth (shadow_map.h says why one is enough).
constexpr double kBiasPixels = 1.0;

}  // namespace

ShadowMap render_shadow_map(const std::vector<const Mesh*>& blockers, const ProjectionFrame& frame,
                            double half_extent, int size, double near) {
  ShadowMap map;
  map.frame = frame;
  map.half_extent = half_extent;
  map.size = size;
  map.pixel = 2 * half_extent / size;
  map.near = near;
  map.depth.assign(std::size_t(size) * size, std::numeric_limits<float>::infinity());

  std::vector<ScreenTriangle> triangles;
  for (const Mesh* m : blockers) {
    for (auto f : m->mesh.faces()) {
      std::vector<Vec3> poly;
      for (auto v : m->mesh.fv_range(f)) {
        const auto& p = m->mesh.point(v);
        poly.emplace_back(p[0], p[1], p[2]);
      }
      poly = clip_to_depth(poly, frame, near, KeepDepth::at_least);
      if (poly.size() < 3) continue;
      std::vector<Vec2> pixels(poly.size());
      std::vector<double> inverse(poly.size());
      for (std::size_t i = 0; i < poly.size(); ++i) {
        pixels[i] = map.to_pixel(frame.tangent(poly[i]));
        inverse[i] = 1.0 / frame.depth(poly[i]);
      }
      for (std::size_t i = 1; i + 1 < poly.size(); ++i) {  // a fan: the clipped polygon is convex
        ScreenTriangle t;
        if (make_screen_triangle({pixels[0], pixels[i], pixels[i + 1]},
                                 {inverse[0], inverse[i], inverse[i + 1]}, size, t)) {
          triangles.push_back(t);
        }
      }
    }
  }

  const int bands = (size + kBandRows - 1) / kBandRows;
  std::vector<std::vector<std::uint32_t>> binned(bands);
  for (std::size_t i = 0; i < triangles.size(); ++i)
    for (int b = triangles[i].y0 / kBandRows; b <= triangles[i].y1 / kBandRows; ++b)
      binned[b].push_back(std::uint32_t(i));
  tbb::parallel_for(tbb::blocked_range<int>(0, bands), [&](const tbb::blocked_range<int>& r) {
    for (int b = r.begin(); b != r.end(); ++b) {
      const int row0 = b * kBandRows, row1 = std::min(size, row0 + kBandRows);
      for (std::uint32_t i : binned[b]) {
        const ScreenTriangle& t = triangles[i];
        for (int y = std::max(row0, t.y0); y <= std::min(row1 - 1, t.y1); ++y)
          scan_row(t, y, size, &map.depth[std::size_t(y) * size]);
      }
    }
  });
  for (float d : map.depth) map.nearest = std::min(map.nearest, double(d));
  return map;
}

std::vector<ShadowFrustum> fit_frusta(const Vec3& centre, const std::vector<Vec3>& points,
                                      double margin) {
  std::vector<ShadowFrustum> frusta;
  if (points.empty()) return frusta;
  if (const std::optional<ProjectionFrame> central = central_frustum(centre, points)) {
    frusta.push_back({*central, 1.0, 0.0, {}, ""});
    frusta[0].points.resize(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) frusta[0].points[i] = i;
  } else {
    std::array<std::vector<std::size_t>, kCubeFaces> faces;
    for (std::size_t i = 0; i < points.size(); ++i)
      faces[cube_face(centre, points[i])].push_back(i);
    for (int f = 0; f < kCubeFaces; ++f) {
      if (faces[f].empty()) continue;
      frusta.push_back(
          {cube_face_frame(centre, f), 1.0, 0.0, std::move(faces[f]), cube_face_name(f)});
    }
  }
  for (ShadowFrustum& f : frusta) {
    TangentBounds tangents;
    double closest = std::numeric_limits<double>::infinity();
    for (std::size_t i : f.points) {
      const double depth = f.frame.depth(points[i]);
      if (depth <= 0) continue;  // at the light's centre: the caller leaves it unshadowed
      closest = std::min(closest, depth);
      tangents.extend(f.frame.tangent(points[i]));
    }
    f.half_extent = std::max(tangents.widest() * (1 + margin), 1e-6);
    // Blocker parts nearer than this are clipped: projecting a point at depth ≈ 0 would throw
    // it to infinity. A thousandth of the nearest receiver point's depth, as the convolution.
    f.near = std::isfinite(closest) ? std::max(1e-3 * closest, 1e-9) : 1e-9;
  }
  return frusta;
}

ReceiverPoint receiver_point(const ShadowMap& map, const Vec3& position, const Vec3& normal) {
  ReceiverPoint r;
  const ProjectionFrame& f = map.frame;
  r.depth = f.depth(position);
  r.tangent = f.tangent(position);
  r.at = map.to_pixel(r.tangent);
  // Plus the stored depth's own rounding: a float holds depth to 6e-8 of it, which for a light
  // far away (a sun, 10⁴ m off) is more than a pixel's footprint and would shadow every lit
  // surface by itself.
  r.bias = kBiasPixels * map.pixel * r.depth +
           4 * double(std::numeric_limits<float>::epsilon()) * r.depth;
  // The ray through pixel (x, y) runs along D + t1·e1 + t2·e2 with t = (x + 0.5)·pixel − h; it
  // meets the plane n·(p − position) = 0 at depth n·(position − o) / n·(D + t1·e1 + t2·e2).
  const double ne1 = normal.dot(f.e1), ne2 = normal.dot(f.e2);
  const double start = 0.5 * map.pixel - map.half_extent;
  r.plane_c = normal.dot(position - f.origin);
  r.plane_a = normal.dot(f.axis) + (ne1 + ne2) * start;
  r.plane_bx = ne1 * map.pixel;
  r.plane_by = ne2 * map.pixel;
  return r;
}

double lit_fraction(const ShadowMap& map, const ReceiverPoint& r, const Vec2& at) {
  // Wholly outside the map (or not finite): nothing known there, and no int overflow below.
  if (!(at.x() > -1 && at.y() > -1 && at.x() < map.size && at.y() < map.size)) return 1.0;
  const double fx = std::floor(at.x()), fy = std::floor(at.y());
  const int x0 = int(fx), y0 = int(fy);
  const double tx = at.x() - fx, ty = at.y() - fy;
  const auto lit = [&](int x, int y) { return blocked(map, r, x, y, nullptr) ? 0.0 : 1.0; };
  return (1 - ty) * ((1 - tx) * lit(x0, y0) + tx * lit(x0 + 1, y0)) +
         ty * ((1 - tx) * lit(x0, y0 + 1) + tx * lit(x0 + 1, y0 + 1));
}

}  // namespace sb
