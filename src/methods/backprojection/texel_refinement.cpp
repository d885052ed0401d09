// Adaptive texel sampling (texel_refinement.h).
//
// A cell is a square of S × S texels of the lightmap (S = 8, 4, 2) that owns the texels
// [x0, x0 + S) × [y0, y0 + S); its samples are its four corners (lattice points of spacing S,
// shared with its neighbours) and its centre. Cells start as the shaft tiles that are neither
// clear nor an umbra (valued 1 and 0 without samples; an umbra's texels that are a cell's corners
// are evaluated as its samples), level by level: the samples of every cell of a level are
// evaluated exactly (in parallel, each once), then each cell either interpolates the texels it
// owns or splits into four. A cell interpolates
// only when
//   1. its five samples are all valued (covered, reached by the light);
//   2. the centre's exact V is within `tolerance` of the mean of the corners, the bilinear
//      prediction there (a kink — the edge of a penumbra or umbra — crossing a cell where the
//      field is otherwise flat moves the centre by at least half the error it causes anywhere
//      in the cell; 5 covers a field that is not flat);
//   3. its texels lie on one smooth piece of surface: its sides on the surface within a factor 3
//      of each other, each texel within `position_texels` (of the shorter side's texels) of the
//      bilinear surface through the corners' positions and with a normal within 15° of the
//      centre's (no UV chart border, crease or horizon change inside);
//   4. no blocker reaches a texel's shaft that no sample saw (a thin post standing between the
//      samples would otherwise vanish), and every blocker the samples saw is far enough from the
//      cell that no penumbra it casts is narrower than `feature_cells` cells: a blocker at
//      distance d from a texel casts a penumbra at least d·θ wide (θ the light's narrowest
//      apparent width), so shadows near contact refine down to single texels; unless all five
//      samples lie in the umbra of one convex solid or one triangle (PairSource::
//      one_triangle_hides), or all five are 0 and a ball inside a closed blocker they saw hides
//      the light from every texel's ray origin (PairSource::ball_hides): a convex blocker's
//      umbra under a convex light is convex, so every texel between them lies in it, however
//      near.
//   5. where the penumbra bound of 4 is under `midpoint_cells` cells (a penumbra's edge may be
//      near), its four edge midpoints are evaluated too, each within `tolerance` of the mean of
//      its edge's corners: a kink along one axis can cancel at the centre against the field's
//      curvature along the other (the cells simulated on the closed form: a centre 0.0018 from its
//      prediction over a texel 0.012 off), but not at both midpoints of the edges it crosses as
//      well. A cell that splits reuses them as its children's corners.
// Inside a cell that passes, V is interpolated linearly over the four triangles the centre makes
// with the cell's sides, so it is exact at all five samples and continuous across cells. Texels
// of a cell that fails at S = 2 are each evaluated. Every decision depends on exact values and
// the geometry alone, so the result is the same for any thread count and from run to run; and a
// cell's checks read all the texels it owns, whether or not a neighbour's samples valued some of
// them already, so its decisions depend on its own samples and texels alone: a texel's value
// depends on its tile and the tiles above, left and below it (their cells' corners), which is what
// lets a tile of rows be baked apart from the rest (pipeline/tiles.h).
#include "methods/backprojection/texel_refinement.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>

namespace sb {

namespace {

enum State : std::uint8_t { kUnknown, kQueued, kValued };

struct Cell {
  int x0 = 0, y0 = 0, size = 0;
};

// One light's refinement over one receiver (refine_light): the tiles' places, the texels' state
// and samples, and the steps of the file's opening comment, each a member.
class Refinement {
 public:
  static constexpr int kTile = TileShafts::kTile;
  using Kind = TileShafts::Kind;

  Refinement(const TexelSpace& space, const TexelGrid& grid, const TileShafts& tiles,
             const PairSource& source, const RefinementSettings& settings)
      : space_(space), grid_(grid), tiles_(tiles), source_(source), settings_(settings) {}

  // The tiles' places in the field, and every texel's first value and state.
  void place_tiles();
  void first_writes();
  // The first cells: the tiles that are neither clear nor empty, cut to cells of max_cell.
  std::vector<Cell> first_cells() const;
  // One level: the cells' samples evaluated, each cell interpolated or split; its children.
  std::vector<Cell> refine_level(const std::vector<Cell>& cells);
  // Every texel the light reaches that no cell valued (cells of 2 that failed; tiles of a
  // lightmap too small for one cell): evaluated, in the order of the tiles' places.
  void evaluate_rest();

  LightField field;

 private:
  struct Queued {
    std::size_t texel, place;
  };
  // Whether cell c may interpolate the texels it owns (the file's opening comment, 1–4): kFail,
  // kPass, or kMidpoints where it may once its edge midpoints agree (5).
  enum Verdict : std::uint8_t { kFail, kPass, kMidpoints };

  Kind kind_at(int tx, int ty) const {
    return tx < 0 || ty < 0 ? Kind::empty
                            : tiles_.kind[std::size_t(ty) * std::size_t(tiles_.tiles_x) + tx];
  }
  bool cells_in(int tx, int ty) const {
    const Kind kind = kind_at(tx, ty);
    return kind == Kind::listed || kind == Kind::all;
  }
  // Whether the light reaches the texel at pixel (x, y), `t` (-1: none is covered there).
  bool is_reached(std::int32_t t, int x, int y) const { return t >= 0 && tiles_.reached_at(x, y); }
  bool is_reached(int x, int y) const { return is_reached(grid_.texel(x, y), x, y); }
  // A texel's place in the arrays: every texel a cell's checks read has one (the cells' own, and
  // their corners but clear ones, which are valued and hold what `none_` holds, and the
  // uncovered or unreached ones, which no check reads past `reached`).
  std::int64_t place(int x, int y) const { return field.index(x, y); }
  const PairSample& sample_at(std::int64_t at) const {
    return at < 0 || sample_of_[std::size_t(at)] < 0
               ? none_
               : samples_[std::size_t(sample_of_[std::size_t(at)])];
  }
  // Whether a covered texel the light reaches is valued (one without a place is: a clear tile's).
  bool valued(std::int64_t at) const { return at < 0 || state_[std::size_t(at)] == kValued; }
  double visibility(int x, int y) const { return double(field.visibility_at(x, y)); }

  void enqueue(int x, int y, bool umbra_too, std::vector<Queued>& queue);
  void evaluate_all(const std::vector<Queued>& queue);
  Verdict verdict(const Cell& c) const;
  Verdict blockers_verdict(const Cell& c, const std::array<std::int32_t, 5>& at,
                           const std::array<std::int64_t, 5>& places, bool all_zero,
                           const Bounds3& box, double texel_extent) const;
  bool midpoints_agree(const Cell& c) const;
  bool settled(const Cell& c) const;
  void interpolate(const Cell& c);

  const TexelSpace& space_;
  const TexelGrid& grid_;
  const TileShafts& tiles_;
  const PairSource& source_;
  const RefinementSettings& settings_;
  std::vector<std::size_t> slotted_;  // the tiles with a place, in order of it
  FreshVector<std::uint8_t> state_;
  // The evaluated texels' samples, in order of evaluation (a level's at a time), and each
  // texel's: what the cells' checks read beyond V.
  std::vector<PairSample> samples_;
  FreshVector<std::int32_t> sample_of_;
  const PairSample none_;  // what a texel valued without evaluation (clear tile) holds
};

// Which tiles hold their texels' own values (LightField): the cells' tiles, the umbrae right of,
// below or below-right of one (their texels are its cells' corners, evaluated), and the clear and
// umbra tiles the light reaches in part (a covered texel of theirs is not reached).
void Refinement::place_tiles() {
  const std::size_t tile_count = tiles_.kind.size();
  // A tile the light reaches (its kind not empty) holding a covered texel it does not reach.
  const auto partly = [&](std::size_t i) {
    const int x0 = int(i % std::size_t(tiles_.tiles_x)) * kTile;
    const int y0 = int(i / std::size_t(tiles_.tiles_x)) * kTile;
    std::uint64_t covered = 0;
    for (int j = 0; j < kTile * kTile; ++j)
      if (grid_.texel(x0 + j % kTile, y0 + j / kTile) >= 0) covered |= std::uint64_t(1) << j;
    return (covered & ~tiles_.reached[i]) != 0;
  };
  field.tiles_x = tiles_.tiles_x;
  field.slot.assign(tile_count, -1);
  field.tile_route.assign(tile_count, TexelRoute::none);
  for (int ty = 0; ty < tiles_.tiles_y; ++ty)
    for (int tx = 0; tx < tiles_.tiles_x; ++tx) {
      const std::size_t i = std::size_t(ty) * std::size_t(tiles_.tiles_x) + tx;
      const Kind kind = tiles_.kind[i];
      const bool corners = kind == Kind::umbra && (cells_in(tx - 1, ty) || cells_in(tx, ty - 1) ||
                                                   cells_in(tx - 1, ty - 1));
      if (cells_in(tx, ty) || corners || (kind != Kind::empty && partly(i))) {
        field.slot[i] = std::int32_t(slotted_.size());
        slotted_.push_back(i);
      } else {
        field.tile_route[i] = kind == Kind::clear   ? TexelRoute::clear
                              : kind == Kind::umbra ? TexelRoute::umbra
                                                    : TexelRoute::none;
      }
    }
}

// Every array's first write, tile by tile: the clear tiles' reached texels are clear (1) and
// valued, the umbrae's umbra (0) and valued, the rest unknown.
void Refinement::first_writes() {
  const std::size_t n = slotted_.size() * std::size_t(kTile * kTile);
  field.visibility.resize(n);
  field.route.resize(n);
  state_.resize(n);
  sample_of_.resize(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, slotted_.size(), 64), [&](const auto& r) {
    for (std::size_t s = r.begin(); s != r.end(); ++s) {
      const std::size_t tile = slotted_[s];
      const int x0 = int(tile % std::size_t(tiles_.tiles_x)) * kTile;
      const int y0 = int(tile / std::size_t(tiles_.tiles_x)) * kTile;
      for (int j = 0; j < kTile * kTile; ++j) {
        const bool lit = is_reached(x0 + j % kTile, y0 + j / kTile);
        // The texel's own patch's kind (a tile's patches may differ).
        const Kind kind = lit ? tiles_.kind_at(x0 + j % kTile, y0 + j / kTile) : Kind::empty;
        const bool clear = lit && kind == Kind::clear, umbra = lit && kind == Kind::umbra;
        const std::size_t i = s * std::size_t(kTile * kTile) + std::size_t(j);
        field.visibility[i] = umbra ? 0.0f : 1.0f;
        field.route[i] = clear ? TexelRoute::clear : umbra ? TexelRoute::umbra : TexelRoute::none;
        state_[i] = clear || umbra ? kValued : kUnknown;
        sample_of_[i] = -1;
      }
    }
  });
}

std::vector<Cell> Refinement::first_cells() const {
  std::vector<Cell> cells;
  const int top = std::min(settings_.max_cell, kTile);
  if (top < 2) return cells;  // max_cell 1: every texel is evaluated (evaluate_rest)
  for (int ty = 0; ty < tiles_.tiles_y; ++ty)
    for (int tx = 0; tx < tiles_.tiles_x; ++tx) {
      if (!cells_in(tx, ty)) continue;
      for (int y = 0; y < kTile; y += top)
        for (int x = 0; x < kTile; x += top) cells.push_back({tx * kTile + x, ty * kTile + y, top});
    }
  return cells;
}

// Queues the texel at (x, y) for evaluation unless it is queued or valued exactly already: an
// interpolated one is evaluated now, and, where a sample's blockers are needed beside V (a cell's
// corners and centre), an umbra tile's too. A clear tile's is skipped: valued, and holding what a
// sample would.
void Refinement::enqueue(int x, int y, bool umbra_too, std::vector<Queued>& queue) {
  const std::int32_t t = grid_.texel(x, y);
  if (!is_reached(t, x, y)) return;
  const std::int64_t at = place(x, y);
  if (at < 0 || state_[std::size_t(at)] == kQueued) return;
  const TexelRoute route = field.route[std::size_t(at)];
  if (state_[std::size_t(at)] == kValued && route != TexelRoute::interpolated &&
      !(umbra_too && route == TexelRoute::umbra))
    return;
  state_[std::size_t(at)] = kQueued;
  queue.push_back({std::size_t(t), std::size_t(at)});
}

void Refinement::evaluate_all(const std::vector<Queued>& queue) {
  const std::size_t first = samples_.size();
  samples_.resize(first + queue.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queue.size(), 8), [&](const auto& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const auto [t, at] = queue[i];
      PairSample& sample = samples_[first + i];
      source_.evaluate(t, sample);
      field.visibility[at] = sample.visibility;
      field.route[at] = sample.route;
      sample_of_[at] = std::int32_t(first + i);
      state_[at] = kValued;
    }
  });
}

// Checks 1–3 of the file's opening comment, then blockers_verdict for 4 and 5.
Refinement::Verdict Refinement::verdict(const Cell& c) const {
  const int s = c.size, h = s / 2;
  const std::array<int, 5> xs = {c.x0, c.x0 + s, c.x0, c.x0 + s, c.x0 + h};
  const std::array<int, 5> ys = {c.y0, c.y0, c.y0 + s, c.y0 + s, c.y0 + h};
  std::array<std::int32_t, 5> at;
  std::array<std::int64_t, 5> places;
  for (std::size_t k = 0; k < 5; ++k) {
    at[k] = grid_.texel(xs[k], ys[k]);
    if (!is_reached(at[k], xs[k], ys[k])) return kFail;
    places[k] = place(xs[k], ys[k]);
    if (!valued(places[k])) return kFail;
  }
  const auto v = [&](int k) { return visibility(xs[std::size_t(k)], ys[std::size_t(k)]); };
  if (std::abs(v(4) - 0.25 * (v(0) + v(1) + v(2) + v(3))) > settings_.tolerance) return kFail;
  // One smooth piece of surface.
  const auto pos = [&](int k) {
    return Vec3(space_.texels[std::size_t(at[std::size_t(k)])].position.cast<double>());
  };
  const Vec3 p00 = pos(0), p10 = pos(1), p01 = pos(2), p11 = pos(3);
  // The cell's sides on the surface: much unequal, a corner lies across a chart border.
  const double side_min =
      std::min({(p10 - p00).norm(), (p01 - p00).norm(), (p11 - p10).norm(), (p11 - p01).norm()});
  const double side_max =
      std::max({(p10 - p00).norm(), (p01 - p00).norm(), (p11 - p10).norm(), (p11 - p01).norm()});
  if (!(side_max <= 3 * side_min)) return kFail;
  const double texel_size = side_min / s;
  const Vec3f centre_normal = space_.texels[std::size_t(at[4])].normal;
  for (int k = 0; k < 4; ++k)
    if (space_.texels[std::size_t(at[std::size_t(k)])].normal.dot(centre_normal) <
        settings_.normal_cos)
      return kFail;
  Bounds3 box;
  for (int k = 0; k < 5; ++k) box.extend(pos(k));
  for (int y = c.y0; y < c.y0 + s; ++y)
    for (int x = c.x0; x < c.x0 + s; ++x) {
      const std::int32_t t = grid_.texel(x, y);
      if (!is_reached(t, x, y)) continue;
      const Texel& tx = space_.texels[std::size_t(t)];
      const double u = double(x - c.x0) / s, w = double(y - c.y0) / s;
      const Vec3 bilinear = (1 - w) * ((1 - u) * p00 + u * p10) + w * ((1 - u) * p01 + u * p11);
      const Vec3 p = tx.position.cast<double>();
      if ((p - bilinear).norm() > settings_.position_texels * texel_size) return kFail;
      if (tx.normal.dot(centre_normal) < settings_.normal_cos) return kFail;
      box.extend(p);
    }
  const bool all_zero = v(0) == 0 && v(1) == 0 && v(2) == 0 && v(3) == 0 && v(4) == 0;
  return blockers_verdict(c, at, places, all_zero, box, side_max / s);
}

// Checks 4 and 5 for a cell whose samples `at` (texels; `places` in the field) passed 1–3, all
// of them 0 or not, `box` bounding its texels and samples, `texel_extent` its longer side's texel
// on the surface.
Refinement::Verdict Refinement::blockers_verdict(const Cell& c,
                                                 const std::array<std::int32_t, 5>& at,
                                                 const std::array<std::int64_t, 5>& places,
                                                 bool all_zero, const Bounds3& box,
                                                 double texel_extent) const {
  const int s = c.size;
  // In the umbra of one convex solid (or one polygon) at all five samples: so is every point
  // between them (a convex blocker's umbra under a convex light is convex), whatever the
  // distance.
  const std::uint32_t umbra = sample_at(places[0]).umbra;
  bool one_umbra = umbra != none_.umbra;
  for (std::size_t k = 1; k < 5; ++k) one_umbra = one_umbra && sample_at(places[k]).umbra == umbra;
  if (one_umbra) return kPass;
  // Every blocker the samples saw, far enough away for penumbrae at least feature_cells wide:
  // a texel of the cell lies at most its diagonal nearer to a blocker than the sample that saw
  // it (and every blocker of the cell's texels is one a sample saw, below).
  std::vector<std::uint32_t> seen;
  double width = std::numeric_limits<double>::infinity();
  double distance = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < 5; ++k) {
    const PairSample& sample = sample_at(places[k]);
    seen.insert(seen.end(), sample.triangles.begin(), sample.triangles.end());
    width = std::min(width, source_.angular_width(std::size_t(at[k])));
    distance = std::min(distance, double(sample.nearest));
  }
  std::sort(seen.begin(), seen.end());
  seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
  thread_local std::vector<std::size_t> inside;  // the texels the cell owns that are reached
  inside.clear();
  for (int y = c.y0; y < c.y0 + s; ++y)
    for (int x = c.x0; x < c.x0 + s; ++x) {
      const std::int32_t t = grid_.texel(x, y);
      if (is_reached(t, x, y)) inside.push_back(std::size_t(t));
    }
  // All five 0, and every texel in the umbra of a ball inside one closed blocker they saw
  // (a tree crown, lumpy, that no one of its facets hides the light behind), or all five in
  // the umbra of one triangle of what they saw (a crown's facet over its shadow): whatever
  // the distance, as above.
  if (all_zero) {
    if (source_.ball_hides(inside, seen)) return kPass;
    std::array<std::size_t, 5> points;
    for (std::size_t k = 0; k < 5; ++k) points[k] = std::size_t(at[k]);
    if (source_.one_triangle_hides(points, seen)) return kPass;
  }
  // The narrowest penumbra a blocker the samples saw may cast on the cell, in cells.
  const double penumbra_cells = std::isfinite(distance)
                                    ? (distance - box.diagonal()) * width / (s * texel_extent)
                                    : std::numeric_limits<double>::infinity();
  if (penumbra_cells < settings_.feature_cells) return kFail;
  const Verdict near = penumbra_cells < settings_.midpoint_cells ? kMidpoints : kPass;
  // A sample traced past the estimator's budget lists nothing: the distance bound above is
  // all there is to go on.
  for (std::size_t k = 0; k < 5; ++k)
    if (!sample_at(places[k]).listed) return near;
  return source_.sees_unlisted(inside, seen) ? kFail : near;
}

// A cell's edge midpoints (5), each with its edge's two corners: (x, y) of the three.
std::array<std::array<int, 6>, 4> edges(const Cell& c) {
  const int s = c.size, h = s / 2, x0 = c.x0, y0 = c.y0;
  return {{{x0 + h, y0, x0, y0, x0 + s, y0},
           {x0, y0 + h, x0, y0, x0, y0 + s},
           {x0 + s, y0 + h, x0 + s, y0, x0 + s, y0 + s},
           {x0 + h, y0 + s, x0, y0 + s, x0 + s, y0 + s}}};
}

// Whether each edge midpoint is valued and within `tolerance` of its edge's corners' mean, the
// interpolation's value there (linear along the cell's sides).
bool Refinement::midpoints_agree(const Cell& c) const {
  for (const auto& [mx, my, ax, ay, bx, by] : edges(c)) {
    if (!is_reached(mx, my) || !valued(place(mx, my))) return false;
    if (std::abs(visibility(mx, my) - 0.5 * (visibility(ax, ay) + visibility(bx, by))) >
        settings_.tolerance)
      return false;
  }
  return true;
}

// Linear over the four triangles the centre makes with the cell's sides.
void Refinement::interpolate(const Cell& c) {
  const int s = c.size, h = s / 2;
  const double v00 = visibility(c.x0, c.y0), v10 = visibility(c.x0 + s, c.y0);
  const double v01 = visibility(c.x0, c.y0 + s), v11 = visibility(c.x0 + s, c.y0 + s);
  const double vc = visibility(c.x0 + h, c.y0 + h);
  for (int y = c.y0; y < c.y0 + s; ++y)
    for (int x = c.x0; x < c.x0 + s; ++x) {
      const std::size_t at = std::size_t(place(x, y));  // the cell's own: its tile has one
      if (!is_reached(x, y) || state_[at] == kValued) continue;
      const double u = double(x - c.x0) / s, w = double(y - c.y0) / s;
      // (a, b, corner_a, corner_b): the triangle's coordinates and its two corners, so that
      // V = 2b·vc + (a − b)·corner_b + (1 − a − b)·corner_a.
      double a, b, ca, cb;
      if (w <= u && w <= 1 - u) {
        a = u, b = w, ca = v00, cb = v10;
      } else if (u >= w && u >= 1 - w) {
        a = w, b = 1 - u, ca = v10, cb = v11;
      } else if (w >= u && w >= 1 - u) {
        a = 1 - u, b = 1 - w, ca = v11, cb = v01;
      } else {
        a = 1 - w, b = u, ca = v01, cb = v00;
      }
      const double v = 2 * b * vc + (a - b) * cb + (1 - a - b) * ca;
      field.visibility[at] = float(std::clamp(v, 0.0, 1.0));
      field.route[at] = TexelRoute::interpolated;
    }
}

// Whether every texel the light reaches that cell c owns is valued exactly already (a clear or
// umbra patch's, tile_shafts.h): the cell has nothing to interpolate, and its samples need not
// be evaluated (a cell beside it evaluates the corners it shares when it needs them).
bool Refinement::settled(const Cell& c) const {
  for (int y = c.y0; y < c.y0 + c.size; ++y)
    for (int x = c.x0; x < c.x0 + c.size; ++x) {
      if (!is_reached(x, y)) continue;
      const std::size_t at = std::size_t(place(x, y));
      if (state_[at] != kValued || field.route[at] == TexelRoute::interpolated) return false;
    }
  return true;
}

std::vector<Cell> Refinement::refine_level(const std::vector<Cell>& given) {
  std::vector<Cell> cells;
  for (const Cell& c : given)
    if (!settled(c)) cells.push_back(c);
  // Their samples, each evaluated once.
  std::vector<Queued> queue;
  for (const Cell& c : cells) {
    const int h = c.size / 2;
    const int xs[5] = {c.x0, c.x0 + c.size, c.x0, c.x0 + c.size, c.x0 + h};
    const int ys[5] = {c.y0, c.y0, c.y0 + c.size, c.y0 + c.size, c.y0 + h};
    for (int k = 0; k < 5; ++k) enqueue(xs[k], ys[k], true, queue);
  }
  evaluate_all(queue);
  // Each cell interpolates what it owns, or splits.
  std::vector<std::uint8_t> pass(cells.size(), kFail);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells.size(), 4), [&](const auto& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) pass[i] = verdict(cells[i]);
  });
  // The edge midpoints of the cells that ask for them, each evaluated once (V alone is read
  // there), then their check.
  std::vector<Queued> midpoints;
  for (std::size_t i = 0; i < cells.size(); ++i)
    if (pass[i] == kMidpoints)
      for (const auto& e : edges(cells[i])) enqueue(e[0], e[1], false, midpoints);
  evaluate_all(midpoints);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells.size(), 16), [&](const auto& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i)
      if (pass[i] == kMidpoints) pass[i] = midpoints_agree(cells[i]) ? kPass : kFail;
  });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells.size(), 16), [&](const auto& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i)
      if (pass[i]) interpolate(cells[i]);
  });
  std::vector<Cell> next;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    if (pass[i]) continue;
    const Cell& c = cells[i];
    if (c.size == 2) continue;  // its texels are evaluated one by one, by evaluate_rest
    const int h = c.size / 2;
    for (int q = 0; q < 4; ++q) next.push_back({c.x0 + (q & 1) * h, c.y0 + (q >> 1) * h, h});
  }
  // Mark what the cells that passed interpolated as valued, for the next level's checks.
  for (std::size_t i = 0; i < cells.size(); ++i) {
    if (!pass[i]) continue;
    const Cell& c = cells[i];
    for (int y = c.y0; y < c.y0 + c.size; ++y)
      for (int x = c.x0; x < c.x0 + c.size; ++x) {
        const std::size_t at = std::size_t(place(x, y));
        if (field.route[at] == TexelRoute::interpolated) state_[at] = kValued;
      }
  }
  return next;
}

void Refinement::evaluate_rest() {
  std::vector<Queued> rest;
  for (std::size_t s = 0; s < slotted_.size(); ++s) {
    const int x0 = int(slotted_[s] % std::size_t(tiles_.tiles_x)) * kTile;
    const int y0 = int(slotted_[s] / std::size_t(tiles_.tiles_x)) * kTile;
    for (int j = 0; j < kTile * kTile; ++j) {
      const std::int32_t t = grid_.texel(x0 + j % kTile, y0 + j / kTile);
      const std::size_t at = s * std::size_t(kTile * kTile) + std::size_t(j);
      if (is_reached(t, x0 + j % kTile, y0 + j / kTile) && state_[at] != kValued)
        rest.push_back({std::size_t(t), at});
    }
  }
  evaluate_all(rest);
}

}  // namespace

LightField refine_light(const TexelSpace& space, const TexelGrid& grid, const TileShafts& tiles,
                        const PairSource& source, const RefinementSettings& settings) {
  Refinement refinement(space, grid, tiles, source, settings);
  refinement.place_tiles();
  refinement.first_writes();
  // Level by level, cells of max_cell texels down to 2.
  for (std::vector<Cell> cells = refinement.first_cells(); !cells.empty();)
    cells = refinement.refine_level(cells);
  refinement.evaluate_rest();
  return std::move(refinement.field);
}

}  // namespace sb
