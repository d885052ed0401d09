// Tests of rasterise_texels (src/texels/uv_rasterizer.cpp): texel conventions, exact interpolation,
// conservative coverage of thin triangles, watertight shared edges, normals, determinism.
//
// Most meshes map world = (u, v, 0), so a texel's position is directly its UV point and can be
// checked against the UV triangle. Coverage is checked against an independent oracle: clipping the
// triangle to each texel square (Sutherland–Hodgman) and keeping squares of positive overlap area.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <set>
#include <utility>
#include <vector>

#include "texels/texel_space.h"

namespace sb {
namespace {

struct Vertex {
  Vec3 position;
  Vec2 uv;
  Vec3 normal = Vec3::UnitZ();
};

Mesh make_mesh(const std::vector<Vertex>& vertices, const std::vector<std::array<int, 3>>& faces) {
  Mesh mesh;
  mesh.name = "test";
  mesh.has_uv = true;
  std::vector<TriMesh::VertexHandle> handles;
  for (const Vertex& v : vertices) {
    const auto h =
        mesh.mesh.add_vertex(TriMesh::Point(v.position.x(), v.position.y(), v.position.z()));
    mesh.mesh.set_texcoord2D(h, TriMesh::TexCoord2D(v.uv.x(), v.uv.y()));
    mesh.mesh.set_normal(h, TriMesh::Normal(v.normal.x(), v.normal.y(), v.normal.z()));
    handles.push_back(h);
  }
  for (const auto& f : faces) mesh.mesh.add_face(handles[f[0]], handles[f[1]], handles[f[2]]);
  mesh.mesh.update_face_normals();
  return mesh;
}

// A vertex whose world position is its UV point on the z = 0 plane.
Vertex flat(double u, double v, Vec3 normal = Vec3::UnitZ()) {
  return {Vec3(u, v, 0.0), Vec2(u, v), normal};
}

// A mesh of triangles given in UV, each with its own three flat vertices.
Mesh flat_mesh(const std::vector<std::array<Vec2, 3>>& triangles) {
  std::vector<Vertex> vertices;
  std::vector<std::array<int, 3>> faces;
  for (const auto& t : triangles) {
    const int base = int(vertices.size());
    for (const Vec2& uv : t) vertices.push_back(flat(uv.x(), uv.y()));
    faces.push_back({base, base + 1, base + 2});
  }
  return make_mesh(vertices, faces);
}

// The full unit square as two triangles, split along the diagonal (0, 0)–(1, 1).
Mesh full_quad() {
  return make_mesh({flat(0, 0), flat(1, 0), flat(1, 1), flat(0, 1)}, {{0, 1, 2}, {0, 2, 3}});
}

Vec2 texel_centre_uv(int x, int y, int width, int height) {
  return Vec2((x + 0.5) / width, 1.0 - (y + 0.5) / height);
}

// Converts a point given in texel coordinates (X = u * width, Y = (1 - v) * height) to UV.
Vec2 uv_of_texel_point(double x, double y, int width, int height) {
  return Vec2(x / width, 1.0 - y / height);
}

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Barycentrics of p in UV triangle t.
Vec3 barycentrics(const std::array<Vec2, 3>& t, const Vec2& p) {
  const double area = cross(t[1] - t[0], t[2] - t[0]);
  const double b1 = cross(p - t[0], t[2] - t[0]) / area;
  const double b2 = cross(t[1] - t[0], p - t[0]) / area;
  return Vec3(1.0 - b1 - b2, b1, b2);
}

// Area of triangle t (UV) clipped to texel (x, y), in texels².
double overlap_area_texels(const std::array<Vec2, 3>& t, int x, int y, int width, int height) {
  std::vector<Vec2> polygon;
  for (const Vec2& uv : t) polygon.push_back(Vec2(uv.x() * width, (1.0 - uv.y()) * height));
  // Clip against x >= x0, x <= x1, y >= y0, y <= y1 in turn.
  const std::array<std::pair<Vec2, double>, 4> planes = {{{Vec2(1, 0), double(x)},
                                                          {Vec2(-1, 0), -double(x + 1)},
                                                          {Vec2(0, 1), double(y)},
                                                          {Vec2(0, -1), -double(y + 1)}}};
  for (const auto& [normal, offset] : planes) {
    std::vector<Vec2> clipped;
    for (std::size_t i = 0; i < polygon.size(); ++i) {
      const Vec2& a = polygon[i];
      const Vec2& b = polygon[(i + 1) % polygon.size()];
      const double da = normal.dot(a) - offset, db = normal.dot(b) - offset;
      if (da >= 0) clipped.push_back(a);
      if ((da >= 0) != (db >= 0)) clipped.push_back(a + (b - a) * (da / (da - db)));
    }
    polygon = std::move(clipped);
    if (polygon.empty()) return 0.0;
  }
  double area = 0.0;
  for (std::size_t i = 0; i < polygon.size(); ++i)
    area += cross(polygon[i], polygon[(i + 1) % polygon.size()]);
  return 0.5 * std::abs(area);
}

std::set<std::pair<int, int>> covered_set(const TexelSpace& space) {
  std::set<std::pair<int, int>> set;
  for (const Texel& t : space.texels) set.insert({t.x, t.y});
  return set;
}

// Each block's summary is its texels' own: the box of their positions, exactly, and uniform just
// where they share their shading and geometric normals and lift nothing.
void expect_blocks(const TexelSpace& space) {
  constexpr int k = TexelBlock::kSide;
  ASSERT_EQ(space.blocks_x, (space.width + k - 1) / k);
  ASSERT_EQ(space.blocks.size(), std::size_t(space.blocks_x) * ((space.height + k - 1) / k));
  std::vector<TexelBlock> own(space.blocks.size());
  std::vector<std::uint8_t> shared(space.blocks.size(), 1);
  for (std::size_t i = 0; i < space.texels.size(); ++i) {
    const Texel& t = space.texels[i];
    const std::size_t b = std::size_t(t.y / k) * std::size_t(space.blocks_x) + t.x / k;
    TexelBlock& o = own[b];
    if (o.empty()) {
      o.lo = o.hi = t.position;
      o.normal = t.normal;
      o.geometric = space.geometric_normal(i);
    }
    o.lo = o.lo.cwiseMin(t.position);
    o.hi = o.hi.cwiseMax(t.position);
    shared[b] = shared[b] && t.normal == o.normal && space.geometric_normal(i) == o.geometric &&
                space.shadow_origin(i) == t.position;
  }
  for (std::size_t b = 0; b < own.size(); ++b) {
    const TexelBlock& got = space.blocks[b];
    ASSERT_EQ(got.empty(), own[b].empty()) << "block " << b;
    if (got.empty()) continue;
    EXPECT_EQ(got.lo, own[b].lo) << "block " << b;
    EXPECT_EQ(got.hi, own[b].hi) << "block " << b;
    EXPECT_EQ(got.uniform, bool(shared[b])) << "block " << b;
    if (got.uniform) {
      EXPECT_EQ(got.normal, own[b].normal);
      EXPECT_EQ(got.geometric, own[b].geometric);
    }
  }
}

// Common invariants: row-major order, no duplicates, `covered` agrees with `texels`.
void expect_consistent(const TexelSpace& space) {
  ASSERT_EQ(space.covered.size(), std::size_t(space.width) * space.height);
  for (std::size_t i = 1; i < space.texels.size(); ++i) {
    const Texel& a = space.texels[i - 1];
    const Texel& b = space.texels[i];
    EXPECT_TRUE(a.y < b.y || (a.y == b.y && a.x < b.x)) << "texel " << i << " out of order";
  }
  std::size_t covered_count = 0;
  for (const std::uint8_t c : space.covered) covered_count += c;
  EXPECT_EQ(covered_count, space.texels.size());
  for (const Texel& t : space.texels) {
    ASSERT_TRUE(t.x >= 0 && t.x < space.width && t.y >= 0 && t.y < space.height);
    EXPECT_EQ(space.covered[std::size_t(t.y) * space.width + t.x], 1);
  }
  expect_blocks(space);
}

TEST(UvRasterizer, FullQuadCoversEveryTexelWithExactPositions) {
  const int width = 16, height = 8;  // not square, so u and v cannot be swapped unnoticed
  const TexelSpace space = rasterise_texels(full_quad(), width, height);
  EXPECT_EQ(space.width, width);
  EXPECT_EQ(space.height, height);
  ASSERT_EQ(space.texels.size(), std::size_t(width * height));
  expect_consistent(space);
  for (std::size_t i = 0; i < space.texels.size(); ++i) {
    const Texel& t = space.texels[i];
    EXPECT_EQ(t.x, int(i) % width);
    EXPECT_EQ(t.y, int(i) / width);
    const Vec2 uv = texel_centre_uv(t.x, t.y, width, height);
    EXPECT_NEAR(t.position.x(), uv.x(), 1e-6);
    EXPECT_NEAR(t.position.y(), uv.y(), 1e-6);
    EXPECT_EQ(t.position.z(), 0.0);
    EXPECT_TRUE(t.face == 0 || t.face == 1);
  }
}

TEST(UvRasterizer, RowZeroIsVOne) {
  const int width = 16, height = 16;
  // A triangle in the top half of UV space (v >= 0.5), its base exactly on v = 0.5.
  const Mesh mesh = flat_mesh({{Vec2(0.0, 0.5), Vec2(1.0, 0.5), Vec2(0.5, 1.0)}});
  const TexelSpace space = rasterise_texels(mesh, width, height);
  expect_consistent(space);
  ASSERT_FALSE(space.texels.empty());
  EXPECT_EQ(space.texels.front().y, 0);
  for (const Texel& t : space.texels) {
    EXPECT_LT(t.y, height / 2);
    EXPECT_GE(t.position.y(), 0.5);
  }
  // Row h/2 - 1 lies just above the base: fully covered.
  for (int x = 0; x < width; ++x)
    EXPECT_EQ(space.covered[std::size_t(height / 2 - 1) * width + x], 1) << "x = " << x;
}

TEST(UvRasterizer, CentreOnSharedEdgeGoesToFirstFace) {
  const int size = 8;
  // The diagonal u = v of full_quad() passes exactly through the centres with x + y = size - 1.
  const TexelSpace space = rasterise_texels(full_quad(), size, size);
  ASSERT_EQ(space.texels.size(), std::size_t(size * size));
  for (const Texel& t : space.texels) {
    const Vec2 uv = texel_centre_uv(t.x, t.y, size, size);
    const int expected_face = t.x + t.y == size - 1 ? 0 : (uv.x() > uv.y() ? 0 : 1);
    EXPECT_EQ(t.face, expected_face) << "texel (" << t.x << ", " << t.y << ")";
  }
}

TEST(UvRasterizer, ThinSliverGetsTexelsOnTheTriangle) {
  const int size = 32;
  // Much narrower than a texel (about 0.05 texels across) and lying between two rows of texel
  // centres (v = 0.484 and 0.516), so no texel centre is inside it.
  const std::array<Vec2, 3> sliver = {Vec2(0.1, 0.5), Vec2(0.9, 0.502), Vec2(0.5, 0.5025)};
  const TexelSpace space = rasterise_texels(flat_mesh({sliver}), size, size);
  expect_consistent(space);
  ASSERT_FALSE(space.texels.empty());
  for (const Texel& t : space.texels) {
    const Vec3 b = barycentrics(sliver, Vec2(t.position.x(), t.position.y()));
    // Positions are single precision: 1e-4 of this 0.0025-wide sliver's barycentrics is 2.5e-7
    // in UV, float rounding at coordinates near 1.
    EXPECT_GE(b.minCoeff(), -1e-4) << "texel (" << t.x << ", " << t.y << ") is off the triangle";
    EXPECT_EQ(t.face, 0);
  }
  // Exactly the texels the sliver overlaps: every one it crosses, none it does not.
  std::set<std::pair<int, int>> expected;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      if (overlap_area_texels(sliver, x, y, size, size) > 1e-12) expected.insert({x, y});
  EXPECT_EQ(covered_set(space), expected);
  // It spans from u = 0.1 to 0.9: about 26 columns, each needing at least one texel.
  std::set<int> columns;
  for (const Texel& t : space.texels) columns.insert(t.x);
  EXPECT_EQ(columns.size(), std::size_t(std::ceil(0.9 * size) - std::floor(0.1 * size)));
}

TEST(UvRasterizer, SharedEdgeCoversEachTexelOnceWithoutGaps) {
  const int width = 40, height = 40;
  // An irregular quad, split along a diagonal at an angle that no texel row or column follows.
  const Vec2 a(0.1, 0.13), b(0.83, 0.2), c(0.9, 0.77), d(0.17, 0.91);
  const Mesh mesh =
      make_mesh({flat(a.x(), a.y()), flat(b.x(), b.y()), flat(c.x(), c.y()), flat(d.x(), d.y())},
                {{0, 1, 2}, {0, 2, 3}});
  const TexelSpace space = rasterise_texels(mesh, width, height);
  expect_consistent(space);  // includes: no texel twice
  const std::array<Vec2, 3> first = {a, b, c}, second = {a, c, d};
  std::set<std::pair<int, int>> expected;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double overlap = overlap_area_texels(first, x, y, width, height) +
                             overlap_area_texels(second, x, y, width, height);
      if (overlap > 1e-12) expected.insert({x, y});
    }
  EXPECT_EQ(covered_set(space), expected);
  // Texels whose centre is inside the quad take the point at their centre, from either face.
  for (const Texel& t : space.texels) {
    const Vec2 centre = texel_centre_uv(t.x, t.y, width, height);
    const bool inside = barycentrics(first, centre).minCoeff() >= 0.0 ||
                        barycentrics(second, centre).minCoeff() >= 0.0;
    if (inside) {
      EXPECT_NEAR(t.position.x(), centre.x(), 1e-6);
      EXPECT_NEAR(t.position.y(), centre.y(), 1e-6);
    }
  }
}

TEST(UvRasterizer, NormalsAreUnitAndInterpolated) {
  const int size = 24;
  const std::array<Vec3, 3> normals = {Vec3::UnitZ(), Vec3(1, 0, 1).normalized(),
                                       Vec3(0, 1, 1).normalized()};
  const std::array<Vec2, 3> uv = {Vec2(0.05, 0.05), Vec2(0.95, 0.1), Vec2(0.4, 0.9)};
  const Mesh mesh =
      make_mesh({flat(uv[0].x(), uv[0].y(), normals[0]), flat(uv[1].x(), uv[1].y(), normals[1]),
                 flat(uv[2].x(), uv[2].y(), normals[2])},
                {{0, 1, 2}});
  const TexelSpace space = rasterise_texels(mesh, size, size);
  ASSERT_FALSE(space.texels.empty());
  for (const Texel& t : space.texels) {
    EXPECT_NEAR(t.normal.norm(), 1.0, 1e-6);
    const Vec3 b = barycentrics(uv, Vec2(t.position.x(), t.position.y()));
    const Vec3 expected = (b[0] * normals[0] + b[1] * normals[1] + b[2] * normals[2]).normalized();
    EXPECT_NEAR((t.normal.cast<double>() - expected).norm(), 0.0, 1e-6)
        << "texel (" << t.x << ", " << t.y << ")";
  }
  // The normals really vary: the texels nearest vertices 1 and 2 lean towards +x and +y.
  const auto [lo, hi] = std::minmax_element(
      space.texels.begin(), space.texels.end(),
      [](const Texel& p, const Texel& q) { return p.normal.x() < q.normal.x(); });
  EXPECT_LT(lo->normal.x(), 0.1);
  EXPECT_GT(hi->normal.x(), 0.5);
}

TEST(UvRasterizer, GeometricNormalFacesTheShadingNormalsSide) {
  const int size = 8;
  // Counter-clockwise in world xy, so the face normal from positions is +z.
  for (const Vec3& shading : {Vec3(0, 0, 1), Vec3(0, 0, -1), Vec3(0.6, 0, -0.8)}) {
    const Mesh mesh =
        make_mesh({flat(0, 0, shading), flat(1, 0, shading), flat(0, 1, shading)}, {{0, 1, 2}});
    const TexelSpace space = rasterise_texels(mesh, size, size);
    ASSERT_FALSE(space.texels.empty());
    const Vec3 expected = shading.z() > 0 ? Vec3::UnitZ() : Vec3(-Vec3::UnitZ());
    for (std::size_t i = 0; i < space.texels.size(); ++i) {
      EXPECT_NEAR((space.geometric_normal(i).cast<double>() - expected).norm(), 0.0, 1e-6);
      EXPECT_GT(space.geometric_normal(i).dot(space.texels[i].normal), 0.0f);
    }
  }
  // A tilted triangle: the face normal is unit and perpendicular to its edges.
  const Mesh tilted = make_mesh({{Vec3(0, 0, 0), Vec2(0, 0), Vec3::UnitZ()},
                                 {Vec3(2, 0, 1), Vec2(1, 0), Vec3::UnitZ()},
                                 {Vec3(0, 3, 0), Vec2(0, 1), Vec3::UnitZ()}},
                                {{0, 1, 2}});
  const TexelSpace space = rasterise_texels(tilted, size, size);
  ASSERT_FALSE(space.texels.empty());
  const Vec3 expected = Vec3(2, 0, 1).cross(Vec3(0, 3, 0)).normalized();
  for (std::size_t i = 0; i < space.texels.size(); ++i) {
    EXPECT_NEAR((space.geometric_normal(i).cast<double>() - expected).norm(), 0.0, 1e-6);
    EXPECT_NEAR(space.texels[i].normal.norm(), 1.0, 1e-6);
  }
}

TEST(UvRasterizer, CoveredCountIsTheUvAreaWithinTheConservativeBand) {
  const int size = 64;
  const std::array<Vec2, 3> uv = {Vec2(0.12, 0.07), Vec2(0.81, 0.33), Vec2(0.37, 0.93)};
  const TexelSpace space = rasterise_texels(flat_mesh({uv}), size, size);
  expect_consistent(space);
  // Every texel overlapping the triangle is covered, so together they contain it: count >= area.
  // Each lies within √2 texels of it, so count <= area + √2 · perimeter + 2π (Steiner formula).
  const double area = 0.5 * std::abs(cross(uv[1] - uv[0], uv[2] - uv[0])) * size * size;
  const double perimeter =
      ((uv[1] - uv[0]).norm() + (uv[2] - uv[1]).norm() + (uv[0] - uv[2]).norm()) * size;
  const double count = double(space.texels.size());
  EXPECT_GE(count, area);
  EXPECT_LE(count, area + std::sqrt(2.0) * perimeter + 2.0 * std::numbers::pi);
  std::size_t overlapping = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) overlapping += overlap_area_texels(uv, x, y, size, size) > 1e-12;
  EXPECT_EQ(space.texels.size(), overlapping);
}

// Three triangles near texel (1, 1) of a 4 × 4 map (texel coordinates; centre (1.5, 1.5)), none
// containing its centre: `far` touches its lower-right corner; `right` and `left` are mirror images
// whose nearest points are equally far from the centre, and nearer than `far`'s.
std::array<Vec2, 3> in_uv(std::array<Vec2, 3> texel_points) {
  for (Vec2& p : texel_points) p = uv_of_texel_point(p.x(), p.y(), 4, 4);
  return texel_points;
}
const std::array<Vec2, 3> kFar = in_uv({Vec2(1.875, 1.9375), Vec2(3.5, 1.9375), Vec2(3.5, 2.0)});
const std::array<Vec2, 3> kRight =
    in_uv({Vec2(1.625, 1.25), Vec2(1.6875, 1.25), Vec2(1.6875, 0.5)});
const std::array<Vec2, 3> kLeft = in_uv({Vec2(1.375, 1.25), Vec2(1.3125, 1.25), Vec2(1.3125, 0.5)});

const Texel* find_texel(const TexelSpace& space, int x, int y) {
  for (const Texel& t : space.texels)
    if (t.x == x && t.y == y) return &t;
  return nullptr;
}

TEST(UvRasterizer, ConservativeTexelTakesTheNearestTriangle) {
  const TexelSpace space = rasterise_texels(flat_mesh({kFar, kRight}), 4, 4);
  const Texel* t = find_texel(space, 1, 1);
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->face, 1);
  // Its point is kRight's vertex nearest the centre.
  EXPECT_NEAR(t->position.x(), kRight[0].x(), 1e-12);
  EXPECT_NEAR(t->position.y(), kRight[0].y(), 1e-12);
}

TEST(UvRasterizer, ConservativeTieGoesToTheLowestFace) {
  for (const auto& [first, second] : {std::pair(kLeft, kRight), std::pair(kRight, kLeft)}) {
    const TexelSpace space = rasterise_texels(flat_mesh({kFar, first, second}), 4, 4);
    const Texel* t = find_texel(space, 1, 1);
    ASSERT_NE(t, nullptr);
    EXPECT_EQ(t->face, 1);
    EXPECT_NEAR(t->position.x(), first[0].x(), 1e-12);
  }
}

TEST(UvRasterizer, UvsOutsideTheUnitSquareAreClipped) {
  const int size = 16;
  const std::array<Vec2, 3> uv = {Vec2(-0.5, -0.25), Vec2(1.5, 0.2), Vec2(0.5, 1.75)};
  const TexelSpace space = rasterise_texels(flat_mesh({uv}), size, size);
  expect_consistent(space);
  std::size_t overlapping = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) overlapping += overlap_area_texels(uv, x, y, size, size) > 1e-12;
  EXPECT_EQ(space.texels.size(), overlapping);
}

TEST(UvRasterizer, SkipsTrianglesWithZeroUvArea) {
  // Collinear UVs: nothing to rasterise, and no texel for it.
  const Mesh mesh = make_mesh({{Vec3(0, 0, 0), Vec2(0.1, 0.1), Vec3::UnitZ()},
                               {Vec3(1, 0, 0), Vec2(0.5, 0.5), Vec3::UnitZ()},
                               {Vec3(0, 1, 0), Vec2(0.9, 0.9), Vec3::UnitZ()}},
                              {{0, 1, 2}});
  const TexelSpace space = rasterise_texels(mesh, 16, 16);
  EXPECT_TRUE(space.texels.empty());
  EXPECT_EQ(space.covered, std::vector<std::uint8_t>(16 * 16, 0));
}

bool same_texels(const TexelSpace& a, const TexelSpace& b) {
  if (a.texels.size() != b.texels.size() || a.covered != b.covered ||
      a.face_normals != b.face_normals || a.lifts != b.lifts)
    return false;
  for (std::size_t i = 0; i < a.texels.size(); ++i) {
    const Texel& p = a.texels[i];
    const Texel& q = b.texels[i];
    if (p.x != q.x || p.y != q.y || p.face != q.face || p.position != q.position ||
        p.normal != q.normal)
      return false;
  }
  return true;
}

TEST(UvRasterizer, SameResultOnAnyThreadCount) {
  // A fan of thin, overlapping triangles: many conservative texels with competing faces.
  std::vector<std::array<Vec2, 3>> fan;
  for (int i = 0; i < 40; ++i) {
    const double angle = 0.157 * i;
    const Vec2 direction(std::cos(angle), std::sin(angle));
    const Vec2 side(-direction.y(), direction.x());
    fan.push_back({Vec2(0.5, 0.5), Vec2(0.5, 0.5) + 0.45 * direction,
                   Vec2(0.5, 0.5) + 0.45 * direction + 0.004 * side});
  }
  const Mesh mesh = flat_mesh(fan);
  const TexelSpace parallel = rasterise_texels(mesh, 128, 96);
  TexelSpace serial;
  {
    tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    serial = rasterise_texels(mesh, 128, 96);
  }
  expect_consistent(parallel);
  EXPECT_TRUE(same_texels(parallel, serial));
  EXPECT_TRUE(same_texels(parallel, rasterise_texels(mesh, 128, 96)));
}

}  // namespace
}  // namespace sb

namespace sb {
namespace {

TEST(UvRasterizer, ShadowOriginIsThePositionOnFlatFaces) {
  const TexelSpace space = rasterise_texels(full_quad(), 16, 16);
  EXPECT_TRUE(space.lifts.empty());
  for (std::size_t i = 0; i < space.texels.size(); ++i)
    EXPECT_EQ(space.shadow_origin(i), space.texels[i].position);
}

// A flat quad's blocks are all uniform; a curved triangle's, whose normals vary, none.
TEST(UvRasterizer, BlocksSummariseTheirTexels) {
  const TexelSpace flat_space = rasterise_texels(full_quad(), 20, 12);
  expect_blocks(flat_space);
  for (const TexelBlock& b : flat_space.blocks) EXPECT_TRUE(b.uniform);
  const Vec3 n0 = Vec3(-1, -1, 2).normalized(), n1 = Vec3(1, -1, 2).normalized(),
             n2 = Vec3(0, 1, 2).normalized();
  const Mesh curved = make_mesh({flat(0, 0, n0), flat(1, 0, n1), flat(0.5, 1, n2)}, {{0, 1, 2}});
  const TexelSpace space = rasterise_texels(curved, 32, 32);
  expect_blocks(space);
  int uniform = 0;
  for (const TexelBlock& b : space.blocks) uniform += b.uniform;
  EXPECT_EQ(uniform, 0);
}

TEST(UvRasterizer, ShadowOriginLiftsOntoTheSmoothSurface) {
  // A flat triangle whose vertex normals lean outwards, as on a coarse sphere: its interior lies
  // below the vertices' tangent planes, and the shadow origin is lifted along +z, never lowered,
  // and not at all at the vertices.
  const Vec3 n0 = Vec3(-1, -1, 2).normalized(), n1 = Vec3(1, -1, 2).normalized(),
             n2 = Vec3(0, 1, 2).normalized();
  const Mesh mesh = make_mesh({flat(0, 0, n0), flat(1, 0, n1), flat(0.5, 1, n2)}, {{0, 1, 2}});
  const TexelSpace space = rasterise_texels(mesh, 32, 32);
  double highest = 0;
  ASSERT_EQ(space.lifts.size(), space.texels.size());
  for (std::size_t i = 0; i < space.texels.size(); ++i) {
    const Vec3 lift = (space.shadow_origin(i) - space.texels[i].position).cast<double>();
    EXPECT_GE(lift.z(), 0.0);
    highest = std::max(highest, lift.z());
  }
  EXPECT_GT(highest, 0.05);
}

}  // namespace
}  // namespace sb
