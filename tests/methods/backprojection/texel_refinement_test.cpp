// Tests of adaptive texel sampling (texel_refinement.cpp) on synthetic fields over a flat 64²
// lightmap: where it interpolates, what it checks before it does, and what it must not miss (a
// kink between samples, a thin shadow no sample falls on, a UV chart border).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <functional>
#include <vector>

#include "methods/backprojection/texel_refinement.h"

namespace sb {
namespace {

constexpr int kSide = 64;

// A flat 1 m² receiver, every texel covered: texel (x, y) at (x/64, y/64, 0), normal up; with
// `border_at` ≥ 0, the texels from that column on lie 1 m away (another UV chart beside it).
TexelSpace flat_space(int border_at = -1) {
  TexelSpace space;
  space.width = space.height = kSide;
  space.covered.assign(kSide * kSide, 1);
  space.face_normals = {Vec3f::UnitZ()};
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x) {
      Texel t;
      t.x = x, t.y = y;
      t.position = Vec3f((x + 0.5f) / kSide + (border_at >= 0 && x >= border_at ? 1.0f : 0.0f),
                         (y + 0.5f) / kSide, 0);
      t.normal = Vec3f::UnitZ();
      t.face = 0;
      space.texels.push_back(t);
    }
  return space;
}

// Every tile listed (one candidate), every texel reached.
TileShafts listed_tiles() {
  TileShafts tiles;
  tiles.tiles_x = tiles.tiles_y = kSide / TileShafts::kTile;
  tiles.kind.assign(std::size_t(tiles.tiles_x * tiles.tiles_y), TileShafts::Kind::listed);
  tiles.patches.assign(tiles.kind.size(), {TileShafts::Kind::listed, {7}, Bounds3()});
  tiles.first_patch.resize(tiles.kind.size() + 1);
  for (std::size_t i = 0; i <= tiles.kind.size(); ++i) tiles.first_patch[i] = std::uint32_t(i);
  tiles.reached.assign(tiles.kind.size(), ~std::uint64_t(0));
  return tiles;
}

// A field V(x, y) the source evaluates exactly, counting evaluations; blockers as the test says.
class FieldSource final : public PairSource {
 public:
  FieldSource(const TexelSpace& space, std::function<double(int, int)> field)
      : space_(space), field_(std::move(field)) {}
  void evaluate(std::size_t t, PairSample& out) const override {
    ++evaluations;
    const Texel& tx = space_.texels[t];
    out = PairSample();
    out.visibility = float(field_(tx.x, tx.y));
    out.route = TexelRoute::exact;
    out.nearest = float(nearest);
    out.triangles = {7};
    out.umbra =
        umbra_where ? (umbra_where(tx.x, tx.y) ? 99u : PairSample().umbra) : PairSample().umbra;
  }
  double angular_width(std::size_t) const override { return 0.5; }
  bool sees_unlisted(const std::vector<std::size_t>& texels,
                     const std::vector<std::uint32_t>&) const override {
    if (!unlisted_where) return false;
    for (std::size_t t : texels)
      if (unlisted_where(space_.texels[t].x, space_.texels[t].y)) return true;
    return false;
  }
  bool one_triangle_hides(const std::array<std::size_t, 5>& samples,
                          const std::vector<std::uint32_t>&) const override {
    if (!triangle_umbra_where) return false;
    for (std::size_t t : samples)
      if (!triangle_umbra_where(space_.texels[t].x, space_.texels[t].y)) return false;
    return true;
  }
  bool ball_hides(const std::vector<std::size_t>& texels,
                  const std::vector<std::uint32_t>&) const override {
    if (!ball_umbra_where) return false;
    for (std::size_t t : texels)
      if (!ball_umbra_where(space_.texels[t].x, space_.texels[t].y)) return false;
    return true;
  }
  mutable std::atomic<int> evaluations{0};  // evaluated in parallel
  double nearest = 10.0;                    // metres: far, for penumbrae far wider than any cell
  std::function<bool(int, int)> unlisted_where, umbra_where, triangle_umbra_where, ball_umbra_where;

 private:
  const TexelSpace& space_;
  std::function<double(int, int)> field_;
};

struct Outcome {
  double max_error = 0;
  int evaluations = 0, interpolated = 0;
};

Outcome refine(const TexelSpace& space, FieldSource& source,
               const std::function<double(int, int)>& truth,
               const RefinementSettings& settings = {}) {
  const LightField field = refine_light(space, TexelGrid(space), listed_tiles(), source, settings);
  Outcome o;
  o.evaluations = source.evaluations;
  for (std::size_t t = 0; t < space.texels.size(); ++t) {
    o.max_error =
        std::max(o.max_error, std::abs(field.visibility_at(space.texels[t].x, space.texels[t].y) -
                                       truth(space.texels[t].x, space.texels[t].y)));
    o.interpolated +=
        field.route_at(space.texels[t].x, space.texels[t].y) == TexelRoute::interpolated;
  }
  return o;
}

// A tile's texels read a row's bits at a time (TexelGrid::tile_texels) are each pixel's own,
// on a lightmap whose width crosses words of 64 pixels and ends inside a tile, half covered.
TEST(TexelGrid, ATilesTexelsAreItsPixelsTexels) {
  TexelSpace space;
  space.width = 150, space.height = 21;
  space.covered.assign(std::size_t(space.width * space.height), 0);
  std::uint32_t state = 12345;
  for (std::uint8_t& c : space.covered) {
    state = state * 1664525u + 1013904223u;
    c = std::uint8_t(state >> 31);
  }
  // Texels are numbered in row-major order of their pixels.
  std::vector<std::int32_t> index(space.covered.size(), -1);
  std::int32_t count = 0;
  for (std::size_t i = 0; i < index.size(); ++i)
    if (space.covered[i]) index[i] = count++;
  const TexelGrid grid(space);
  std::array<std::int32_t, TexelGrid::kSide * TexelGrid::kSide> texels;
  std::int32_t covered = 0;
  for (int ty = 0; ty * TexelGrid::kSide < space.height; ++ty)
    for (int tx = 0; tx * TexelGrid::kSide < space.width; ++tx) {
      grid.tile_texels(tx, ty, texels);
      for (int j = 0; j < TexelGrid::kSide * TexelGrid::kSide; ++j) {
        const int x = tx * TexelGrid::kSide + j % TexelGrid::kSide;
        const int y = ty * TexelGrid::kSide + j / TexelGrid::kSide;
        const std::int32_t expected =
            x < space.width && y < space.height
                ? index[std::size_t(y) * std::size_t(space.width) + std::size_t(x)]
                : -1;
        ASSERT_EQ(texels[std::size_t(j)], expected) << x << ", " << y;
        ASSERT_EQ(grid.texel(x, y), expected) << x << ", " << y;
        covered += texels[std::size_t(j)] >= 0;
      }
    }
  EXPECT_EQ(covered, count);
  EXPECT_GT(count, 0);
}

TEST(TexelRefinement, InterpolatesASmoothFieldExactlyWithFewSamples) {
  const TexelSpace space = flat_space();
  const auto linear = [](int x, int y) { return 0.2 + 0.01 * x + 0.002 * y; };
  FieldSource source(space, linear);
  const Outcome o = refine(space, source, linear);
  EXPECT_LT(o.max_error, 1e-6);
  EXPECT_LT(o.evaluations, kSide * kSide / 6);  // the last column and row lack their corners
  EXPECT_GT(o.interpolated, kSide * kSide / 2);
}

// The edge of a penumbra: V flat, then a ramp (a kink in V along a line). Cells across it see
// their centre disagree with their corners and refine; what is interpolated is within the
// tolerance (a kink moves the centre by at least half the error it causes).
TEST(TexelRefinement, FindsAKinkBetweenItsSamples) {
  const TexelSpace space = flat_space();
  const auto kink = [](int x, int) { return std::clamp((x - 21.3) / 12.0, 0.0, 1.0); };
  FieldSource source(space, kink);
  const Outcome o = refine(space, source, kink);
  EXPECT_LT(o.max_error, 1.5 * RefinementSettings().tolerance);
  EXPECT_GT(o.interpolated, 0);
}

// A kink along x (at x = 18, inside the 8-cells from x = 16) that the field's curvature along y
// cancels at their centres: the centre agrees with its corners (2 − 3 + 1 hundredths) while the
// texels on the kink lie 0.015 off the interpolation. With a blocker near enough for penumbrae
// under four cells, the cells' edge midpoints are checked too and find it; without that check
// (midpoint_cells 0) the error stands.
TEST(TexelRefinement, FindsAKinkTheCentreCancels) {
  const TexelSpace space = flat_space();
  const auto field = [](int x, int y) {
    const int v = y % 8;
    return 0.3 + 0.01 * std::max(0, x - 18) + 0.000625 * v * (8 - v);
  };
  RefinementSettings without;
  without.midpoint_cells = 0;
  FieldSource unchecked(space, field);
  unchecked.nearest = 0.93;  // penumbrae about three 8-cells wide, six 4-cells
  EXPECT_GT(refine(space, unchecked, field, without).max_error, 0.01);
  FieldSource checked(space, field);
  checked.nearest = 0.93;
  const Outcome o = refine(space, checked, field);
  EXPECT_LT(o.max_error, 1.5 * RefinementSettings().tolerance);
  EXPECT_GT(o.interpolated, 0);
}

// A shadow one texel wide on a column no sample of an 8-cell falls on: only the check for
// blockers no sample saw finds it; without that check the cells would interpolate 1 over it.
TEST(TexelRefinement, DoesNotMissAThinShadowNoSampleSees) {
  const TexelSpace space = flat_space();
  const auto line = [](int x, int) { return x == 13 ? 0.0 : 1.0; };
  FieldSource source(space, line);
  source.unlisted_where = [](int x, int) { return x == 13; };
  EXPECT_EQ(refine(space, source, line).max_error, 0.0);
  FieldSource blind(space, line);
  EXPECT_EQ(refine(space, blind, line).max_error, 1.0);  // what the check is for
}

// Blockers near the receiver cast penumbrae narrower than a cell: no cell interpolates across
// them, however well its samples agree.
TEST(TexelRefinement, DoesNotInterpolateNearContact) {
  const TexelSpace space = flat_space();
  const auto flat = [](int, int) { return 0.5; };
  FieldSource source(space, flat);
  source.nearest = 0.001;  // 1 mm: penumbrae ~0.5 mm wide, a texel is 16 mm
  const Outcome o = refine(space, source, flat);
  EXPECT_EQ(o.interpolated, 0);
  EXPECT_EQ(o.evaluations, kSide * kSide);
}

// In the umbra of one convex solid at every sample, a cell interpolates even near contact (that
// umbra is convex); in two different solids' umbrae it does not.
TEST(TexelRefinement, InterpolatesInsideOneConvexSolidsUmbra) {
  const TexelSpace space = flat_space();
  const auto dark = [](int, int) { return 0.0; };
  FieldSource one(space, dark);
  one.nearest = 0.001;
  one.umbra_where = [](int, int) { return true; };
  EXPECT_GT(refine(space, one, dark).interpolated, kSide * kSide / 2);
  FieldSource none(space, dark);
  none.nearest = 0.001;
  EXPECT_EQ(refine(space, none, dark).interpolated, 0);
}

// The same where one triangle hides the light from all five samples, though their own umbrae
// are of nothing single (the sun under a tree crown's facets): only the cells whose samples all
// lie in that triangle's umbra interpolate.
TEST(TexelRefinement, InterpolatesInsideOneTrianglesUmbra) {
  const TexelSpace space = flat_space();
  const auto dark = [](int, int) { return 0.0; };
  FieldSource one(space, dark);
  one.nearest = 0.001;
  one.triangle_umbra_where = [](int x, int) { return x <= 32; };
  const Outcome o = refine(space, one, dark);
  EXPECT_GT(o.interpolated, kSide * kSide / 4);
  const LightField field = refine_light(space, TexelGrid(space), listed_tiles(), one, {});
  for (std::size_t t = 0; t < space.texels.size(); ++t) {
    if (space.texels[t].x >= 32) {
      EXPECT_NE(field.route_at(space.texels[t].x, space.texels[t].y), TexelRoute::interpolated)
          << space.texels[t].x;
    }
  }
}

// The same where a ball inside a closed blocker hides the light from the cell's texels (a lumpy
// tree crown's umbra): only the cells all of whose texels it hides interpolate, and only where
// their samples are all 0.
TEST(TexelRefinement, InterpolatesInsideABallsUmbra) {
  const TexelSpace space = flat_space();
  const auto dark_left = [](int x, int) { return x < 48 ? 0.0 : 0.5; };
  FieldSource ball(space, dark_left);
  ball.nearest = 0.001;
  ball.ball_umbra_where = [](int x, int) { return x < 32 || x >= 48; };
  const Outcome o = refine(space, ball, dark_left);
  EXPECT_GT(o.interpolated, kSide * kSide / 4);
  EXPECT_EQ(o.max_error, 0);
  const LightField field = refine_light(space, TexelGrid(space), listed_tiles(), ball, {});
  for (const Texel& t : space.texels) {
    if (t.x >= 32) {
      EXPECT_NE(field.route_at(t.x, t.y), TexelRoute::interpolated) << t.x << ", " << t.y;
    }
  }
}

// Two UV charts side by side in the lightmap, far apart on the surface: no cell interpolates
// across their border, where the field jumps.
TEST(TexelRefinement, DoesNotInterpolateAcrossAChartBorder) {
  const TexelSpace space = flat_space(/*border_at=*/28);
  const auto jump = [](int x, int) { return x < 28 ? 0.2 + 0.001 * x : 0.9 - 0.001 * x; };
  FieldSource source(space, jump);
  const Outcome o = refine(space, source, jump);
  EXPECT_LT(o.max_error, 1e-6);
  // Column 27 is chart A's last: no cell it belongs to has all its corners in A.
  FieldSource again(space, jump);
  const LightField field = refine_light(space, TexelGrid(space), listed_tiles(), again, {});
  for (std::size_t t = 0; t < space.texels.size(); ++t) {
    if (space.texels[t].x == 27) {
      EXPECT_NE(field.route_at(space.texels[t].x, space.texels[t].y), TexelRoute::interpolated)
          << space.texels[t].y;
    }
  }
}

}  // namespace
}  // namespace sb

namespace sb {
namespace {

// The field's storage by tile (LightField): a clear or umbra tile the light reaches all of holds
// one value, a tile it reaches in part and the cells' tiles hold their texels' own, and an umbra
// right of a cells' tile has its corners evaluated; every texel reads what the refinement gave it.
TEST(TexelRefinement, TilesWithoutPlacesHoldTheirKindsValue) {
  const TexelSpace space = flat_space();
  using Kind = TileShafts::Kind;
  constexpr int k = TileShafts::kTile;
  TileShafts tiles = listed_tiles();
  const auto at = [&](int tx, int ty) { return std::size_t(ty * tiles.tiles_x + tx); };
  for (int ty = 0; ty < tiles.tiles_y; ++ty)
    for (int tx = 0; tx < tiles.tiles_x; ++tx) tiles.kind[at(tx, ty)] = Kind::clear;
  tiles.kind[at(2, 2)] = Kind::listed;  // cells, whose right, lower and lower-right tiles...
  tiles.kind[at(3, 2)] = Kind::umbra;   // ... hold their corners
  tiles.kind[at(6, 6)] = Kind::umbra;   // alone: one value
  tiles.kind[at(0, 7)] = Kind::empty;
  for (std::size_t i = 0; i < tiles.kind.size(); ++i) tiles.patches[i].kind = tiles.kind[i];
  for (int y = 0; y < k; ++y)  // the light reaches only the left half of tile (5, 0)
    for (int x = 5 * k + k / 2; x < 6 * k; ++x)
      tiles.reached[tiles.tile_of(x, y)] &= ~TileShafts::bit_of(x, y);
  tiles.reached[at(0, 7)] = 0;  // nor any of the empty tile
  // A field with a kink inside the cells' tile, whose corners in the umbra are evaluated.
  const auto field_at = [](int x, int) { return x < 20 ? 1.0 : 0.25; };
  FieldSource source(space, field_at);
  const LightField field = refine_light(space, TexelGrid(space), tiles, source, {});
  EXPECT_LT(field.visibility.size(), space.texels.size() / 4) << "only some tiles have places";
  int corners = 0;
  for (const Texel& t : space.texels) {
    const Kind kind = tiles.kind[at(t.x / k, t.y / k)];
    const bool reached = tiles.reached_at(t.x, t.y);
    const TexelRoute route = field.route_at(t.x, t.y);
    const float v = field.visibility_at(t.x, t.y);
    if (!reached) {
      EXPECT_EQ(route, TexelRoute::none) << t.x << ", " << t.y;
    } else if (kind == Kind::clear) {
      EXPECT_EQ(route, TexelRoute::clear) << t.x << ", " << t.y;
      EXPECT_EQ(v, 1.0f);
    } else if (kind == Kind::listed) {
      EXPECT_TRUE(route == TexelRoute::exact || route == TexelRoute::interpolated);
      EXPECT_NEAR(v, field_at(t.x, t.y), 1e-6) << t.x << ", " << t.y;
    } else if (route == TexelRoute::exact) {  // a corner of the cells: their right column
      EXPECT_EQ(t.x, 3 * k);
      EXPECT_EQ(t.y / k, 2);
      EXPECT_EQ(v, 0.25f);
      ++corners;
    } else {
      EXPECT_EQ(route, TexelRoute::umbra) << t.x << ", " << t.y;
      EXPECT_EQ(v, 0.0f);
    }
  }
  EXPECT_GT(corners, 0) << "the umbra's texels the cells take as corners are evaluated";
}

}  // namespace
}  // namespace sb
