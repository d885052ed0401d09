// Generated lightmap UVs (auto_uv.h): charts, their flattening, their packing, and the mesh
// rebuilt with its vertices split along the charts' borders. Whether a flattened chart folds
// over itself is found by chart_folds.h.
//
// Written here rather than taken from a library: Debian 12 packages no lightmap UV generator
// (xatlas and UVAtlas are not packaged); the pieces that are libraries are used as such, CGAL's
// LSCM for curved charts (chart_lscm.h) and stb_rect_pack for the packing (atlas_packing.h).
#include "texels/auto_uv.h"

#include <Eigen/Eigenvalues>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <queue>
#include <utility>
#include <vector>

#include "texels/atlas_packing.h"
#include "texels/chart_folds.h"
#include "texels/chart_lscm.h"
#include "texels/lightmap_sizes.h"
#include "texels/seams.h"

namespace sb {

namespace {

double cos_deg(double degrees) { return std::cos(degrees * std::numbers::pi / 180.0); }

// The cone of normals (about the chart's mean) a chart grows within. 60° makes a 32-segment
// cylinder's side four charts; wider cones (90° measured) give fewer charts on bumpy meshes but a
// wider texel density spread, and need the bisection below more often.
constexpr double kConeDegrees = 60.0;
// Charts whose normals all lie within this of their mean are projected on its plane: exact for
// flat ones, and LSCM would only add rounding.
constexpr double kFlatDegrees = 0.5;
// A flattened chart whose triangle has UV area more than this times (or less than this fraction
// of) its surface area, once the chart is scaled to its surface, is cut again: texel density
// across it would vary more than √2 along a side.
constexpr double kMaxAreaSpread = 2.0;

struct Face {
  std::array<TriMesh::VertexHandle, 3> vertex;
  std::array<Vec3, 3> p;
  Vec3 normal = Vec3::Zero();  // unit, from the winding
  double area = 0;
};

// The surface as charting sees it: faces and, per face edge k (from corner k to k + 1), the face
// across it where the two meet in space along a smooth edge with the same orientation, else −1.
struct Surface {
  std::vector<Face> faces;
  std::vector<std::array<int, 3>> across;
};

Surface surface_of(const TriMesh& mesh) {
  Surface s;
  for (auto f : mesh.faces()) {
    Face face;
    int k = 0;
    for (auto v : mesh.fv_range(f)) {
      face.vertex[std::size_t(k)] = v;
      const auto& p = mesh.point(v);
      face.p[std::size_t(k++)] = Vec3(p[0], p[1], p[2]);
    }
    const Vec3 cross = (face.p[1] - face.p[0]).cross(face.p[2] - face.p[0]);
    face.area = 0.5 * cross.norm();
    face.normal = face.area > 0 ? Vec3(cross.normalized()) : Vec3(0, 0, 1);
    s.faces.push_back(face);
  }
  // Directed edges by their end points' bits; an edge joins two faces when exactly one face
  // runs it each way and the vertex normals agree at both ends.
  std::map<std::array<std::uint64_t, 6>, std::vector<std::pair<int, int>>> directed;
  auto key = [](const Vec3& a, const Vec3& b) {
    const PositionBits x = position_bits(a), y = position_bits(b);
    return std::array<std::uint64_t, 6>{x[0], x[1], x[2], y[0], y[1], y[2]};
  };
  for (std::size_t f = 0; f < s.faces.size(); ++f)
    for (int k = 0; k < 3; ++k)
      directed[key(s.faces[f].p[std::size_t(k)], s.faces[f].p[std::size_t((k + 1) % 3)])].push_back(
          {int(f), k});
  const double smooth = cos_deg(kSmoothEdgeDegrees);
  auto normal = [&](TriMesh::VertexHandle v) {
    const auto& n = mesh.normal(v);
    return Vec3(n[0], n[1], n[2]);
  };
  s.across.assign(s.faces.size(), {-1, -1, -1});
  for (std::size_t f = 0; f < s.faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int k1 = (k + 1) % 3;
      const auto& forward =
          directed[key(s.faces[f].p[std::size_t(k)], s.faces[f].p[std::size_t(k1)])];
      const auto back =
          directed.find(key(s.faces[f].p[std::size_t(k1)], s.faces[f].p[std::size_t(k)]));
      if (forward.size() != 1 || back == directed.end() || back->second.size() != 1) continue;
      const auto [g, j] = back->second.front();
      const Face& a = s.faces[f];
      const Face& b = s.faces[std::size_t(g)];
      // b's edge j runs from a's corner k1 to a's corner k.
      const bool smooth_edge =
          normal(a.vertex[std::size_t(k)]).dot(normal(b.vertex[std::size_t((j + 1) % 3)])) >=
              smooth &&
          normal(a.vertex[std::size_t(k1)]).dot(normal(b.vertex[std::size_t(j)])) >= smooth;
      if (smooth_edge && g != int(f)) s.across[f][std::size_t(k)] = g;
    }
  }
  return s;
}

// Charts grown over `faces` (a subset of the surface): from the largest face not yet taken (ties:
// the lowest index), across joined edges, the face nearest the chart's mean normal first, while
// it lies within `cone_deg` of that mean.
std::vector<std::vector<int>> grow_charts(const Surface& s, const std::vector<int>& faces,
                                          double cone_deg) {
  std::vector<char> open(s.faces.size(), 0);  // in `faces` and not yet in a chart
  for (const int f : faces) open[std::size_t(f)] = 1;
  std::vector<int> seeds = faces;
  std::stable_sort(seeds.begin(), seeds.end(), [&](int a, int b) {
    return s.faces[std::size_t(a)].area > s.faces[std::size_t(b)].area;
  });
  const double cone = cos_deg(cone_deg);
  std::vector<std::vector<int>> charts;
  for (const int seed : seeds) {
    if (!open[std::size_t(seed)]) continue;
    std::vector<int> chart;
    Vec3 sum = Vec3::Zero();
    // Candidates by how close their normal is to the mean when they were found (then by index).
    std::priority_queue<std::pair<double, int>> candidates;
    auto take = [&](int f) {
      open[std::size_t(f)] = 0;
      chart.push_back(f);
      sum += s.faces[std::size_t(f)].normal * s.faces[std::size_t(f)].area;
      const Vec3 mean = sum.normalized();
      for (const int g : s.across[std::size_t(f)])
        if (g >= 0 && open[std::size_t(g)])
          candidates.push({s.faces[std::size_t(g)].normal.dot(mean), -g});
    };
    take(seed);
    while (!candidates.empty()) {
      const int f = -candidates.top().second;
      candidates.pop();
      if (!open[std::size_t(f)]) continue;
      if (s.faces[std::size_t(f)].normal.dot(sum.normalized()) >= cone) take(f);
    }
    charts.push_back(std::move(chart));
  }
  return charts;
}

double signed_area(const std::array<Vec2, 3>& t) {
  const Vec2 a = t[1] - t[0], b = t[2] - t[0];
  return 0.5 * (a.x() * b.y() - a.y() * b.x());
}

// Where two triangles of a flattened chart overlap with positive area in UV
// (overlapping_triangles, chart_folds.h): the triangles' centres in space.
std::optional<ChartFold> triangles_overlap(const ChartUvs& uv, const Surface& s,
                                           const std::vector<int>& chart) {
  const auto overlapping = overlapping_triangles(uv);
  if (!overlapping) return std::nullopt;
  const Face& fa = s.faces[std::size_t(chart[(*overlapping)[0]])];
  const Face& ft = s.faces[std::size_t(chart[(*overlapping)[1]])];
  return ChartFold{(fa.p[0] + fa.p[1] + fa.p[2]) / 3.0, (ft.p[0] + ft.p[1] + ft.p[2]) / 3.0};
}

// The chart flattened, scaled so its UV area equals its surface area; nothing when it cannot be
// (not a disc, folded, or its triangles' areas spread beyond kMaxAreaSpread); `fold` then says
// where it folded, if that was why.
std::optional<ChartUvs> flatten(const Surface& s, const std::vector<int>& chart, bool* conformal,
                                std::optional<ChartFold>* fold) {
  // Local vertices: one per position (texture-UV seams inside a chart are one vertex here).
  std::map<PositionBits, int> index;
  std::vector<Vec3> positions;
  std::vector<std::array<int, 3>> triangles;
  Vec3 sum = Vec3::Zero();
  double world_area = 0;
  for (const int f : chart) {
    const Face& face = s.faces[std::size_t(f)];
    std::array<int, 3> t{};
    for (std::size_t k = 0; k < 3; ++k) {
      const auto [it, added] = index.try_emplace(position_bits(face.p[k]), int(positions.size()));
      if (added) positions.push_back(face.p[k]);
      t[k] = it->second;
    }
    triangles.push_back(t);
    sum += face.normal * face.area;
    world_area += face.area;
  }
  const Vec3 mean = sum.norm() > 0 ? Vec3(sum.normalized()) : Vec3(0, 0, 1);
  double widest = 1;
  for (const int f : chart) widest = std::min(widest, s.faces[std::size_t(f)].normal.dot(mean));

  std::vector<Vec2> uv;
  *conformal = widest < cos_deg(kFlatDegrees);
  if (*conformal) {
    auto unwrapped = lscm_unwrap(positions, triangles);
    if (!unwrapped) return std::nullopt;
    uv = std::move(*unwrapped);
  } else {
    // On the chart's plane, in a basis of its mean normal (Duff et al.'s orthonormal basis).
    const double sign = std::copysign(1.0, mean.z());
    const double a = -1.0 / (sign + mean.z()), b = mean.x() * mean.y() * a;
    const Vec3 t(1.0 + sign * mean.x() * mean.x() * a, sign * b, -sign * mean.x());
    const Vec3 bt(b, sign + mean.y() * mean.y() * a, -mean.y());
    for (const Vec3& p : positions) uv.emplace_back(p.dot(t), p.dot(bt));
  }
  const auto corners = [&](const std::array<int, 3>& t) {
    return std::array<Vec2, 3>{uv[std::size_t(t[0])], uv[std::size_t(t[1])], uv[std::size_t(t[2])]};
  };
  double uv_area = 0;
  for (const auto& t : triangles) uv_area += signed_area(corners(t));
  if (uv_area < 0) {  // a mirrored flattening: turn it over
    for (Vec2& p : uv) p.x() = -p.x();
    uv_area = -uv_area;
  }
  if (!(uv_area > 0)) return std::nullopt;
  const double scale = std::sqrt(world_area / uv_area);
  for (Vec2& p : uv) p *= scale;
  ChartUvs out;
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    out.push_back(corners(triangles[i]));
    const double area = signed_area(out[i]), surface = s.faces[std::size_t(chart[i])].area;
    if (!(area > 0)) return std::nullopt;  // flipped: the chart folds
    if (area > kMaxAreaSpread * surface || area * kMaxAreaSpread < surface) return std::nullopt;
  }
  // Border edges: local edges that one triangle of the chart uses.
  std::map<std::array<int, 2>, int> uses;
  for (const auto& t : triangles)
    for (std::size_t k = 0; k < 3; ++k)
      ++uses[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}];
  std::vector<std::array<int, 2>> border;
  for (const auto& [edge, count] : uses)
    if (count == 1) border.push_back(edge);
  if ((*fold = border_crosses(uv, positions, border))) return std::nullopt;
  if ((*fold = triangles_overlap(out, s, chart))) return std::nullopt;
  return out;
}

struct Chart {
  std::vector<int> faces;
  ChartUvs uv;  // metres, turned to its smallest bounding rectangle, lowest corner at 0
  Vec2 size = Vec2::Zero();
  bool conformal = false;
};

// Turns a chart to its smallest-area bounding rectangle (an edge of its convex hull lies along
// one side of that rectangle) and moves its lowest corner to the origin.
void fit_rectangle(Chart& chart) {
  std::vector<Vec2> points;
  for (const auto& t : chart.uv) points.insert(points.end(), t.begin(), t.end());
  std::sort(points.begin(), points.end(), [](const Vec2& a, const Vec2& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  // Andrew's monotone chain.
  std::vector<Vec2> hull(2 * points.size());
  std::size_t k = 0;
  auto cross = [](const Vec2& o, const Vec2& a, const Vec2& b) {
    return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
  };
  for (std::size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], points[i - 1]) <= 0) --k;
    hull[k++] = points[i - 1];
  }
  hull.resize(k > 1 ? k - 1 : k);
  Vec2 best_axis(1, 0);
  double best_area = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Vec2 edge = hull[(i + 1) % hull.size()] - hull[i];
    if (edge.norm() <= 0) continue;
    const Vec2 u = edge.normalized(), v(-u.y(), u.x());
    double u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
    for (const Vec2& p : hull) {
      u0 = std::min(u0, p.dot(u)), u1 = std::max(u1, p.dot(u));
      v0 = std::min(v0, p.dot(v)), v1 = std::max(v1, p.dot(v));
    }
    if ((u1 - u0) * (v1 - v0) < best_area) best_area = (u1 - u0) * (v1 - v0), best_axis = u;
  }
  const Vec2 u = best_axis, v(-u.y(), u.x());
  Vec2 lo(INFINITY, INFINITY), hi(-INFINITY, -INFINITY);
  for (auto& t : chart.uv) {
    for (Vec2& p : t) {
      p = Vec2(p.dot(u), p.dot(v));
      lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    }
  }
  for (auto& t : chart.uv)
    for (Vec2& p : t) p -= lo;
  chart.size = hi - lo;
}

// The pieces of `chart` on the two sides of a plane, each split into its connected parts: the plane
// halfway between the two lips of a fold, across the line joining them (a pinch in the surface,
// such as a tufted cushion's, unfolds only once cut between its lips), or else the plane through
// the chart's centroid across its longest axis (halves of an annulus are discs, halves of a cap
// that spreads too much spread less).
std::vector<std::vector<int>> bisect(const Surface& s, const std::vector<int>& chart,
                                     const std::optional<ChartFold>& fold) {
  std::vector<Vec3> centre;
  Vec3 mean = Vec3::Zero();
  double area = 0;
  for (const int f : chart) {
    const Face& face = s.faces[std::size_t(f)];
    centre.push_back((face.p[0] + face.p[1] + face.p[2]) / 3.0);
    mean += centre.back() * face.area;
    area += face.area;
  }
  mean /= area;
  Vec3 axis;
  if (fold && (fold->b - fold->a).norm() > 0) {
    axis = (fold->b - fold->a).normalized();
    mean = (fold->a + fold->b) / 2;
  } else {
    Mat3 covariance = Mat3::Zero();
    for (std::size_t i = 0; i < chart.size(); ++i)
      covariance +=
          s.faces[std::size_t(chart[i])].area * (centre[i] - mean) * (centre[i] - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Mat3> solver(covariance);
    axis = solver.eigenvectors().col(2);  // the largest eigenvalue's
  }
  std::vector<char> side(s.faces.size(), -1);  // −1: not in the chart
  std::size_t below = 0;
  for (std::size_t i = 0; i < chart.size(); ++i) {
    side[std::size_t(chart[i])] = (centre[i] - mean).dot(axis) < 0;
    below += (centre[i] - mean).dot(axis) < 0;
  }
  if (below == 0 || below == chart.size()) {  // every centre on one side: halve the list
    for (std::size_t i = 0; i < chart.size(); ++i)
      side[std::size_t(chart[i])] = 2 * i < chart.size();
  }
  std::vector<std::vector<int>> pieces;
  std::vector<char> seen(s.faces.size(), 0);
  for (const int seed : chart) {
    if (seen[std::size_t(seed)]) continue;
    std::vector<int> piece = {seed};
    seen[std::size_t(seed)] = 1;
    for (std::size_t i = 0; i < piece.size(); ++i)
      for (const int g : s.across[std::size_t(piece[i])])
        if (g >= 0 && !seen[std::size_t(g)] && side[std::size_t(g)] == side[std::size_t(seed)])
          seen[std::size_t(g)] = 1, piece.push_back(g);
    pieces.push_back(std::move(piece));
  }
  return pieces;
}

// `faces` flattened as one chart, or else bisected and each piece placed the same way.
void place_chart(const Surface& s, std::vector<int> faces, std::vector<Chart>& out) {
  Chart chart;
  chart.faces = std::move(faces);
  std::optional<ChartFold> fold;
  if (auto uv = flatten(s, chart.faces, &chart.conformal, &fold)) {
    chart.uv = std::move(*uv);
    out.push_back(std::move(chart));
    return;
  }
  for (std::vector<int>& piece : bisect(s, chart.faces, fold))
    place_chart(s, std::move(piece), out);
}

// The texel rectangle a chart takes at `scale` texels per metre: the texels it touches when
// placed half a texel in (its size plus one, rounded up), then the margin.
std::array<int, 2> texel_rectangle(const Chart& c, double scale, int margin) {
  return {int(std::ceil(c.size.x() * scale)) + 1 + margin,
          int(std::ceil(c.size.y() * scale)) + 1 + margin};
}

RectanglePacking pack(const std::vector<Chart>& charts, double scale, int margin, int side) {
  std::vector<std::array<int, 2>> sizes;
  for (const Chart& c : charts) sizes.push_back(texel_rectangle(c, scale, margin));
  return pack_rectangles(sizes, side, side);
}

// The largest density (texels per metre) at which the charts fit side², to a part in 10⁴;
// nothing when they do not fit even as points with their margins. A chart at any density above
// 0 takes at least its texel and the one it is placed half a texel into (texel_rectangle), one
// more per side than at 0, so the points are tested at the least density above 0: tested at 0,
// charts that fit only there sent the search below every density, halving towards 0 for ever.
std::optional<double> fill_side(const std::vector<Chart>& charts, int margin, int side) {
  const double least = std::numeric_limits<double>::min();
  if (!pack(charts, least, margin, side).all_packed()) return std::nullopt;
  double area = 0;
  for (const Chart& c : charts) area += c.size.x() * c.size.y();
  double lo = least, hi = double(side) / std::sqrt(std::max(area, 1e-300));
  // From a fit at `least` the search narrows to 10⁻⁴ in at most about 1,100 halvings (the
  // exponent range of a double); the bound keeps a bad chart size from looping.
  for (int step = 0; step < 2048 && hi - lo > 1e-4 * hi; ++step) {
    const double mid = 0.5 * (lo + hi);
    (pack(charts, mid, margin, side).all_packed() ? lo : hi) = mid;
  }
  return lo;
}

}  // namespace

Expected<AutoUvReport> generate_lightmap_uvs(Mesh& mesh, const AutoUvTarget& target) {
  const Surface surface = surface_of(mesh.mesh);
  std::vector<int> all(surface.faces.size());
  for (std::size_t f = 0; f < all.size(); ++f) all[f] = int(f);
  std::vector<Chart> charts;
  for (std::vector<int>& grown : grow_charts(surface, all, kConeDegrees))
    place_chart(surface, std::move(grown), charts);
  for (Chart& c : charts) fit_rectangle(c);

  // The side and density: a side given (the density that fills it), or a density given (the
  // smallest side that holds it, up to max_side, beyond which max_side filled).
  AutoUvReport report;
  report.charts = int(charts.size());
  for (const Chart& c : charts) report.conformal_charts += c.conformal;
  const int margin = std::max(target.margin, 0);
  int side = target.side;
  double scale = target.texels_per_metre;
  if (side <= 0) {
    const int largest = std::max(target.max_side, kMinLightmapSide);
    if (pack(charts, scale, margin, largest).all_packed()) {
      int lo = kMinLightmapSide - 1, hi = largest;  // lo does not fit (or is below the least)
      while (hi - lo > 1) {
        const int mid = lo + (hi - lo) / 2;
        (pack(charts, scale, margin, mid).all_packed() ? hi : lo) = mid;
      }
      side = hi;
    } else {
      side = largest;
      scale = 0;  // fill it
    }
  }
  if (scale <= 0) {
    const std::optional<double> filled = fill_side(charts, margin, side);
    if (!filled) {
      return scene_error(fmt::format(
          "its {} generated UV charts do not fit a {}² lightmap even as points {} texels apart; "
          "raise its resolution or lower 'margin'",
          charts.size(), side, margin));
    }
    scale = *filled;
  }
  const RectanglePacking placed = pack(charts, scale, margin, side);
  report.side = side;
  report.texels_per_metre = scale;

  // Each chart's UVs in the lightmap: half a margin and its centring offset into its rectangle.
  const int low_margin = margin / 2;
  std::vector<std::array<Vec2, 3>> corner_uv(surface.faces.size());
  std::vector<int> chart_of(surface.faces.size(), -1);
  for (std::size_t c = 0; c < charts.size(); ++c) {
    const std::array<int, 2> rect = texel_rectangle(charts[c], scale, margin);
    const Vec2 offset(double(placed.x[c] + low_margin) +
                          0.5 * (double(rect[0] - margin) - charts[c].size.x() * scale),
                      double(placed.y[c] + low_margin) +
                          0.5 * (double(rect[1] - margin) - charts[c].size.y() * scale));
    for (std::size_t i = 0; i < charts[c].faces.size(); ++i) {
      const std::size_t f = std::size_t(charts[c].faces[i]);
      chart_of[f] = int(c);
      for (std::size_t k = 0; k < 3; ++k)
        corner_uv[f][k] = (offset + charts[c].uv[i][k] * scale) / double(side);
    }
  }

  // The mesh again, faces in their order, a vertex per (vertex, chart).
  TriMesh rebuilt;
  std::vector<Vec2> texture_uv;
  const bool has_texture_uv = !mesh.texture_uv.empty();
  std::map<std::pair<int, int>, TriMesh::VertexHandle> copy;
  for (std::size_t f = 0; f < surface.faces.size(); ++f) {
    std::array<TriMesh::VertexHandle, 3> corner;
    for (std::size_t k = 0; k < 3; ++k) {
      const TriMesh::VertexHandle v = surface.faces[f].vertex[k];
      auto [it, added] = copy.try_emplace({v.idx(), chart_of[f]});
      if (added) {
        it->second = rebuilt.add_vertex(mesh.mesh.point(v));
        rebuilt.set_normal(it->second, mesh.mesh.normal(v));
        rebuilt.set_texcoord2D(it->second,
                               TriMesh::TexCoord2D(corner_uv[f][k].x(), corner_uv[f][k].y()));
        if (has_texture_uv) texture_uv.push_back(mesh.texture_uv[std::size_t(v.idx())]);
      }
      corner[k] = it->second;
    }
    add_triangle(rebuilt, corner[0], corner[1], corner[2], texture_uv);
  }
  rebuilt.update_face_normals();
  mesh.mesh = std::move(rebuilt);
  mesh.texture_uv = std::move(texture_uv);
  mesh.has_uv = true;
  mesh.uv_generated = true;
  return report;
}

}  // namespace sb
