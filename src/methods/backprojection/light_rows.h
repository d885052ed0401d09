// The back-projection estimator's working types (penumbra_estimator.cpp): rows across a light,
// a light seen from one texel (its plane and turned frame), and what the blockers hide of each of
// its rows; and the rasterisers that fill them (blocker_rasteriser.cpp: polygons and convex solids
// one by one; outline_rasteriser.cpp: many triangles at once through the outline of their union).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "core/geometry.h"
#include "methods/backprojection/shaft_blockers.h"

namespace sb {

// Rows across (the visible part of) a light, in the light's turned frame (s across rows, t along
// the frame): row r's centre line is t = first + r·pitch, and it crosses the light from `enter`
// to `leave` (s). Metres, but for a sphere's own rows, which are those of the unit disk.
struct LightRows {
  static constexpr int kMaxRows = 64;
  static constexpr int kCells = 64;  // a row falls back to cells (one bit each) past a few polygons
  int count = 0;
  double pitch = 0, first = 0;
  bool whole = true;  // across the whole light; false: across the part above a texel's horizon
  std::array<double, kMaxRows> enter, leave;  // rows [0, count) written
};

constexpr int kCells = LightRows::kCells;
constexpr std::uint64_t kAllCells = ~std::uint64_t(0);
// Intervals a row keeps exactly before it falls back to cells: the rows of a shaft with a few
// polygons are exact, those of a dense mesh's many are cells.
constexpr int kExactIntervals = 6;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The height over the light's plane above which a blocker point lies behind a ray origin at
// height `h_origin`: a hair below it, far less than the start every ray skips (`light_offset`,
// RayScene::surface_offset), so that nothing a ray may meet is cut (a relative margin of 1e-9
// was 0.1 mm under a sun placed 100 km away), and far above rounding there.
inline double origin_ceiling(double h_origin, double light_offset) {
  return h_origin - std::max(1e-3 * light_offset, 1e-14 * std::abs(h_origin));
}

// The light as one texel sees it: the plane its rows lie in (the light's own, or a sphere's
// silhouette disk seen from the texel's ray origin) with the normal towards the texel, and the
// rows' turned axes.
struct LightFrame {
  Vec3 centre;  // of the light, or of a sphere's silhouette disk
  Vec3 normal;  // of its plane, towards the texel
  Vec3 s_axis, t_axis;
  double radius = 0;       // a disk's or a sphere's silhouette's (0 for a rectangle)
  double clip_height = 0;  // blocker points nearer the plane than this do not block
  // A ball that holds the whole light (a sphere's own): every ray the rows stand for ends in it.
  Vec3 ball_centre;
  double ball_radius = 0;
};

// What each row's centre line has blocked: up to kExactIntervals intervals kept exactly, beyond
// that the cells whose centres they cover (cell c of row r centred at enter + (c + ½)·width/64).
// A texel's evaluation makes one for its rows alone: the rest is left unwritten (zeroing all 64
// rows' intervals, 7 KB, was a tenth of a clear texel's evaluation).
struct BlockedRows {
  struct Interval {
    double first, second;
    bool operator<(const Interval& o) const {
      return first < o.first || (first == o.first && second < o.second);
    }
  };
  struct Row {
    int count;  // intervals given; above kExactIntervals, `cells` holds them all
    std::array<Interval, kExactIntervals> intervals;
    std::uint64_t cells;
  };
  std::array<Row, LightRows::kMaxRows> rows;

  // Rows [0, n) empty; the others are not read.
  explicit BlockedRows(int n) { clear(n); }
  void clear(int n) {
    for (int r = 0; r < n; ++r) rows[std::size_t(r)].count = 0, rows[std::size_t(r)].cells = 0;
  }

  // The cells of a row (of chord enter..leave) whose centres [a, b] covers.
  static std::uint64_t cells_of(double enter, double leave, double a, double b);
  // Adds [a, b] (within the row's chord) to row r.
  void add(const LightRows& lights, int r, double a, double b);
  // Adds cells to row r, which holds cells from then on.
  void add_cells(const LightRows& lights, int r, std::uint64_t cells);
};

// Everything a rasteriser needs of one texel's evaluation.
struct RasterTarget {
  const LightFrame* frame = nullptr;
  const LightRows* rows = nullptr;
  Vec3 origin, position, normal;  // the ray origin; the surface point and its shading normal
  double light_offset = 0;        // RayScene::surface_offset
  BlockedRows* blocked = nullptr;
  PenumbraSample* out = nullptr;                   // nearest_blocker and umbra are updated
  std::vector<std::uint32_t>* blocking = nullptr;  // keys that reach the light, unsorted
};

// Whether every row of the light is hidden from end to end, as the estimator's integral sweeps
// it (penumbra_estimator.cpp).
bool every_row_hidden(const LightRows& rows, const BlockedRows& blocked);

// A wall of several polygons that hides all of the light, found without the rest of a crowded
// shaft (blocker_rasteriser.cpp): the blockers' polygons in the shaft are rasterised nearest
// first (by their boxes' distance from the origin), a few at a time, until every row is hidden
// or `budget` of them are in; false at once where the shaft holds no more than `fewest`. True
// where every row is hidden: V is then 0 whatever the rest hide, `target.blocked` holds the
// rows, `target.out->nearest_blocker` is a lower bound on every blocker's distance (polygons,
// solids and dense meshes) and `*target.blocking` lists them all (what the refinement's checks
// read of a sample: a bound on what may hide the light near it). False: `target.blocked` is
// left empty, for the whole pass.
bool nearest_hide_all(const RasterTarget& target, const Blockers& blockers, std::size_t fewest,
                      std::size_t budget);

// Polygons one by one, and convex solids by their silhouette edges (blocker_rasteriser.cpp).
void rasterise_polygons_and_solids(const RasterTarget& target,
                                   const std::vector<BlockerPolygon>& polygons,
                                   const std::vector<BlockerSolidRef>& solids);

// Many triangles through the outline of their union (outline_rasteriser.cpp).
void rasterise_outline(const RasterTarget& target, const BlockerOutline& outline);

}  // namespace sb
