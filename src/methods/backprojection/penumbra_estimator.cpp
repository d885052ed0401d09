// The back-projection penumbra estimator (penumbra_estimator.h).
//
// Sources: Drettakis & Fiume, "A Fast Shadow Algorithm for Area Light Sources Using
// Backprojection" (SIGGRAPH 1994) see a light from a receiver point through the blockers
// projected onto it; Schwarz & Stamminger, "Bitmask Soft Shadows" (EG 2007) keep what the
// projections cover as a bitmask over fixed points of the light; Laine et al., "Soft Shadow
// Volumes for Ray Tracing" (SIGGRAPH 2005) measure one to two orders of magnitude over rays at
// equal samples. The weight is docs/design.md §1.
//
// What it computes. Seen from a texel y, a point x of a planar light of uniform exitance brings
// irradiance in proportion to w(x) = cosθ_x·cosθ_y / |x − y|², and V = ∫ w·v / ∫ w over the light,
// v(x) = 1 where the segment from the texel's ray origin o to x meets no blocker. Every blocker
// point p between o and the light (the shaft's polygons hold exactly those) hides the light
// point o + (p − o)·h_o/(h_o − h_p) (h: height above the light's plane), so the hidden part of the
// light is the union of the polygons projected from o onto the light's plane: projection maps
// a convex polygon to a convex polygon.
//
// How. The light is cut into rows along a direction turned by kRowAngle from its axes (so that
// the edges of furniture parallel to a panel's sides cross them). A projected polygon gives, in
// every row whose centre line it crosses, the interval of that line it covers; a row keeps up to
// six intervals exactly and merges them, and beyond that marks the 64 cells of the row whose
// centres they cover (a union is then a bitwise OR). Along a row, in coordinates s across it
// and t along the frame,
//     w ∝ (a + b·τ) / (γ + τ²)²,   τ = s − s_y,   γ = h² + (t − t_y)²,
//     a = n_t·(t − t_y) − h·n_n,   b = n_s   (n_s, n_t, n_n: the texel's normal in the frame),
// whose integral has the closed form
//     P(τ) = a·[τ / (2γ(γ + τ²)) + atan(τ/√γ) / (2γ^{3/2})] − b / (2(γ + τ²)),
// so the hidden part of each row, clipped to the texel's horizon (a + b·τ > 0), is integrated
// exactly; the rows are summed as a midpoint rule across them, which is exact for any part of
// the light whose outline is straight within a row's band (a blocker's edge crossing it). A
// row's chord of the light is widened or narrowed about its middle to its band's exact area, so
// the light's own corners cost nothing either. What remains is the rows holding a corner of a
// projected polygon (the error falls about threefold per doubling of the rows: the tests measure
// 0.0014 RMSE at 32 rows on random triangles, 0.0005 at 64), and, in rows of cells, a hidden
// run's ends snapped to cell boundaries. V = 1 − hidden / F, F the light's closed-form form
// factor: exactly 1 where nothing is blocked, and 0 where every row is blocked end to end.
//
// Where the texel's horizon cuts the light, the rows are spread over the part above it alone
// and the light's weight is integrated over the same rows (V = 1 − hidden / total), so that a
// sliver of light above a grazing horizon, thinner than a row, is still resolved.
//
// A sphere is seen from the texel as the disk of its silhouette (just beyond the shaft's base,
// shaft_culling.cpp: the same disk seen from the ray origin); uniform in solid angle, its points
// weigh cosθ_y·dω = cosθ_y·(h/ℓ)·dA/ℓ², the same form with h the plane's distance.
#include "methods/backprojection/penumbra_estimator.h"

#include "methods/backprojection/light_rows.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>

#include "occluders/blocker_solids.h"
#include "occluders/ray_scene.h"

namespace sb {

namespace {

// The most polygons tried nearest first where the light's centre is hidden (Blockers::
// centre_hidden; on OpenArena's oacmpdm9, 32 of them hide all of the light behind 97 % of the
// walls tried, 16 behind 83 %), in shafts of more than kNearestFewest (fewer cost the estimator
// less than the attempt).
constexpr std::size_t kNearestFirst = 32;
constexpr std::size_t kNearestFewest = 8;

// The closed-form integral of the weight along one row (the file's opening comment).
// atan to within 2e-8 (Abramowitz & Stegun 4.4.49 on [0, 1], and π/2 − atan(1/x) beyond): the
// rows' integrals take hundreds per texel, and std::atan is four times slower.
double fast_atan(double x) {
  const double a = std::abs(x);
  const bool beyond = a > 1;
  const double z = beyond ? 1 / a : a, z2 = z * z;
  double p = 0.0028662257;
  p = p * z2 - 0.0161657367;
  p = p * z2 + 0.0429096138;
  p = p * z2 - 0.0752896400;
  p = p * z2 + 0.1065626393;
  p = p * z2 - 0.1420889944;
  p = p * z2 + 0.1999355085;
  p = p * z2 - 0.3333314528;
  p = p * z2 + 1;
  const double r = beyond ? std::numbers::pi / 2 - p * z : p * z;
  return std::copysign(r, x);
}

struct RowWeight {
  double a = 0, b = 0, g = 1, sg = 1;
  double half_over_g = 0.5, half_over_g_sg = 0.5, over_sg = 1;  // 1/(2γ), 1/(2γ√γ), 1/√γ
  void set(double a_, double b_, double gamma) {
    a = a_, b = b_, g = gamma, sg = std::sqrt(gamma);
    half_over_g = 0.5 / g, half_over_g_sg = half_over_g / sg, over_sg = 1 / sg;
  }
  double primitive(double tau) const {
    const double over_q = 1 / (g + tau * tau);
    return a * (tau * half_over_g * over_q + fast_atan(tau * over_sg) * half_over_g_sg) -
           0.5 * b * over_q;
  }
  // ∫ over τ ∈ [t0, t1] where the light is above the horizon (a + b·τ > 0).
  double integral(double t0, double t1) const {
    if (b > 0) {
      t0 = std::max(t0, -a / b);
    } else if (b < 0) {
      t1 = std::min(t1, -a / b);
    } else if (a <= 0) {
      return 0;
    }
    if (!(t1 > t0)) return 0;
    return primitive(t1) - primitive(t0);
  }
};

// Where the line t = const crosses the convex polygon p (s from lo to hi; lo > hi: it misses).
std::pair<double, double> polygon_chord(const std::array<Vec2, 4>& p, double t) {
  double lo = kInfinity, hi = -kInfinity;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const Vec2& a = p[k];
    const Vec2& b = p[(k + 1) % p.size()];
    if ((a.y() - t) * (b.y() - t) > 0 || a.y() == b.y()) continue;
    const double x = a.x() + (t - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  return {lo, hi};
}

}  // namespace

PenumbraEstimator::PenumbraEstimator(const Light& light, int rows, double light_offset)
    : light_(&light),
      row_count_(std::clamp(rows, 1, LightRows::kMaxRows)),
      light_offset_(light_offset) {
  const double c = std::cos(kRowAngle), s = std::sin(kRowAngle);
  row_axis_s_ = c * light.right() + s * light.up();
  row_axis_t_ = -s * light.right() + c * light.up();
  // The light's outline in the turned frame, and each row's chord of it: where its centre line
  // crosses the outline, widened or narrowed about its middle to the band's exact area (a row
  // across a corner of a rectangle, or near a disk's rim, would weigh otherwise what its centre
  // line's chord says).
  const int n = row_count_;
  rows_.count = n;
  rows_.whole = true;
  const auto set_row = [&](int r, double lo, double hi, double area) {
    const double middle = 0.5 * (lo + hi), half = 0.5 * area / rows_.pitch;
    rows_.enter[std::size_t(r)] = middle - half;
    rows_.leave[std::size_t(r)] = middle + half;
  };
  // A rectangle's or polygon's corners (a triangle's last one twice: an edge of no length,
  // which no row crosses), relative to the centre.
  std::array<Vec3, 4> outline;
  if (light.outline(outline) > 0) {
    double t_min = kInfinity, t_max = -kInfinity;
    for (std::size_t k = 0; k < 4; ++k) {
      const Vec3 offset = outline[k] - light.centre();
      ball_radius_ = std::max(ball_radius_, offset.norm() * (1 + 1e-9));
      corners_[k] = Vec2(offset.dot(row_axis_s_), offset.dot(row_axis_t_));
      t_min = std::min(t_min, corners_[k].y());
      t_max = std::max(t_max, corners_[k].y());
    }
    rows_.pitch = (t_max - t_min) / n;
    rows_.first = t_min + 0.5 * rows_.pitch;
    for (int r = 0; r < n; ++r) {
      const double t = rows_.first + r * rows_.pitch;
      const auto [lo, hi] = polygon_chord(corners_, t);
      // The band's exact area: trapezoids between the corners within it.
      std::vector<double> cuts = {t - 0.5 * rows_.pitch, t + 0.5 * rows_.pitch};
      for (const Vec2& p : corners_)
        if (p.y() > cuts[0] && p.y() < cuts[1]) cuts.push_back(p.y());
      std::sort(cuts.begin(), cuts.end());
      double area = 0;
      for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
        const double a = std::max(cuts[k], t_min), b = std::min(cuts[k + 1], t_max);
        if (!(b > a)) continue;
        const auto [a0, a1] = polygon_chord(corners_, a);
        const auto [b0, b1] = polygon_chord(corners_, b);
        area += 0.5 * ((a1 - a0) + (b1 - b0)) * (b - a);
      }
      set_row(r, lo, hi, area);
    }
    return;
  }
  // A disk of radius R (a sphere's unit disk, scaled per texel): ∫ of its chord 2·√(R² − t²).
  const double radius = light.shape() == LightShape::disk ? light.desc().radius : 1.0;
  ball_radius_ = light.desc().radius * (1 + 1e-9);
  rows_.pitch = 2 * radius / n;
  rows_.first = -radius + 0.5 * rows_.pitch;
  const auto below = [&](double t) {
    t = std::clamp(t, -radius, radius);
    return t * std::sqrt(std::max(0.0, radius * radius - t * t)) +
           radius * radius * std::asin(t / radius);
  };
  for (int r = 0; r < n; ++r) {
    const double t = rows_.first + r * rows_.pitch;
    const double half = chord_half(t, radius);
    set_row(r, -half, half, below(t + 0.5 * rows_.pitch) - below(t - 0.5 * rows_.pitch));
  }
}

double PenumbraEstimator::chord_half(double t, double radius) const {
  return std::sqrt(std::max(0.0, radius * radius - t * t));
}

bool PenumbraEstimator::frame(const Vec3& position, LightFrame& f) const {
  const Light& light = *light_;
  if (light.shape() != LightShape::sphere) {
    f.centre = light.centre();
    f.normal = light.normal();
    f.s_axis = row_axis_s_;
    f.t_axis = row_axis_t_;
    f.radius = light.shape() == LightShape::disk ? light.desc().radius : 0.0;
    f.clip_height = light_offset_;
    f.ball_centre = light.centre();
    f.ball_radius = ball_radius_;
    return true;
  }
  // The silhouette of the sphere seen from the texel, as the reference samples it: a disk of
  // radius R·√(D² − R²)/D at (D² − R²)/D from it. Blockers are projected onto it from the ray
  // origin, whose shaft holds every ray from there to it outside the sphere (the origin's own
  // silhouette disk, the shaft's base, lies beyond the sphere's near side).
  const Vec3 to = light.centre() - position;
  const double dist = to.norm(), radius = light.desc().radius;
  if (!(dist > radius * (1 + 1e-9))) return false;
  const Vec3 axis = to / dist;
  f.centre = position + axis * ((dist * dist - radius * radius) / dist);
  f.normal = -axis;
  const Vec3 a = any_orthogonal(axis), b = axis.cross(a);
  const double c = std::cos(kRowAngle), s = std::sin(kRowAngle);
  f.s_axis = c * a + s * b;
  f.t_axis = -s * a + c * b;
  f.radius = radius * std::sqrt(std::max(0.0, dist * dist - radius * radius)) / dist;
  f.clip_height = 0;
  f.ball_centre = light.centre();
  f.ball_radius = ball_radius_;
  return true;
}

const LightRows& PenumbraEstimator::rows_for(const LightFrame& f, const Vec3& position,
                                             const Vec3& normal, LightRows& scratch) const {
  // The horizon in the light's plane: visible where α·s + β·t + γ > 0.
  const double alpha = normal.dot(f.s_axis), beta = normal.dot(f.t_axis);
  const double gamma = normal.dot(f.centre - position);
  const bool polygon =
      light_->shape() == LightShape::rectangle || light_->shape() == LightShape::polygon;
  bool cut = false;
  if (polygon) {
    for (const Vec2& p : corners_) cut = cut || alpha * p.x() + beta * p.y() + gamma < 0;
  } else {
    cut = gamma - f.radius * std::hypot(alpha, beta) < 0;
  }
  if (!cut && light_->shape() != LightShape::sphere) return rows_;
  scratch.count = row_count_;
  scratch.whole = !cut;
  if (!cut) {  // a sphere's unit rows, scaled to its silhouette
    scratch.pitch = rows_.pitch * f.radius;
    scratch.first = rows_.first * f.radius;
    for (int r = 0; r < row_count_; ++r) {
      scratch.enter[std::size_t(r)] = rows_.enter[std::size_t(r)] * f.radius;
      scratch.leave[std::size_t(r)] = rows_.leave[std::size_t(r)] * f.radius;
    }
    return scratch;
  }
  // The t-extent of the part above the horizon: its corners above it, and where the horizon's
  // line crosses the outline.
  double t_lo = kInfinity, t_hi = -kInfinity;
  const auto add = [&](const Vec2& p) {
    t_lo = std::min(t_lo, p.y());
    t_hi = std::max(t_hi, p.y());
  };
  const auto above = [&](const Vec2& p) { return alpha * p.x() + beta * p.y() + gamma >= 0; };
  if (polygon) {
    for (std::size_t k = 0; k < 4; ++k) {
      const Vec2& a = corners_[k];
      const Vec2& b = corners_[(k + 1) % 4];
      if (above(a)) add(a);
      const double da = alpha * a.x() + beta * a.y() + gamma;
      const double db = alpha * b.x() + beta * b.y() + gamma;
      if ((da < 0) != (db < 0)) add(a + (b - a) * (da / (da - db)));
    }
  } else {
    const double r = f.radius, norm2 = alpha * alpha + beta * beta;
    if (above(Vec2(0, r))) add(Vec2(0, r));
    if (above(Vec2(0, -r))) add(Vec2(0, -r));
    // Where the horizon's line meets the circle: the foot of the perpendicular from the centre,
    // ± along the line.
    const double d = -gamma / std::max(norm2, 1e-300);
    const Vec2 foot(alpha * d, beta * d);
    const double along2 = r * r - foot.squaredNorm();
    if (along2 >= 0 && norm2 > 0) {
      const Vec2 dir = Vec2(-beta, alpha) / std::sqrt(norm2);
      add(foot + std::sqrt(along2) * dir);
      add(foot - std::sqrt(along2) * dir);
    }
  }
  if (!(t_hi > t_lo)) {
    scratch.count = 0;
    return scratch;
  }
  scratch.pitch = (t_hi - t_lo) / row_count_;
  scratch.first = t_lo + 0.5 * scratch.pitch;
  for (int r = 0; r < row_count_; ++r) {
    const double t = scratch.first + r * scratch.pitch;
    double lo, hi;
    if (polygon) {
      std::tie(lo, hi) = polygon_chord(corners_, t);
    } else {
      hi = chord_half(t, f.radius);
      lo = -hi;
    }
    // Only the part above the horizon: the cells of a row then resolve what the texel sees of
    // it, however small a sliver of the chord that is.
    const double cut = beta * t + gamma;
    if (alpha > 0) {
      lo = std::max(lo, -cut / alpha);
    } else if (alpha < 0) {
      hi = std::min(hi, -cut / alpha);
    } else if (cut < 0) {
      hi = lo;
    }
    scratch.enter[std::size_t(r)] = lo;
    scratch.leave[std::size_t(r)] = std::max(lo, hi);
  }
  return scratch;
}

namespace {

// A row's exact intervals in order of their starts (insertion sort: a handful).
std::array<BlockedRows::Interval, kExactIntervals> sorted_intervals(const BlockedRows::Row& row) {
  std::array<BlockedRows::Interval, kExactIntervals> sorted;
  std::copy(row.intervals.begin(), row.intervals.begin() + std::min(row.count, kExactIntervals),
            sorted.begin());
  for (int k = 1; k < row.count; ++k)
    for (int j = k; j > 0 && sorted[std::size_t(j)] < sorted[std::size_t(j - 1)]; --j)
      std::swap(sorted[std::size_t(j)], sorted[std::size_t(j - 1)]);
  return sorted;
}

}  // namespace

// A texel in an umbra, most of what a sun's refinement evaluates, needs none of the rows'
// integrals.
bool every_row_hidden(const LightRows& rows, const BlockedRows& blocked) {
  for (int r = 0; r < rows.count; ++r) {
    const BlockedRows::Row& row = blocked.rows[std::size_t(r)];
    const double enter = rows.enter[std::size_t(r)], leave = rows.leave[std::size_t(r)];
    if (!(leave > enter)) continue;
    if (row.count == 0) return false;
    if (row.count > kExactIntervals) {
      if (row.cells != kAllCells) return false;
      continue;
    }
    const auto sorted = sorted_intervals(row);
    if (sorted[0].first > enter) return false;
    double to = sorted[0].second;
    for (int k = 1; k < row.count; ++k) {
      const auto [a, b] = sorted[std::size_t(k)];
      if (a > to && to < leave) return false;
      to = std::max(to, b);
    }
    if (to < leave) return false;
  }
  return true;
}

void PenumbraEstimator::integrate(const LightFrame& f, const LightRows& rows, const Vec3& position,
                                  const Vec3& normal, const BlockedRows& blocked,
                                  double form_factor, PenumbraSample& out) const {
  const double h = f.normal.dot(position - f.centre);  // the texel's height over the plane
  if (!(h > 0) || rows.count == 0) return;
  const Vec3 rel = position - f.centre;
  const double s_y = f.s_axis.dot(rel), t_y = f.t_axis.dot(rel);
  const double n_s = normal.dot(f.s_axis), n_t = normal.dot(f.t_axis);
  const double n_n = normal.dot(f.normal);
  const bool biased = weight_bias != 1.0;
  // Over the whole light, its closed-form F is the whole; over the part above the horizon, the
  // rows' own total is.
  const bool exact_total = !biased && rows.whole;
  if (exact_total && every_row_hidden(rows, blocked)) {
    const double f0 = form_factor > 0 ? form_factor : light_->form_factor(position, normal);
    if (!(f0 * std::numbers::pi / (h * rows.pitch) > 0)) return;
    out.contributes = true;
    out.visibility = 0.0;
    return;
  }
  double hidden = 0, total = 0;
  bool any = false, every = true;  // some part blocked; every row blocked from end to end
  for (int r = 0; r < rows.count; ++r) {
    const BlockedRows::Row& row = blocked.rows[std::size_t(r)];
    const double enter = rows.enter[std::size_t(r)], leave = rows.leave[std::size_t(r)];
    if (!(leave > enter) || (row.count == 0 && exact_total)) {
      every = every && !(leave > enter);
      continue;
    }
    const double dt = rows.first + r * rows.pitch - t_y;
    RowWeight w;
    w.set(n_t * dt - h * n_n, n_s, h * h + dt * dt);
    // ∫ over [s0, s1] (light coordinates), with the test's bias on s > 0.
    const auto integral = [&](double s0, double s1) {
      if (!biased || s1 <= 0) return w.integral(s0 - s_y, s1 - s_y);
      if (s0 >= 0) return weight_bias * w.integral(s0 - s_y, s1 - s_y);
      return w.integral(s0 - s_y, -s_y) + weight_bias * w.integral(-s_y, s1 - s_y);
    };
    if (!exact_total) total += integral(enter, leave);
    if (row.count == 0) {
      every = false;
    } else if (row.count <= kExactIntervals) {
      // The union of the intervals, swept in order of their starts, within the row's chord.
      const auto sorted = sorted_intervals(row);
      double from = sorted[0].first, to = sorted[0].second;
      bool whole = from <= enter;
      const auto close = [&] {
        const double a = std::max(from, enter), b = std::min(to, leave);
        if (b > a) {
          hidden += integral(a, b);
          any = true;
        }
      };
      for (int k = 1; k < row.count; ++k) {
        const auto [a, b] = sorted[std::size_t(k)];
        if (a > to) {
          whole = whole && to >= leave;
          close();
          from = a;
        }
        to = std::max(to, b);
      }
      whole = whole && to >= leave;
      close();
      every = every && whole;
    } else if (row.cells == kAllCells) {
      hidden += integral(enter, leave);
      any = true;
    } else {
      const double cell = (leave - enter) / kCells;
      std::uint64_t shut = row.cells;
      every = false;
      any = any || shut != 0;
      while (shut) {
        const int from = std::countr_zero(shut);
        const std::uint64_t rest = shut >> from;
        const int length = rest == kAllCells ? kCells - from : std::countr_zero(~rest);
        const int to = from + length;
        hidden += integral(from == 0 ? enter : enter + from * cell,
                           to == kCells ? leave : enter + to * cell);
        shut &= to == kCells ? 0 : (kAllCells << to);
      }
    }
  }
  // The rows' integrand is cosθ_texel/ℓ³ · (h/ℓ) / h: F = h/π · Σ_rows ∫ · pitch.
  const double whole_rows =
      exact_total ? (form_factor > 0 ? form_factor : light_->form_factor(position, normal)) *
                        std::numbers::pi / (h * rows.pitch)
                  : total;
  if (!(whole_rows > 0)) return;
  out.contributes = true;
  out.visibility = every ? 0.0 : any ? std::clamp(1.0 - hidden / whole_rows, 0.0, 1.0) : 1.0;
}

PenumbraSample PenumbraEstimator::visibility(const Vec3& position, const Vec3& normal,
                                             const Vec3& origin, const Blockers& blockers,
                                             double form_factor,
                                             std::vector<std::uint32_t>* blocking) const {
  PenumbraSample out;
  out.nearest_blocker = kInfinity;
  LightFrame f;
  if (!frame(position, f)) return out;
  LightRows scratch;
  const LightRows& rows = rows_for(f, position, normal, scratch);
  BlockedRows blocked(rows.count);
  if (blocking) blocking->clear();
  const RasterTarget target{&f,       &rows, origin,  position, normal, light_offset_,
                            &blocked, &out,  blocking};
  // Behind a wall of many polygons, the nearest few may hide all of the light: V is 0, and the
  // rest need not be rasterised (OpenArena's oacmpdm9: texels in shafts of a hundred polygons,
  // each cut and projected, where the nearest wall's few hide the light). Only where the whole
  // light is integrated (V = 0 is then exact).
  const bool hidden_by_nearest = blockers.centre_hidden && rows.whole && weight_bias == 1.0 &&
                                 nearest_hide_all(target, blockers, kNearestFewest, kNearestFirst);
  if (!hidden_by_nearest) {
    static const std::vector<BlockerPolygon> no_polygons;
    static const std::vector<BlockerSolidRef> no_solids;
    rasterise_polygons_and_solids(target, blockers.polygons ? *blockers.polygons : no_polygons,
                                  blockers.solids ? *blockers.solids : no_solids);
    if (blockers.outlines)
      for (const BlockerOutline& outline : *blockers.outlines) rasterise_outline(target, outline);
  }
  if (blocking) {
    std::sort(blocking->begin(), blocking->end());
    blocking->erase(std::unique(blocking->begin(), blocking->end()), blocking->end());
  }
  integrate(f, rows, position, normal, blocked, form_factor, out);
  return out;
}

PenumbraSample PenumbraEstimator::visibility_traced(const Vec3& position, const Vec3& normal,
                                                    const Vec3& origin, const RayScene& scene,
                                                    double form_factor) const {
  PenumbraSample out;
  LightFrame f;
  if (!frame(position, f)) return out;
  LightRows scratch;
  const LightRows& rows = rows_for(f, position, normal, scratch);
  // One ray per pair of cells, to the middle of the pair on the row's centre line, stopping the
  // surface offset short of the light's surface (a sphere's near side).
  constexpr int kPairs = kCells / 2;
  const int n = rows.count;
  std::vector<Vec3> origins(std::size_t(n) * kPairs, origin), directions(origins.size());
  std::vector<double> lengths(origins.size(), 0.0);
  std::vector<std::uint8_t> hits(origins.size(), 0);
  const double offset = std::max(light_offset_, scene.surface_offset());
  const double radius = light_->desc().radius;
  for (int r = 0; r < n; ++r) {
    const double t = rows.first + r * rows.pitch;
    const double enter = rows.enter[std::size_t(r)];
    const double cell = (rows.leave[std::size_t(r)] - enter) / kCells;
    for (int k = 0; k < kPairs; ++k) {
      const std::size_t i = std::size_t(r) * kPairs + std::size_t(k);
      const Vec3 x = f.centre + (enter + (2 * k + 1) * cell) * f.s_axis + t * f.t_axis;
      Vec3 d = x - origin;
      if (light_->shape() == LightShape::sphere) {
        // The point of the sphere the texel sees through x, on its near side (where the
        // reference aims: Light::above_horizon's samples), before the silhouette's plane.
        const Vec3 e = x - position, pc = position - light_->centre();
        const double a = e.squaredNorm(), b = pc.dot(e), c = pc.squaredNorm() - radius * radius;
        const double disc = b * b - a * c;
        if (disc > 0) d = position + std::clamp((-b - std::sqrt(disc)) / a, 0.0, 1.0) * e - origin;
      }
      const double norm = d.norm();
      directions[i] = d;
      lengths[i] = norm > 2 * offset ? 1 - offset / norm : 0.0;
    }
  }
  scene.occluded(int(origins.size()), origins.data(), directions.data(), lengths.data(),
                 hits.data());
  // How near the nearest blocker lies tells the refinement how narrow a penumbra may be here:
  // from the nearest hits of one ray in 16 (every 4th row, every 4th pair) that are blocked.
  std::vector<Vec3> probe_origins, probe_directions;
  std::vector<double> probe_lengths;
  for (int r = 0; r < n; r += 4)
    for (int k = 0; k < kPairs; k += 4) {
      const std::size_t i = std::size_t(r) * kPairs + std::size_t(k);
      if (!hits[i]) continue;
      probe_origins.push_back(origins[i]);
      probe_directions.push_back(directions[i]);
      probe_lengths.push_back(lengths[i]);
    }
  std::vector<double> t_hit(probe_origins.size(), -1.0);
  scene.first_hit(int(probe_origins.size()), probe_origins.data(), probe_directions.data(),
                  probe_lengths.data(), t_hit.data());
  out.nearest_blocker = kInfinity;
  for (std::size_t i = 0; i < t_hit.size(); ++i)
    if (t_hit[i] >= 0)
      out.nearest_blocker = std::min(out.nearest_blocker, t_hit[i] * probe_directions[i].norm());
  BlockedRows blocked(n);
  for (int r = 0; r < n; ++r) {
    BlockedRows::Row& row = blocked.rows[std::size_t(r)];
    row.count = kExactIntervals + 1;
    for (int k = 0; k < kPairs; ++k)
      if (hits[std::size_t(r) * kPairs + std::size_t(k)]) row.cells |= std::uint64_t(3) << (2 * k);
  }
  integrate(f, rows, position, normal, blocked, form_factor, out);
  return out;
}

}  // namespace sb
