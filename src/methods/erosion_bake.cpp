// The `erosion` baseline: contact-hardening soft shadows by erosion (Klein, Nischwitz &
// Obermeier, docs/design.md [S4]), moved from screen space into lightmap
// texel space (docs/design.md §7). Per light:
//  1. Hard shadow: one ray per texel towards the light's centre, asking the first blocker
//     (RayScene::first_hit), so a shadowed texel knows d_b (light to blocker) and d_r (light to
//     receiver). Texels the light does not reach, and uncovered texels, are no part of the image.
//     Where the centre is below the texel's horizon but part of the light is not, the ray aims at
//     that part instead (hard_shadow_target says why).
//  2. Edges: the paper's 3×3 Laplacian on the binary hard shadow. It is non-zero exactly where a
//     4-neighbour differs, so edge texels lie on both sides of the shadow boundary; a neighbour
//     that is uncovered, unreached or in another UV chart is skipped (counted as equal).
//  3. Penumbra width at each edge (Fernando's parallel planes): w = L·(d_r − d_b)/d_b, with the
//     blocker ratio of a lit edge texel taken from its shadowed neighbours. The paper's division
//     by the observer distance, which turns metres into screen pixels, becomes a division by the
//     texel's size along the edge normal, seen across the light direction: the edge normal is
//     mapped to metres by the texel's own triangle (so a receiver lit at a grazing angle, or with
//     stretched UVs, gets its wider penumbra in texels). L is the light's width across that
//     direction (Light::half_extents), not Light::extent_across: the latter is the worst case
//     over directions (a square light's diagonal) and would widen every side-on penumbra by √2.
//  4. Best-fit line (the paper's aliasing correction): a least-squares line through the edge
//     texels of a 7×7 window; the point an edge stands for is its centre's foot on that line,
//     i.e. the paper's edge vector plus v_line. Where the window holds a corner rather than a line
//     (large residual) the crack between the texel and its differing neighbours is used instead.
//     The line's normal (else the crack's) is the edge normal that steps 3 and 6 use.
//  5. Erosion, as the paper's gathering variant (§4): for each texel the nearest edge; the texel
//     is in the penumbra if it lies within that edge's range (half its width). It erodes the lit
//     region and dilates the shadow alike, giving the inner and the outer penumbra. The search is
//     exact (edges bucketed in tiles) where the paper approximates it with a min-max mipmap on
//     the GPU. The nearest edge decides even when a farther, wider one would reach the texel:
//     that keeps contact shadows hard where a narrow edge (a foot on the floor) lies next to a
//     wide one (measured on the scenes: equal or lower error on all but one, and no discs of a
//     far edge's penumbra drawn across a contact shadow).
//  6. Shadow factor, by settings.erosion_factor:
//     "distance": the paper's s_outer = (ω − d)/(2ω), s_inner = 1 − s_outer, so V = 1/2 ± d/w.
//       The paper's ω there is the penumbra's extent on each side of the hard edge, which the
//       centre's hard edge splits in two: ω = w/2 with Fernando's full width w.
//     "pcf": the hard shadow box-filtered over a footprint whose extent across the edge is w
//       (side w/(|n_x| + |n_y|) for edge normal n), with fractional texels at its border, by
//       summed-area tables; outside every edge's range the hard shadow stays.
// UV charts: neighbourhoods (Laplacian, line fits, erosion, filter) only read texels of the
// same chart (faces joined by shared vertices, which share UVs), never uncovered ones. At a UV
// seam each side sees only its own edges: a penumbra whose hard edge lies just across a seam
// is missed on this side, which stays hard up to the seam.
#include "methods/erosion_bake.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>

namespace sb {

namespace {

constexpr int kFitRadius = 3;                  // texels: the line-fit window is 7×7
constexpr int kFitMinimumTexels = 5;           // fewer edge texels than this: no line
constexpr double kFitResidualLimit = 0.6;      // texels RMS: more, and the window holds a corner
constexpr int kTile = 16;                      // texels per side of an edge bucket
constexpr double kLargestWidthFraction = 0.5;  // of the lightmap side: the erosion is bounded

// Metres per texel step along lightmap x and y on one face (row 0 is v = 1).
struct TexelFrame {
  Vec3 dx = Vec3::Zero(), dy = Vec3::Zero();
};

std::vector<TexelFrame> texel_frames(const Mesh& mesh, int width, int height) {
  std::vector<TexelFrame> frames(mesh.mesh.n_faces());
  for (auto f : mesh.mesh.faces()) {
    const Triangle tri = triangle(mesh.mesh, f);
    auto texel = [&](const Vec2& uv) { return Vec2(uv.x() * width, (1.0 - uv.y()) * height); };
    const Vec2 a = texel(tri.uv[1]) - texel(tri.uv[0]), b = texel(tri.uv[2]) - texel(tri.uv[0]);
    const double det = a.x() * b.y() - a.y() * b.x();
    if (std::abs(det) < 1e-12) continue;
    const Vec3 pa = tri.p[1] - tri.p[0], pb = tri.p[2] - tri.p[0];
    // [pa pb] = [dx dy]·[a b]  ⇒  [dx dy] = [pa pb]·[a b]⁻¹
    frames[f.idx()].dx = (pa * b.y() - pb * a.y()) / det;
    frames[f.idx()].dy = (pb * a.x() - pa * b.x()) / det;
  }
  return frames;
}

// UV chart of each face, numbered from 0: faces joined through shared vertices. Vertices carry
// the UVs, so a shared vertex means the layout is continuous there.
std::vector<int> face_charts(const TriMesh& mesh, int* chart_count) {
  std::vector<int> parent(mesh.n_vertices());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (auto f : mesh.faces()) {
    int first = -1;
    for (auto v : mesh.fv_range(f)) {
      if (first < 0) {
        first = find(v.idx());
      } else {
        parent[find(v.idx())] = first;
      }
    }
  }
  std::vector<int> label(mesh.n_vertices(), -1), charts(mesh.n_faces(), 0);
  int count = 0;
  for (auto f : mesh.faces()) {
    const int root = find(mesh.fv_range(f).begin()->idx());
    if (label[root] < 0) label[root] = count++;
    charts[f.idx()] = label[root];
  }
  *chart_count = count;
  return charts;
}

// One edge texel of the hard shadow, in texel coordinates (texel (x, y) spans [x, x+1]×[y, y+1]).
struct Edge {
  Vec2 foot;         // the point distances are measured to
  Vec2 normal;       // unit, from the shadow towards the lit side
  double width = 0;  // penumbra width w, texels
  int chart = -1;
};

// Summed-area tables of one chart over its bounding box: valid texels and lit ones, so that a
// box filter reads this chart's texels only.
struct ChartTable {
  int x0 = 0, y0 = 0, w = 0, h = 0;
  // (w + 1) × (h + 1) counts; entry (i, j): texels left of column i and above row j.
  std::vector<std::int32_t> valid, lit;

  // The integral over [x0, X]×[y0, Y] of a table's piecewise-constant image: bilinear in the
  // table, exactly.
  double integral(const std::vector<std::int32_t>& table, double X, double Y) const {
    const double fx = std::clamp(X - x0, 0.0, double(w)), fy = std::clamp(Y - y0, 0.0, double(h));
    const int i = std::min(int(fx), w - 1), j = std::min(int(fy), h - 1);
    const double ax = fx - i, ay = fy - j;
    auto at = [&](int a, int b) { return double(table[std::size_t(b) * (w + 1) + a]); };
    return (1 - ay) * ((1 - ax) * at(i, j) + ax * at(i + 1, j)) +
           ay * ((1 - ax) * at(i, j + 1) + ax * at(i + 1, j + 1));
  }
  double box(const std::vector<std::int32_t>& table, double xa, double ya, double xb,
             double yb) const {
    return integral(table, xb, yb) - integral(table, xa, yb) - integral(table, xb, ya) +
           integral(table, xa, ya);
  }
};

// Finds, for a texel, the nearest edge of its chart and whether that edge's range (half its
// width) reaches it: edges bucketed by the tile of their foot, each bucket with its feet's box
// and its largest reach. A tile's own reach R is the largest reach of any bucket that can reach
// into it; an edge in range lies nearer than R, so only buckets nearer than R to the tile are
// searched, nearest first, and if the nearest edge is out of its own range no farther one counts.
class EdgeIndex {
 public:
  EdgeIndex(const std::vector<Edge>& edges, int width, int height)
      : edges_(edges),
        tiles_x_((width + kTile - 1) / kTile),
        tiles_y_((height + kTile - 1) / kTile),
        buckets_(std::size_t(tiles_x_) * tiles_y_),
        reach_(buckets_.size(), 0.0),
        near_(buckets_.size()) {
    for (std::size_t e = 0; e < edges.size(); ++e) {
      Bucket& b = buckets_[tile_of(edges[e].foot)];
      b.edges.push_back(int(e));
      b.lo = b.lo.cwiseMin(edges[e].foot);
      b.hi = b.hi.cwiseMax(edges[e].foot);
      b.reach = std::max(b.reach, 0.5 * edges[e].width);
    }
    for (std::size_t b = 0; b < buckets_.size(); ++b) {
      if (buckets_[b].edges.empty()) continue;
      for_tiles_near(buckets_[b].lo, buckets_[b].hi, buckets_[b].reach,
                     [&](std::size_t t) { reach_[t] = std::max(reach_[t], buckets_[b].reach); });
    }
    tbb::parallel_for(std::size_t(0), buckets_.size(), [&](std::size_t t) {
      if (reach_[t] <= 0) return;
      const Vec2 lo(double(t % tiles_x_) * kTile, double(t / tiles_x_) * kTile);
      const Vec2 hi = lo + Vec2::Constant(kTile);
      std::vector<std::pair<double, int>>& near = near_[t];
      for_tiles_near(lo, hi, reach_[t], [&](std::size_t b) {
        if (buckets_[b].edges.empty()) return;
        const double gap = box_gap(lo, hi, buckets_[b].lo, buckets_[b].hi);
        if (gap < reach_[t]) near.emplace_back(gap, int(b));
      });
      std::sort(near.begin(), near.end());
    });
  }

  // The nearest edge of `chart` to `q` (texel coordinates) if q lies in its range, else −1;
  // its distance to q in *distance.
  int nearest_in_range(const Vec2& q, int chart, double* distance) const {
    int best = -1;
    double best_distance = std::numeric_limits<double>::infinity();
    for (const auto& [tile_gap, b] : near_[tile_of(q)]) {
      if (tile_gap >= best_distance) break;  // sorted: no nearer edge in the rest
      for (int e : buckets_[std::size_t(b)].edges) {
        const Edge& edge = edges_[std::size_t(e)];
        if (edge.chart != chart) continue;
        const double d = (q - edge.foot).norm();
        if (d < best_distance) best = e, best_distance = d;
      }
    }
    *distance = best_distance;
    if (best >= 0 && best_distance >= 0.5 * edges_[std::size_t(best)].width) return -1;
    return best;
  }

 private:
  struct Bucket {
    std::vector<int> edges;
    Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity());
    Vec2 hi = Vec2::Constant(-std::numeric_limits<double>::infinity());
    double reach = 0;  // texels
  };

  std::size_t tile_of(const Vec2& q) const {
    const int tx = std::clamp(int(std::floor(q.x() / kTile)), 0, tiles_x_ - 1);
    const int ty = std::clamp(int(std::floor(q.y() / kTile)), 0, tiles_y_ - 1);
    return std::size_t(ty) * tiles_x_ + tx;
  }
  // Distance between two boxes, texels (0 where they overlap).
  static double box_gap(const Vec2& alo, const Vec2& ahi, const Vec2& blo, const Vec2& bhi) {
    return (blo - ahi).cwiseMax(alo - bhi).cwiseMax(Vec2::Zero()).norm();
  }
  // Calls f on every tile whose square comes within `reach` of the box [lo, hi].
  template <typename F>
  void for_tiles_near(const Vec2& lo, const Vec2& hi, double reach, F&& f) const {
    const int x0 = std::max(0, int(std::floor((lo.x() - reach) / kTile)));
    const int x1 = std::min(tiles_x_ - 1, int(std::floor((hi.x() + reach) / kTile)));
    const int y0 = std::max(0, int(std::floor((lo.y() - reach) / kTile)));
    const int y1 = std::min(tiles_y_ - 1, int(std::floor((hi.y() + reach) / kTile)));
    for (int ty = y0; ty <= y1; ++ty)
      for (int tx = x0; tx <= x1; ++tx) f(std::size_t(ty) * tiles_x_ + tx);
  }

  const std::vector<Edge>& edges_;
  int tiles_x_, tiles_y_;
  std::vector<Bucket> buckets_;  // per tile: the edges whose foot is in it
  std::vector<double> reach_;    // per tile: R, texels
  std::vector<std::vector<std::pair<double, int>>> near_;  // per tile: (gap, bucket), nearest first
};

struct Figures {
  std::int64_t edges = 0, fitted = 0, capped = 0, penumbra_texels = 0, rays = 0;
  double width_sum = 0;
};

class ErosionBake {
 public:
  ErosionBake(const TexelSpace& space, const BaselineInputs& in, const ErosionOptions& options)
      : space_(space), in_(in), options_(options), W_(space.width), H_(space.height) {
    frames_ = texel_frames(*in.receiver, W_, H_);
    const std::vector<int> charts = face_charts(in.receiver->mesh, &chart_count_);
    texel_at_.assign(std::size_t(W_) * H_, -1);
    chart_.assign(std::size_t(W_) * H_, -1);
    for (std::size_t t = 0; t < space.texels.size(); ++t) {
      const Texel& tx = space.texels[t];
      texel_at_[pixel(tx.x, tx.y)] = std::int64_t(t);
      chart_[pixel(tx.x, tx.y)] = tx.face >= 0 ? charts[tx.face] : 0;
    }
  }

  // One light's visibility into `mix`.
  void light(std::size_t l, LightMix& mix, Figures& figures) {
    const Light& light = (*in_.lights)[l];
    hard_shadow(light, figures);
    find_edges(light, figures);
    erode(l, mix, figures);
  }

 private:
  std::size_t pixel(int x, int y) const { return std::size_t(y) * W_ + x; }
  bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < W_ && y < H_; }
  // Whether pixel q may be read from pixel p's neighbourhood: part of the image, same chart.
  bool joined(std::size_t p, int x, int y) const {
    return inside(x, y) && state_[pixel(x, y)] >= 0 && chart_[pixel(x, y)] == chart_[p];
  }

  void hard_shadow(const Light& light, Figures& figures) {
    const RayScene& rays = *in_.rays;
    const double offset = rays.surface_offset();
    state_.assign(std::size_t(W_) * H_, -1);
    ratio_.assign(std::size_t(W_) * H_, 0.0f);
    axis_.assign(space_.texels.size(), Vec3f::Zero());
    std::atomic<std::int64_t> traced{0};
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, space_.texels.size(), 256),
        [&](const tbb::blocked_range<std::size_t>& range) {
          std::vector<Vec3> origins, directions;
          std::vector<double> lengths, hits;
          std::vector<std::size_t> which;
          for (std::size_t t = range.begin(); t != range.end(); ++t) {
            const Texel& tx = space_.texels[t];
            if (!light.reaches(tx.position.cast<double>(), tx.normal.cast<double>())) continue;
            const Vec3 origin = space_.ray_origin(t, offset);
            bool at_centre = true;
            const std::optional<Vec3> target =
                hard_shadow_target(light, tx, space_.geometric_normal(t), &at_centre);
            state_[pixel(tx.x, tx.y)] = 1;
            if (!target) continue;
            const Vec3 d = *target - origin;
            const double len = d.norm();
            if (len <= 2 * offset) continue;
            axis_[t] = (d / len).cast<float>();
            origins.push_back(origin);
            directions.push_back(d);
            // Stop short of the light's own surface, as the reference does (the centre of a sphere
            // light lies inside it, and no blocker is there).
            const bool inside_sphere = at_centre && light.shape() == LightShape::sphere;
            lengths.push_back(1.0 - (inside_sphere ? light.desc().radius : offset) / len);
            which.push_back(t);
          }
          hits.resize(which.size());
          rays.first_hit(int(which.size()), origins.data(), directions.data(), lengths.data(),
                         hits.data());
          traced += std::int64_t(which.size());
          for (std::size_t k = 0; k < which.size(); ++k) {
            if (hits[k] < 0) continue;
            const Texel& tx = space_.texels[which[k]];
            // t is the hit's fraction of the segment from the receiver to the ray's target on
            // the light: d_b = (1 − t)·|d|, d_r = |d|, so (d_r − d_b)/d_b = t/(1 − t).
            const double t = std::min(hits[k], 1.0 - 1e-9);
            state_[pixel(tx.x, tx.y)] = 0;
            ratio_[pixel(tx.x, tx.y)] = float(t / (1.0 - t));
          }
        });
    figures.rays += traced.load();
  }

  // Where a texel's hard-shadow ray aims: the light's centre, as the paper's shadow map from
  // the light's position, unless the centre lies below the texel's horizon (of its shading or
  // its triangle's normal) while part of the light is above both (near a terminator, on a
  // receiver beside a low light). A shadow map would call such a texel back-facing, hence dark,
  // where V = H/H0 counts only the part above the horizon; so there the ray aims at that part's
  // irradiance-weighted centroid, from a 4×4 grid of light samples (no rays). A ray below the
  // triangle's plane would hit the receiver's own neighbouring triangles. No part above both
  // horizons (the shading normal sees the light, the triangle does not): nullopt, and the texel
  // counts as lit, as the reference finds it where the shading normal is smooth.
  static std::optional<Vec3> hard_shadow_target(const Light& light, const Texel& tx,
                                                const Vec3f& face_normal, bool* at_centre) {
    const Vec3 y = tx.position.cast<double>(), n = tx.normal.cast<double>();
    const Vec3 face = face_normal.cast<double>();
    const Vec3 to_centre = light.centre() - y;
    *at_centre = to_centre.dot(n) > 0 && to_centre.dot(face) > 0;
    if (*at_centre) return light.centre();
    constexpr int kGrid = 4;
    Vec3 sum = Vec3::Zero();
    double weight = 0;
    for (int j = 0; j < kGrid; ++j)
      for (int i = 0; i < kGrid; ++i) {
        const LightSample s = light.sample(y, n, Vec2((i + 0.5) / kGrid, (j + 0.5) / kGrid));
        if (s.weight <= 0 || (s.point - y).dot(face) <= 0) continue;
        sum += s.weight * s.point;
        weight += s.weight;
      }
    if (weight <= 0) return std::nullopt;
    return sum / weight;
  }

  void find_edges(const Light& light, Figures& figures) {
    edges_.clear();
    std::vector<std::array<int, 2>> where;
    edge_at_.assign(std::size_t(W_) * H_, -1);
    const int dx4[4] = {1, -1, 0, 0}, dy4[4] = {0, 0, 1, -1};
    for (int y = 0; y < H_; ++y)
      for (int x = 0; x < W_; ++x) {
        const std::size_t p = pixel(x, y);
        if (state_[p] < 0) continue;
        for (int k = 0; k < 4; ++k) {
          const int qx = x + dx4[k], qy = y + dy4[k];
          if (joined(p, qx, qy) && state_[pixel(qx, qy)] != state_[p]) {
            edge_at_[p] = std::int64_t(where.size());
            where.push_back({x, y});
            break;
          }
        }
      }
    edges_.resize(where.size());
    const double largest = kLargestWidthFraction * std::max(W_, H_);
    std::atomic<std::int64_t> fitted{0}, capped{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, where.size(), 256), [&](const auto& r) {
      for (std::size_t e = r.begin(); e != r.end(); ++e) {
        const int x = where[e][0], y = where[e][1];
        const std::size_t p = pixel(x, y);
        Edge& edge = edges_[e];
        edge.chart = chart_[p];
        const Vec2 centre(x + 0.5, y + 0.5);
        // The crack towards the differing 4-neighbours, and the blocker ratio of the shadowed
        // side (this texel's own, or its shadowed 8-neighbours' mean).
        Vec2 crack = Vec2::Zero();
        int differing = 0, blockers = 0;
        double ratio = 0;
        for (int j = -1; j <= 1; ++j)
          for (int i = -1; i <= 1; ++i) {
            if ((i == 0 && j == 0) || !joined(p, x + i, y + j)) continue;
            const std::size_t q = pixel(x + i, y + j);
            if (state_[q] != state_[p] && (i == 0 || j == 0)) {
              crack += Vec2(i, j);
              ++differing;
            }
            if (state_[q] == 0) ratio += ratio_[q], ++blockers;
          }
        crack /= std::max(differing, 1);
        if (state_[p] == 0) {
          ratio = ratio_[p];
        } else if (blockers > 0) {
          ratio /= blockers;
        }
        Vec2 normal = state_[p] == 0 ? crack : Vec2(-crack);
        normal = normal.norm() > 0 ? normal.normalized() : Vec2(1, 0);
        edge.normal = normal;
        edge.foot = centre + 0.5 * crack;
        if (fit_line(x, y, centre, normal, edge)) ++fitted;
        if (!options_.line_distance) edge.foot = centre;
        // Width: L across the edge's world-space normal, over the metres one texel step along
        // the normal spans across the light direction.
        const Texel& tx = space_.texels[std::size_t(texel_at_[p])];
        const TexelFrame& frame = frames_[std::size_t(std::max(tx.face, 0))];
        const Vec3 axis = axis_[std::size_t(texel_at_[p])].cast<double>();
        const Vec3 step = edge.normal.x() * frame.dx + edge.normal.y() * frame.dy;
        const Vec3 across = step - step.dot(axis) * axis;
        double width = 0;
        if (across.norm() > 0 && axis.norm() > 0) {
          const Vec3 dir = across.normalized();
          const double light_width = 2 * light.half_extents(dir, dir).x();
          width = light_width * ratio / across.norm();
        }
        if (width > largest) width = largest, ++capped;
        edge.width = width;
      }
    });
    figures.edges += std::int64_t(edges_.size());
    figures.fitted += fitted.load();
    figures.capped += capped.load();
    for (const Edge& e : edges_) figures.width_sum += e.width;
  }

  // The least-squares line through the edge texels of the window around (x, y), in the same
  // chart; on success moves edge.foot to the centre's foot on it and edge.normal to its normal.
  bool fit_line(int x, int y, const Vec2& centre, const Vec2& normal, Edge& edge) const {
    const std::size_t p = pixel(x, y);
    Vec2 mean = Vec2::Zero();
    Eigen::Matrix2d second = Eigen::Matrix2d::Zero();
    int n = 0;
    for (int j = -kFitRadius; j <= kFitRadius; ++j)
      for (int i = -kFitRadius; i <= kFitRadius; ++i) {
        if (!joined(p, x + i, y + j) || edge_at_[pixel(x + i, y + j)] < 0) continue;
        const Vec2 c(i, j);  // relative to (x, y): small numbers
        mean += c;
        second += c * c.transpose();
        ++n;
      }
    if (n < kFitMinimumTexels) return false;
    mean /= n;
    const Eigen::Matrix2d covariance = second / n - mean * mean.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(covariance);
    // Eigenvalues ascending: the smallest is the mean squared distance to the line.
    if (std::sqrt(std::max(0.0, solver.eigenvalues()[0])) > kFitResidualLimit) return false;
    Vec2 line_normal = solver.eigenvectors().col(0);
    if (line_normal.dot(normal) < 0) line_normal = -line_normal;
    const Vec2 on_line = centre + mean;  // the window's centroid, absolute
    edge.foot = centre - (centre - on_line).dot(line_normal) * line_normal;
    edge.normal = line_normal;
    return true;
  }

  void erode(std::size_t l, LightMix& mix, Figures& figures) {
    const bool by_distance = in_.settings.erosion_by_distance;
    if (!by_distance) build_tables();
    const EdgeIndex index(edges_, W_, H_);
    std::atomic<std::int64_t> penumbra{0};
    tbb::parallel_for(tbb::blocked_range<int>(0, H_, 4), [&](const tbb::blocked_range<int>& r) {
      std::int64_t local_penumbra = 0;
      for (int y = r.begin(); y != r.end(); ++y)
        for (int x = 0; x < W_; ++x) {
          const std::size_t p = pixel(x, y);
          if (state_[p] < 0) continue;
          const Vec2 centre(x + 0.5, y + 0.5);
          double best_distance = 0;
          int best = index.nearest_in_range(centre, chart_[p], &best_distance);
          double v = state_[p];
          if (best >= 0) {
            ++local_penumbra;
            const Edge& edge = edges_[std::size_t(best)];
            if (by_distance) {
              const double s = best_distance / edge.width;  // in [0, 1/2)
              v = state_[p] == 1 ? 0.5 + s : 0.5 - s;
            } else {
              v = filtered(p, centre, edge);
            }
          }
          mix.set(l, std::size_t(texel_at_[p]), Vec3::Constant(std::clamp(v, 0.0, 1.0)));
        }
      penumbra += local_penumbra;
    });
    figures.penumbra_texels += penumbra.load();
  }

  // The hard shadow averaged over a square footprint centred on the texel whose extent across
  // the edge's normal is the penumbra width, over this chart's texels.
  double filtered(std::size_t p, const Vec2& centre, const Edge& edge) const {
    const ChartTable& table = tables_[std::size_t(chart_[p])];
    const double half = 0.5 * edge.width / (std::abs(edge.normal.x()) + std::abs(edge.normal.y()));
    const double xa = centre.x() - half, xb = centre.x() + half;
    const double ya = centre.y() - half, yb = centre.y() + half;
    const double valid = table.box(table.valid, xa, ya, xb, yb);
    // The footprint always holds part of this texel; the guard is for rounding only.
    if (valid <= 1e-9) return state_[p];
    return table.box(table.lit, xa, ya, xb, yb) / valid;
  }

  void build_tables() {
    std::vector<std::array<int, 4>> box(
        std::size_t(chart_count_),
        {std::numeric_limits<int>::max(), std::numeric_limits<int>::max(), -1, -1});
    for (const Texel& tx : space_.texels) {
      auto& b = box[std::size_t(chart_[pixel(tx.x, tx.y)])];
      b = {std::min<int>(b[0], tx.x), std::min<int>(b[1], tx.y), std::max<int>(b[2], tx.x),
           std::max<int>(b[3], tx.y)};
    }
    tables_.assign(std::size_t(chart_count_), ChartTable{});
    tbb::parallel_for(0, chart_count_, [&](int c) {
      const auto& b = box[std::size_t(c)];
      if (b[2] < 0) return;
      ChartTable& t = tables_[std::size_t(c)];
      t.x0 = b[0], t.y0 = b[1], t.w = b[2] - b[0] + 1, t.h = b[3] - b[1] + 1;
      t.valid.assign(std::size_t(t.w + 1) * (t.h + 1), 0);
      t.lit.assign(t.valid.size(), 0);
      for (int j = 0; j < t.h; ++j)
        for (int i = 0; i < t.w; ++i) {
          const std::size_t p = pixel(t.x0 + i, t.y0 + j);
          const bool mine = state_[p] >= 0 && chart_[p] == c;
          const std::size_t at = std::size_t(j + 1) * (t.w + 1) + (i + 1);
          const std::size_t up = std::size_t(j) * (t.w + 1) + (i + 1);
          const std::size_t left = std::size_t(j + 1) * (t.w + 1) + i;
          const std::size_t diag = std::size_t(j) * (t.w + 1) + i;
          t.valid[at] = t.valid[up] + t.valid[left] - t.valid[diag] + (mine ? 1 : 0);
          t.lit[at] = t.lit[up] + t.lit[left] - t.lit[diag] + (mine && state_[p] == 1 ? 1 : 0);
        }
    });
  }

  const TexelSpace& space_;
  const BaselineInputs& in_;
  ErosionOptions options_;
  int W_, H_;
  int chart_count_ = 0;
  std::vector<TexelFrame> frames_;
  std::vector<std::int64_t> texel_at_;  // per pixel: index into space_.texels, or −1
  std::vector<int> chart_;              // per pixel: UV chart, or −1
  // Per light:
  std::vector<std::int8_t> state_;  // per pixel: −1 not in the image, 0 shadowed, 1 lit
  std::vector<float> ratio_;        // per pixel: (d_r − d_b)/d_b where shadowed
  std::vector<Vec3f> axis_;         // per texel: unit direction of its hard-shadow ray
  std::vector<Edge> edges_;
  std::vector<std::int64_t> edge_at_;  // per pixel: index into edges_, or −1
  std::vector<ChartTable> tables_;
};

}  // namespace

MixedImages bake_erosion(const TexelSpace& space, const BaselineInputs& in,
                         const ErosionOptions& options, MethodStats* stats,
                         std::int64_t* rays_traced) {
  LightMix mix(space, *in.lights, in.settings.quantity, LightMix::Order::light_major,
               in.keep_per_light);
  Figures figures;
  if (!space.texels.empty()) {
    ErosionBake bake(space, in, options);
    for (std::size_t l = 0; l < in.lights->size(); ++l) bake.light(l, mix, figures);
  }
  if (rays_traced) *rays_traced += figures.rays;
  if (stats) {
    stats->emplace_back("edge texels", double(figures.edges));
    stats->emplace_back("mean penumbra width (texels)",
                        figures.edges > 0 ? figures.width_sum / double(figures.edges) : 0);
    stats->emplace_back("edges with a fitted line",
                        figures.edges > 0 ? double(figures.fitted) / double(figures.edges) : 0);
    stats->emplace_back("edges with capped width", double(figures.capped));
    stats->emplace_back("penumbra texels", double(figures.penumbra_texels));
  }
  return mix.finish();
}

MixedImages bake_erosion(const TexelSpace& space, const BaselineInputs& in, MethodStats* stats,
                         std::int64_t* rays_traced) {
  return bake_erosion(space, in, ErosionOptions{}, stats, rays_traced);
}

}  // namespace sb
