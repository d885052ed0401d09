// Rasterises a receiver's triangles in lightmap UV space: for each texel of a width × height
// lightmap, whether the UV layout covers it and, if so, the surface point it stands for (world
// position, interpolated shading normal, face, shadow-ray origin; the faces' normals). The bake
// methods shade exactly these points, so every later image is only as complete as this coverage.
//
// Two passes per row of texels:
//  1. Centre sampling. A texel whose centre lies inside a triangle or on its edge takes the point
//     at its centre, by barycentric interpolation; the first face in face order wins. Edge
//     functions are evaluated with the edge's endpoints in a canonical order, so two triangles
//     sharing an edge get exactly opposite values and a centre on it is never lost to rounding.
//  2. Conservative coverage (Hasselgren, Akenine-Möller & Ohlsson, "Conservative Rasterization",
//     GPU Gems 2, ch. 42, 2005). A texel that no centre test claimed but whose square a triangle
//     overlaps with positive area takes that triangle's point nearest its centre in UV space
//     (Ericson, "Real-Time Collision Detection", 2005, §5.1.5); of several such triangles the one
//     with the nearest point wins, then the lowest face index. The overlap test is the separating
//     axis test of Akenine-Möller ("Fast 3D Triangle-Box Overlap Testing", JGT 2001) reduced to
//     2D: the square's two axes and the triangle's three edge normals.
//
// Why pass 2 matters: a triangle thinner than a texel, or the border of a UV chart, often contains
// no texel centre at all. With centre sampling alone such geometry gets no texels, its part of the
// lightmap stays black, and bilinear filtering pulls that black in as seams along chart borders
// and across thin geometry. The nearest-point rule keeps every conservative texel's position on
// its triangle, so shading it never samples a point off the surface.
//
// Rows are independent (a texel's coverage depends only on the triangles crossing its row), so
// rows run in parallel with oneTBB; the result does not depend on the thread count.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "core/nearest_point.h"
#include "texels/texel_space.h"

namespace sb {
namespace {

// One edge of a footprint as a function of texel-space point (X, Y), >= 0 on the triangle's side:
// value = a (X - x0) + b (Y - y0). The edge's endpoints are taken in lexicographic order, so two
// triangles sharing an edge hold the same (x0, y0) and opposite (a, b), and get bitwise opposite
// values at every point: a texel centre on a shared edge is inside both, never lost to rounding.
struct EdgeFunction {
  double a = 0.0, b = 0.0, x0 = 0.0, y0 = 0.0;

  EdgeFunction() = default;
  // The edge p → q of a triangle whose texel-space signed area has sign `orientation` (±1).
  EdgeFunction(const Vec2& p, const Vec2& q, double orientation) {
    const bool ordered = p.x() < q.x() || (p.x() == q.x() && p.y() <= q.y());
    const Vec2& from = ordered ? p : q;
    const Vec2& to = ordered ? q : p;
    const double sign = ordered ? orientation : -orientation;
    a = -(to.y() - from.y()) * sign;
    b = (to.x() - from.x()) * sign;
    x0 = from.x();
    y0 = from.y();
  }
  double row_term(double y) const { return b * (y - y0); }
  double operator()(double x, double row_term_y) const { return a * (x - x0) + row_term_y; }
};

// A triangle's UV footprint in texel coordinates, X = u * width and Y = (1 - v) * height, so that
// texel (x, y) is the unit square [x, x + 1] × [y, y + 1] with its centre at (x + 0.5, y + 0.5).
struct FaceFootprint {
  int face = -1;
  Vec2 texel_uv[3];      // vertices in texel coordinates
  Vec2 uv[3];            // vertices in UV coordinates, for the nearest-point rule
  EdgeFunction edge[3];  // edge[i] is the edge opposite vertex i; its value weighs vertex i
  Vec2 lo, hi;           // texel-space bounding box
};

// Everything needed to turn barycentrics on face f into a Texel.
struct FaceSurface {
  Vec3 position[3];
  Vec3 normal[3];
  Vec3 face_normal;  // unit, from the world positions
  // Whether its vertex normals may lift a point of it (make_texel): some corner lies above
  // another's tangent plane by more than a millionth of its longest side.
  bool curved = false;
};

// How far apart on the surface two points of a face one pixel apart in the lightmap lie at most:
// the largest singular value of its map from texel coordinates to world space, at most its
// longest side (a face whose UVs nearly collapse stretches without bound).
double texel_step(const FaceFootprint& fp, const FaceSurface& s) {
  const Vec2 t1 = fp.texel_uv[1] - fp.texel_uv[0], t2 = fp.texel_uv[2] - fp.texel_uv[0];
  const Vec3 p1 = s.position[1] - s.position[0], p2 = s.position[2] - s.position[0];
  const double longest = std::max({p1.norm(), p2.norm(), (s.position[2] - s.position[1]).norm()});
  const double det = t1.x() * t2.y() - t1.y() * t2.x();
  if (!(std::abs(det) > 0)) return longest;
  // J = [p1 p2] · [t1 t2]⁻¹; its largest singular value from the 2 × 2 matrix JᵀJ.
  const Vec3 ju = (p1 * t2.y() - p2 * t1.y()) / det, jv = (p2 * t1.x() - p1 * t2.x()) / det;
  const double a = ju.dot(ju), b = ju.dot(jv), c = jv.dot(jv);
  const double largest = 0.5 * (a + c) + std::sqrt(0.25 * (a - c) * (a - c) + b * b);
  return std::min(std::sqrt(largest), longest);
}

// Twice the signed area of (a, b, p); positive when p lies to the left of a → b.
double orient(const Vec2& a, const Vec2& b, const Vec2& p) {
  return (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
}

// The three edge values of centre (x, y) scaled to barycentrics; false when it is outside.
bool centre_barycentrics(const FaceFootprint& fp, double x, double y, double bary[3]) {
  double sum = 0.0;
  for (int i = 0; i < 3; ++i) {
    bary[i] = fp.edge[i](x, fp.edge[i].row_term(y));
    if (bary[i] < 0.0) return false;
    sum += bary[i];
  }
  if (!(sum > 0.0)) return false;
  const double inverse_sum = 1.0 / sum;
  for (int i = 0; i < 3; ++i) bary[i] *= inverse_sum;
  return true;
}

// Overlaps shorter than this (in texels, along any separating axis) count as touching, not
// overlapping: a triangle whose edge lies on a texel border does not claim the texel beyond it.
constexpr double kOverlapTolerance = 1e-9;

// True when the footprint and texel square [x, x + 1] × [y, y + 1] overlap with positive area.
bool overlaps_texel(const FaceFootprint& fp, int x, int y) {
  const double sx0 = x, sx1 = x + 1.0, sy0 = y, sy1 = y + 1.0;
  if (fp.hi.x() <= sx0 + kOverlapTolerance || fp.lo.x() >= sx1 - kOverlapTolerance) return false;
  if (fp.hi.y() <= sy0 + kOverlapTolerance || fp.lo.y() >= sy1 - kOverlapTolerance) return false;
  const Vec2 centre(x + 0.5, y + 0.5);
  for (int i = 0; i < 3; ++i) {
    const Vec2& a = fp.texel_uv[i];
    const Vec2& b = fp.texel_uv[(i + 1) % 3];
    const Vec2& opposite = fp.texel_uv[(i + 2) % 3];
    // Axis: the edge's normal (unnormalised). The triangle projects onto [edge, opposite vertex].
    const Vec2 axis(-(b.y() - a.y()), b.x() - a.x());
    const double length = axis.norm();
    const double edge_value = axis.dot(a);
    const double opposite_value = axis.dot(opposite);
    const double tri_lo = std::min(edge_value, opposite_value);
    const double tri_hi = std::max(edge_value, opposite_value);
    const double radius = 0.5 * (std::abs(axis.x()) + std::abs(axis.y()));
    const double square_value = axis.dot(centre);
    const double tolerance = kOverlapTolerance * length;
    if (tri_hi <= square_value - radius + tolerance || tri_lo >= square_value + radius - tolerance)
      return false;
  }
  return true;
}

// The x extent of the footprint within the row strip Y in [y0, y1], or false if it misses it.
bool row_extent(const FaceFootprint& fp, double y0, double y1, double& x_lo, double& x_hi) {
  x_lo = std::numeric_limits<double>::infinity();
  x_hi = -x_lo;
  const auto include = [&](double x) {
    x_lo = std::min(x_lo, x);
    x_hi = std::max(x_hi, x);
  };
  for (int i = 0; i < 3; ++i) {
    const Vec2& a = fp.texel_uv[i];
    const Vec2& b = fp.texel_uv[(i + 1) % 3];
    if (a.y() >= y0 && a.y() <= y1) include(a.x());
    for (const double y : {y0, y1}) {
      if ((a.y() < y && b.y() > y) || (a.y() > y && b.y() < y)) {
        const double t = (y - a.y()) / (b.y() - a.y());
        include(a.x() + t * (b.x() - a.x()));
      }
    }
  }
  return x_lo <= x_hi;
}

// Texels in a row that the footprint may touch: [first, last], clamped to the image.
bool row_span(const FaceFootprint& fp, int y, int width, int& first, int& last) {
  double x_lo, x_hi;
  if (!row_extent(fp, y, y + 1.0, x_lo, x_hi)) return false;
  // A little slack: the exact decision is made per texel, this only bounds the loop.
  x_lo = std::clamp(std::floor(x_lo - 1e-6), 0.0, double(width));
  x_hi = std::clamp(std::ceil(x_hi + 1e-6), 0.0, double(width));
  first = int(x_lo);
  last = std::min(int(x_hi), width - 1);
  return first <= last;
}

Vec3 unit_or(const Vec3& v, const Vec3& fallback) {
  const double length = v.norm();
  return length > 1e-12 ? Vec3(v * (1.0 / length)) : fallback;
}

// The texel at barycentric `bary` of face `face`, and its shadow origin's lift off its position.
Texel make_texel(const FaceSurface& s, int face, int x, int y, const double bary[3], Vec3f& lift) {
  Texel t;
  t.x = std::uint16_t(x);
  t.y = std::uint16_t(y);
  t.face = face;
  const Vec3 position = bary[0] * s.position[0] + bary[1] * s.position[1] + bary[2] * s.position[2];
  const Vec3 normal =
      unit_or(bary[0] * s.normal[0] + bary[1] * s.normal[1] + bary[2] * s.normal[2], s.face_normal);
  t.position = position.cast<float>();
  t.normal = normal.cast<float>();
  // Shadow-terminator offset (Hanika, "Hacking the Shadow Terminator", Ray Tracing Gems II,
  // ch. 4, 2021): a flat triangle of a curved mesh lies inside the smooth surface its vertex
  // normals describe, so rays towards a grazing light hit the neighbouring triangles. Lift the
  // point by the barycentric mean of its heights below each vertex's tangent plane.
  lift = Vec3f::Zero();
  if (s.curved) {
    Vec3 shadow_origin = position;
    for (int i = 0; i < 3; ++i) {
      const double below = (s.position[i] - position).dot(s.normal[i]);
      if (below > 0) shadow_origin += bary[i] * below * s.normal[i];
    }
    lift = shadow_origin.cast<float>() - t.position;
  }
  return t;
}

// The footprint of triangle `tri` (face `face`) in a width × height lightmap; false when the face
// has none worth rasterising: non-finite or collapsed UVs, or a footprint outside the lightmap.
bool make_footprint(const Triangle& tri, int face, int width, int height, FaceFootprint& fp) {
  fp.face = face;
  bool finite = true;
  for (int i = 0; i < 3; ++i) {
    fp.uv[i] = tri.uv[i];
    fp.texel_uv[i] = Vec2(tri.uv[i].x() * width, (1.0 - tri.uv[i].y()) * height);
    finite = finite && fp.texel_uv[i].allFinite();
  }
  if (!finite) return false;
  const double area2 = orient(fp.texel_uv[0], fp.texel_uv[1], fp.texel_uv[2]);
  // Zero UV area (collapsed UVs) has no interior to shade. 1e-10 texel² is far below any sliver
  // worth a texel; a nearly collinear triangle above it is still safe, as every texel it gets is
  // a convex combination of its vertices.
  if (std::abs(area2) <= 1e-10) return false;
  const double orientation = area2 > 0.0 ? 1.0 : -1.0;
  for (int i = 0; i < 3; ++i)
    fp.edge[i] = EdgeFunction(fp.texel_uv[(i + 1) % 3], fp.texel_uv[(i + 2) % 3], orientation);
  fp.lo = fp.texel_uv[0].cwiseMin(fp.texel_uv[1]).cwiseMin(fp.texel_uv[2]);
  fp.hi = fp.texel_uv[0].cwiseMax(fp.texel_uv[1]).cwiseMax(fp.texel_uv[2]);
  if (fp.hi.x() <= 0.0 || fp.hi.y() <= 0.0 || fp.lo.x() >= width || fp.lo.y() >= height)
    return false;  // entirely outside the lightmap
  return true;
}

// The world-space surface of triangle `tri`: its corners, vertex normals, unit face normal, and
// whether its vertex normals curve it.
void describe_surface(const Triangle& tri, FaceSurface& s) {
  for (int i = 0; i < 3; ++i) {
    s.position[i] = tri.p[i];
    s.normal[i] = tri.n[i];
  }
  const Vec3 average_normal = tri.n[0] + tri.n[1] + tri.n[2];
  s.face_normal = unit_or((tri.p[1] - tri.p[0]).cross(tri.p[2] - tri.p[0]),
                          unit_or(average_normal, Vec3::UnitZ()));
  // A point's height below corner i's tangent plane is linear over the face, so it is
  // greatest at a corner: below that bound nothing lifts (a flat face's vertex normals, up to
  // the rounding of its file's floats).
  double longest = 0, highest = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      longest = std::max(longest, (tri.p[i] - tri.p[j]).norm());
      highest = std::max(highest, (tri.p[i] - tri.p[j]).dot(tri.n[i]));
    }
  s.curved = highest > 1e-6 * longest;
}

// The rows of a height-texel lightmap that a footprint's bounding box crosses: [y0, y1].
void footprint_rows(const FaceFootprint& fp, int height, int& y0, int& y1) {
  y0 = int(std::clamp(std::floor(fp.lo.y()), 0.0, double(height - 1)));
  y1 = int(std::clamp(std::ceil(fp.hi.y()) - 1.0, 0.0, double(height - 1)));
}

// Rows → footprints whose bounding box crosses them, in face order (compressed rows): row y's
// footprints are those indexed by faces[begin[y]] up to faces[begin[y + 1]].
struct RowFaces {
  std::vector<std::size_t> begin;
  std::vector<std::int32_t> faces;
};

// The row index of `footprints` over a height-texel lightmap, by counting then filling.
RowFaces index_rows(const std::vector<FaceFootprint>& footprints, int height) {
  RowFaces index;
  std::vector<std::size_t>& row_begin = index.begin;
  row_begin.assign(std::size_t(height) + 1, 0);
  for (const FaceFootprint& fp : footprints) {
    int y0, y1;
    footprint_rows(fp, height, y0, y1);
    for (int y = y0; y <= y1; ++y) ++row_begin[std::size_t(y) + 1];
  }
  for (int y = 0; y < height; ++y) row_begin[std::size_t(y) + 1] += row_begin[std::size_t(y)];
  index.faces.resize(row_begin[std::size_t(height)]);
  std::vector<std::size_t> next(row_begin.begin(), row_begin.end() - 1);
  for (std::size_t i = 0; i < footprints.size(); ++i) {
    int y0, y1;
    footprint_rows(footprints[i], height, y0, y1);
    for (int y = y0; y <= y1; ++y) index.faces[next[std::size_t(y)]++] = std::int32_t(i);
  }
  return index;
}

// Per-texel owner codes: no face, face f by centre (pass 1) as f, by overlap (pass 2) as -2 - f.
constexpr std::int32_t kUncovered = -1;
std::int32_t conservative_code(int face) { return -2 - face; }
bool is_centre_code(std::int32_t code) { return code >= 0; }
int face_of(std::int32_t code) { return code >= 0 ? code : -2 - code; }

// Scratch of one task's rows in the passes, one entry per texel of a row.
struct RowScratch {
  std::vector<double> best_distance;      // pass 2: the UV distance of the owner's nearest point
  std::vector<std::uint8_t> row_strict;   // pass 1: whether the owner holds the centre strictly
  std::vector<std::uint8_t> row_overlap;  // pass 1: whether two faces' interiors hold the centre
  explicit RowScratch(int width)
      : best_distance(static_cast<std::size_t>(width)),
        row_strict(static_cast<std::size_t>(width)),
        row_overlap(static_cast<std::size_t>(width)) {}
};

// Texel i, whose shadow origin is its position lifted by `lift`, into its block's summary.
void add_to_block(TexelSpace& space, std::size_t i, const Vec3f& lift) {
  constexpr int kBlock = TexelBlock::kSide;
  const Texel& t = space.texels[i];
  TexelBlock& b = space.blocks[std::size_t(t.y / kBlock) * std::size_t(space.blocks_x) +
                               std::size_t(t.x / kBlock)];
  const Vec3f geometric = space.geometric_normal(i);
  const bool flat = lift == Vec3f::Zero();
  if (b.empty()) {
    b.lo = b.hi = t.position;
    b.texel_size = space.face_texel_sizes[std::size_t(t.face)];
    b.uniform = flat;
    b.normal = t.normal;
    b.geometric = geometric;
    return;
  }
  b.texel_size = std::max(b.texel_size, space.face_texel_sizes[std::size_t(t.face)]);
  b.lo = b.lo.cwiseMin(t.position);
  b.hi = b.hi.cwiseMax(t.position);
  b.uniform = b.uniform && flat && t.normal == b.normal && geometric == b.geometric;
}

// The steps of rasterise_texels over the window of rows [row0, row1), sharing the usable faces'
// footprints and the owner code of every texel of the window.
struct Rasteriser {
  const TriMesh& tri_mesh;
  int width, height;
  int row0, row1;
  std::vector<FaceFootprint> footprints;  // of the usable faces, in face order
  std::vector<FaceSurface> surfaces;      // indexed by face
  RowFaces row_faces;
  std::unique_ptr<std::int32_t[]> owner;  // row-major over the window
  std::vector<std::size_t> row_count;  // covered texels per row (indexed from row0), then offsets

  void collect_faces();
  std::int64_t assign_owners();
  void centre_pass(int y, std::int32_t* row_owner, RowScratch& scratch) const;
  void conservative_pass(int y, std::int32_t* row_owner, RowScratch& scratch) const;
  bool describe_faces(TexelSpace& space) const;
  void emit_texels(TexelSpace& space, bool lifted) const;
};

// Footprints of the usable faces, in face order; surfaces indexed by face.
void Rasteriser::collect_faces() {
  surfaces.resize(tri_mesh.n_faces());
  footprints.reserve(tri_mesh.n_faces());
  for (const auto f : tri_mesh.faces()) {
    const Triangle tri = triangle(tri_mesh, f);
    FaceFootprint fp;
    if (!make_footprint(tri, f.idx(), width, height, fp)) continue;
    describe_surface(tri, surfaces[f.idx()]);
    footprints.push_back(fp);
  }
}

// Passes 1 and 2, row by row: the owner code of every texel of the window, and covered texels
// per row (indexed from row0). Returns the texels whose centre two faces' interiors share.
std::int64_t Rasteriser::assign_owners() {
  const int window = row1 - row0;
  // Left unwritten here: each row fills its own, in parallel (a 4096² lightmap's are 67 MB of
  // fresh pages, whose first touch is a fault).
  owner.reset(new std::int32_t[std::size_t(window) * std::size_t(width)]);
  row_count.assign(std::size_t(window) + 1, 0);
  std::atomic<std::int64_t> overlapping{0};
  tbb::parallel_for(tbb::blocked_range<int>(row0, row1), [&](const tbb::blocked_range<int>& rows) {
    RowScratch scratch(width);
    for (int y = rows.begin(); y != rows.end(); ++y) {
      std::fill(scratch.row_overlap.begin(), scratch.row_overlap.end(), 0);
      std::int32_t* row_owner = &owner[std::size_t(y - row0) * std::size_t(width)];
      std::fill(row_owner, row_owner + width, kUncovered);
      centre_pass(y, row_owner, scratch);
      conservative_pass(y, row_owner, scratch);
      std::size_t count = 0;
      for (int x = 0; x < width; ++x) count += row_owner[x] != kUncovered;
      row_count[std::size_t(y - row0) + 1] = count;
      std::int64_t overlaps = 0;
      for (const std::uint8_t o : scratch.row_overlap) overlaps += o;
      overlapping += overlaps;
    }
  });
  return overlapping.load();
}

// Pass 1 on row y: each texel whose centre a footprint holds goes to the first such face.
void Rasteriser::centre_pass(int y, std::int32_t* row_owner, RowScratch& scratch) const {
  const auto faces_begin =
      row_faces.faces.begin() + std::ptrdiff_t(row_faces.begin[std::size_t(y)]);
  const auto faces_end =
      row_faces.faces.begin() + std::ptrdiff_t(row_faces.begin[std::size_t(y) + 1]);
  const double centre_y = y + 0.5;
  for (auto it = faces_begin; it != faces_end; ++it) {
    const FaceFootprint& fp = footprints[std::size_t(*it)];
    int first, last;
    if (!row_span(fp, y, width, first, last)) continue;
    const double row_term[3] = {fp.edge[0].row_term(centre_y), fp.edge[1].row_term(centre_y),
                                fp.edge[2].row_term(centre_y)};
    for (int x = first; x <= last; ++x) {
      const double centre_x = x + 0.5;
      const double e0 = fp.edge[0](centre_x, row_term[0]);
      const double e1 = fp.edge[1](centre_x, row_term[1]);
      const double e2 = fp.edge[2](centre_x, row_term[2]);
      if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) continue;
      const bool strictly = e0 > 0.0 && e1 > 0.0 && e2 > 0.0;
      if (row_owner[x] == kUncovered) {
        row_owner[x] = fp.face;
        scratch.row_strict[std::size_t(x)] = strictly;
      } else if (strictly || scratch.row_strict[std::size_t(x)]) {
        // Two triangles share a centre on a common edge or vertex (inside neither strictly);
        // one strictly inside means their interiors overlap.
        scratch.row_overlap[std::size_t(x)] = 1;
      }
    }
  }
}

// Pass 2 on row y: each texel no centre claimed goes to the overlapping face nearest its centre.
void Rasteriser::conservative_pass(int y, std::int32_t* row_owner, RowScratch& scratch) const {
  const auto faces_begin =
      row_faces.faces.begin() + std::ptrdiff_t(row_faces.begin[std::size_t(y)]);
  const auto faces_end =
      row_faces.faces.begin() + std::ptrdiff_t(row_faces.begin[std::size_t(y) + 1]);
  const double centre_y = y + 0.5;
  const double centre_v = 1.0 - centre_y / height;
  for (auto it = faces_begin; it != faces_end; ++it) {
    const FaceFootprint& fp = footprints[std::size_t(*it)];
    int first, last;
    if (!row_span(fp, y, width, first, last)) continue;
    for (int x = first; x <= last; ++x) {
      const std::int32_t code = row_owner[x];
      if (is_centre_code(code) || !overlaps_texel(fp, x, y)) continue;
      double bary[3];
      const Vec2 centre_uv((x + 0.5) / width, centre_v);
      const double d = nearest_point(fp.uv[0], fp.uv[1], fp.uv[2], centre_uv, bary);
      // Faces come in increasing order, so strict < keeps the lowest face index on ties.
      if (code == kUncovered || d < scratch.best_distance[std::size_t(x)]) {
        row_owner[x] = conservative_code(fp.face);
        scratch.best_distance[std::size_t(x)] = d;
      }
    }
  }
}

// The per-face outputs: normals, texel sizes and, where some face is smooth, its shading corners.
// Returns whether some face is curved, so that its texels' shadow origins lift.
bool Rasteriser::describe_faces(TexelSpace& space) const {
  space.face_normals.resize(tri_mesh.n_faces(), Vec3f::Zero());
  space.face_texel_sizes.resize(tri_mesh.n_faces(), 0.0f);
  bool lifted = false, smooth = false;
  for (const FaceFootprint& fp : footprints) {
    const FaceSurface& s = surfaces[std::size_t(fp.face)];
    space.face_normals[std::size_t(fp.face)] = s.face_normal.cast<float>();
    space.face_texel_sizes[std::size_t(fp.face)] = float(texel_step(fp, s));
    lifted = lifted || s.curved;
    smooth = smooth || s.normal[0] != s.normal[1] || s.normal[0] != s.normal[2];
  }
  if (smooth) {
    space.face_shading.resize(tri_mesh.n_faces());
    for (const FaceFootprint& fp : footprints) {
      const FaceSurface& s = surfaces[std::size_t(fp.face)];
      TexelSpace::FaceShading& shading = space.face_shading[std::size_t(fp.face)];
      for (int i = 0; i < 3; ++i) {
        shading.corner[i] = fp.texel_uv[i].cast<float>();
        shading.normal[i] = s.normal[i].cast<float>();
      }
    }
  }
  return lifted;
}

// The texels of the window in row-major order, from their owner codes, with their lifts (when
// `lifted`) and their blocks' summaries; marks them covered.
void Rasteriser::emit_texels(TexelSpace& space, bool lifted) const {
  std::vector<int> footprint_of_face(tri_mesh.n_faces(), -1);
  for (std::size_t i = 0; i < footprints.size(); ++i)
    footprint_of_face[std::size_t(footprints[i].face)] = int(i);
  // By rows of blocks, so that each block's summary (TexelBlock) is one task's.
  constexpr int kBlock = TexelBlock::kSide;
  space.blocks_x = (width + kBlock - 1) / kBlock;
  space.blocks.assign(std::size_t(space.blocks_x) * std::size_t((height + kBlock - 1) / kBlock),
                      TexelBlock());
  tbb::parallel_for(
      tbb::blocked_range<int>(row0 / kBlock, (row1 + kBlock - 1) / kBlock),
      [&](const tbb::blocked_range<int>& block_rows) {
        const int y_begin = std::max(row0, block_rows.begin() * kBlock);
        const int y_end = std::min(row1, block_rows.end() * kBlock);
        for (int y = y_begin; y < y_end; ++y) {
          std::size_t out = row_count[std::size_t(y - row0)];
          const std::size_t row_offset = std::size_t(y) * std::size_t(width);
          const std::size_t owner_offset = std::size_t(y - row0) * std::size_t(width);
          const double centre_y = y + 0.5;
          const double centre_v = 1.0 - centre_y / height;
          for (int x = 0; x < width; ++x) {
            const std::int32_t code = owner[owner_offset + std::size_t(x)];
            if (code == kUncovered) continue;
            const int face = face_of(code);
            const FaceFootprint& fp = footprints[std::size_t(footprint_of_face[std::size_t(face)])];
            double bary[3] = {};
            // Pass 1 found the centre inside, so centre_barycentrics succeeds; the nearest point
            // is the same point should it not.
            if (!is_centre_code(code) || !centre_barycentrics(fp, x + 0.5, centre_y, bary))
              nearest_point(fp.uv[0], fp.uv[1], fp.uv[2], Vec2((x + 0.5) / width, centre_v), bary);
            Vec3f lift = Vec3f::Zero();
            space.texels[out] = make_texel(surfaces[std::size_t(face)], face, x, y, bary, lift);
            if (lifted) space.lifts[out] = lift;
            add_to_block(space, out, lift);  // make_texel's lift is 0 on a flat face
            ++out;
            space.covered[row_offset + std::size_t(x)] = 1;
          }
        }
      });
}

}  // namespace

TexelSpace rasterise_texels(const Mesh& mesh, int width, int height, RowRange rows) {
  assert(width > 0 && height > 0);
  TexelSpace space;
  if (width <= 0 || height <= 0) return space;
  space.width = width;
  space.height = height;
  const std::size_t texel_count = std::size_t(width) * std::size_t(height);
  space.covered.assign(texel_count, 0);
  // The rows rasterised: all, or a tile's (rows are independent, so a row's texels are the same).
  const int row0 = std::clamp(rows.begin, 0, height), row1 = std::clamp(rows.end, row0, height);
  const int window = row1 - row0;
  if (!mesh.has_uv) return space;  // no lightmap UVs: nothing is covered

  Rasteriser r{mesh.mesh, width, height, row0, row1, {}, {}, {}, {}, {}};
  r.collect_faces();
  r.row_faces = index_rows(r.footprints, height);
  space.overlapping_texels = r.assign_owners();

  // Offsets of each row's texels in the row-major output, then the texels themselves.
  for (int y = 0; y < window; ++y) r.row_count[std::size_t(y) + 1] += r.row_count[std::size_t(y)];
  space.texels.resize(r.row_count[std::size_t(window)]);
  const bool lifted = r.describe_faces(space);
  if (lifted) space.lifts.resize(space.texels.size());
  r.emit_texels(space, lifted);
  return space;
}

}  // namespace sb
