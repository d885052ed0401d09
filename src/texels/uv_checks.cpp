// Lightmap UV layout checks (uv_checks.h).
//
// Charts: union-find over triangles, joined where two share an edge whose UVs are bitwise the
// same at both ends (the mesh's vertices may be split on other channels' seams, so vertex
// identity would cut a lightmap chart in two). Nearness to another chart: each texel holds its
// chart's label; the smallest and largest label within ±margin texels (a separable sliding
// min/max, rows then columns) differ from the texel's own exactly when another chart's texel lies
// in that square.
#include "texels/uv_checks.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>
#include <utility>

namespace sb {

namespace {

// Area of the part of triangle (a, b, c) inside the unit square: Sutherland–Hodgman against its
// four sides, then the shoelace formula.
double area_inside_unit_square(const Vec2& a, const Vec2& b, const Vec2& c) {
  std::vector<Vec2> poly = {a, b, c}, next;
  const auto clip = [&](int axis, double limit, double sign) {
    next.clear();
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const Vec2& p = poly[i];
      const Vec2& q = poly[(i + 1) % poly.size()];
      const double dp = sign * (p[axis] - limit), dq = sign * (q[axis] - limit);
      if (dp >= 0) next.push_back(p);
      if ((dp >= 0) != (dq >= 0)) next.push_back(p + (q - p) * (dp / (dp - dq)));
    }
    poly.swap(next);
  };
  clip(0, 0.0, +1);
  clip(0, 1.0, -1);
  clip(1, 0.0, +1);
  clip(1, 1.0, -1);
  double twice = 0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2& p = poly[i];
    const Vec2& q = poly[(i + 1) % poly.size()];
    twice += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * std::abs(twice);
}

int find(std::vector<int>& parent, int i) {
  while (parent[std::size_t(i)] != i)
    i = parent[std::size_t(i)] = parent[std::size_t(parent[std::size_t(i)])];
  return i;
}

// Sliding minimum and maximum over ±radius along one axis of a width × height label image.
void sliding_min_max(std::vector<int>& lo, std::vector<int>& hi, int width, int height, int radius,
                     bool along_rows) {
  const int lines = along_rows ? height : width, length = along_rows ? width : height;
  std::vector<int> line_lo(static_cast<std::size_t>(length)),
      line_hi(static_cast<std::size_t>(length));
  for (int l = 0; l < lines; ++l) {
    const auto at = [&](int k) {
      return along_rows ? std::size_t(l) * std::size_t(width) + std::size_t(k)
                        : std::size_t(k) * std::size_t(width) + std::size_t(l);
    };
    for (int k = 0; k < length; ++k) {
      int a = std::numeric_limits<int>::max(), b = std::numeric_limits<int>::min();
      for (int j = std::max(0, k - radius); j <= std::min(length - 1, k + radius); ++j) {
        a = std::min(a, lo[at(j)]);
        b = std::max(b, hi[at(j)]);
      }
      line_lo[std::size_t(k)] = a;
      line_hi[std::size_t(k)] = b;
    }
    for (int k = 0; k < length; ++k) {
      lo[at(k)] = line_lo[std::size_t(k)];
      hi[at(k)] = line_hi[std::size_t(k)];
    }
  }
}

}  // namespace

UvQuality uv_quality(const Mesh& mesh) {
  UvQuality q;
  if (!mesh.has_uv) return q;
  // Per triangle: surface area, UV area, and Sander et al.'s (2001) L2 stretch² of the map from
  // UV to surface, (|∂p/∂s|² + |∂p/∂t|²) / 2.
  struct Sample {
    double surface, uv, stretch2;
  };
  std::vector<Sample> samples;
  double surface = 0, uv = 0;
  for (const auto f : mesh.mesh.faces()) {
    const Triangle t = triangle(mesh.mesh, f);
    const double a = 0.5 * ((t.uv[1] - t.uv[0]).x() * (t.uv[2] - t.uv[0]).y() -
                            (t.uv[1] - t.uv[0]).y() * (t.uv[2] - t.uv[0]).x());
    const double area = 0.5 * (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).norm();
    if (!(std::abs(a) > 0) || !(area > 0)) continue;
    const Vec3 ds = (t.p[0] * (t.uv[1].y() - t.uv[2].y()) + t.p[1] * (t.uv[2].y() - t.uv[0].y()) +
                     t.p[2] * (t.uv[0].y() - t.uv[1].y())) /
                    (2 * a);
    const Vec3 dt = (t.p[0] * (t.uv[2].x() - t.uv[1].x()) + t.p[1] * (t.uv[0].x() - t.uv[2].x()) +
                     t.p[2] * (t.uv[1].x() - t.uv[0].x())) /
                    (2 * a);
    samples.push_back({area, std::abs(a), 0.5 * (ds.squaredNorm() + dt.squaredNorm())});
    surface += area;
    uv += std::abs(a);
  }
  if (samples.empty()) return q;
  // Stretch: √(Σ A·L2² / Σ A), times √(UV area / surface area) so that a uniform scale is 1.
  double sum = 0;
  for (const Sample& s : samples) sum += s.surface * s.stretch2;
  q.stretch = std::sqrt(sum / surface) * std::sqrt(uv / surface);
  // Density: texels per metre ∝ √(UV area / surface area), percentiles by surface area.
  std::sort(samples.begin(), samples.end(),
            [](const Sample& a, const Sample& b) { return a.uv * b.surface < b.uv * a.surface; });
  auto density_at = [&](double fraction) {
    double below = 0;
    for (const Sample& s : samples) {
      below += s.surface;
      if (below >= fraction * surface) return std::sqrt(s.uv / s.surface);
    }
    return std::sqrt(samples.back().uv / samples.back().surface);
  };
  q.density_spread = density_at(0.95) / density_at(0.05);
  return q;
}

UvLayoutReport check_uv_layout(const Mesh& mesh, const TexelSpace& space, int margin) {
  UvLayoutReport report;
  report.overlapping_texels = space.overlapping_texels;
  report.margin = margin;
  report.generated = mesh.uv_generated;
  if (!mesh.has_uv) return report;
  const UvQuality quality = uv_quality(mesh);
  report.stretch = quality.stretch;
  report.density_spread = quality.density_spread;
  const TriMesh& m = mesh.mesh;
  const int faces = int(m.n_faces());

  // Charts by shared UV edges.
  std::vector<int> parent(static_cast<std::size_t>(faces));
  std::iota(parent.begin(), parent.end(), 0);
  using UvKey = std::pair<std::uint64_t, std::uint64_t>;  // one UV, bitwise
  const auto key_of = [](const Vec2& uv) {
    std::uint64_t u, v;
    std::memcpy(&u, &uv.x(), 8);
    std::memcpy(&v, &uv.y(), 8);
    return UvKey(u, v);
  };
  std::map<std::pair<UvKey, UvKey>, int> edge_owner;
  for (const auto f : m.faces()) {
    const Triangle t = triangle(m, f);
    const Vec2 ab = t.uv[1] - t.uv[0], ac = t.uv[2] - t.uv[0];
    const double area = 0.5 * std::abs(ab.x() * ac.y() - ab.y() * ac.x());
    report.uv_area += area;
    report.uv_area_outside += area - area_inside_unit_square(t.uv[0], t.uv[1], t.uv[2]);
    for (int e = 0; e < 3; ++e) {
      UvKey a = key_of(t.uv[e]), b = key_of(t.uv[(e + 1) % 3]);
      if (b < a) std::swap(a, b);
      const auto [it, inserted] = edge_owner.emplace(std::make_pair(a, b), f.idx());
      if (!inserted) parent[std::size_t(find(parent, f.idx()))] = find(parent, it->second);
    }
  }
  report.uv_area_outside = std::max(0.0, report.uv_area_outside);
  std::vector<int> chart(std::size_t(faces), -1);
  for (int f = 0; f < faces; ++f) {
    const int root = find(parent, f);
    if (chart[std::size_t(root)] < 0) chart[std::size_t(root)] = report.charts++;
    chart[std::size_t(f)] = chart[std::size_t(root)];
  }

  // Texels near another chart.
  if (margin <= 0 || report.charts < 2 || space.texels.empty()) return report;
  const int w = space.width, h = space.height;
  std::vector<int> lo(std::size_t(w) * std::size_t(h), std::numeric_limits<int>::max());
  std::vector<int> hi(lo.size(), std::numeric_limits<int>::min());
  for (const Texel& t : space.texels) {
    const std::size_t i = std::size_t(t.y) * std::size_t(w) + std::size_t(t.x);
    lo[i] = hi[i] = chart[std::size_t(t.face)];
  }
  sliding_min_max(lo, hi, w, h, margin, true);
  sliding_min_max(lo, hi, w, h, margin, false);
  for (const Texel& t : space.texels) {
    const std::size_t i = std::size_t(t.y) * std::size_t(w) + std::size_t(t.x);
    const int own = chart[std::size_t(t.face)];
    report.texels_near_other_charts += lo[i] < own || hi[i] > own;
  }
  return report;
}

std::vector<std::string> uv_layout_warnings(const UvLayoutReport& r) {
  std::vector<std::string> out;
  if (r.uv_area > 0 && r.uv_area_outside > 1e-6 * r.uv_area) {
    out.push_back(fmt::format(
        "{:.1f}% of its lightmap UV area lies outside [0, 1] and gets no texels; repack the "
        "lightmap UVs into the unit square",
        100.0 * r.uv_area_outside / r.uv_area));
  }
  if (r.overlapping_texels > 0) {
    out.push_back(fmt::format(
        "{} lightmap texel(s) are claimed by two UV triangles (overlapping charts), so each shows "
        "one of two surface points; give the lightmap UV set non-overlapping charts",
        r.overlapping_texels));
  }
  if (r.texels_near_other_charts > 0) {
    out.push_back(fmt::format(
        "{} texel(s) lie within the margin ({} texels) of another UV chart, where filtering and "
        "dilation mix the two; pack the charts further apart or lower 'margin'",
        r.texels_near_other_charts, r.margin));
  }
  return out;
}

}  // namespace sb
