// Ambient occlusion by rays against closed forms. Under a parallel ceiling at height h, a ray at
// angle θ from the floor's normal meets it after h / cos θ, so within a distance d it is blocked
// when cos θ > h / d; cosine-weighted, P(cos θ ≤ c) = c², so A = (h / d)² for h < d and 1 for
// h ≥ d. Beside a wall, every ray leaving towards it is blocked: A = 1/2.
#include <gtest/gtest.h>

#include <cmath>

#include "methods/ambient_occlusion.h"
#include "support/test_scenes.h"

namespace sb {
namespace {

// A square of half-width `half` centred on `centre`, spanned by unit axes a and b, two triangles.
Mesh square(const Vec3& centre, const Vec3& a, const Vec3& b, double half) {
  Mesh m;
  m.name = "square";
  TriMesh& t = m.mesh;
  TriMesh::VertexHandle v[4];
  const double st[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (int i = 0; i < 4; ++i) {
    const Vec3 p = centre + half * (st[i][0] * a + st[i][1] * b);
    v[i] = t.add_vertex(TriMesh::Point(p.x(), p.y(), p.z()));
  }
  t.add_face(v[0], v[1], v[2]);
  t.add_face(v[0], v[2], v[3]);
  return m;
}

// Texels facing up on the floor z = 0 at x ∈ [x0, x1], y = 0.
TexelSpace floor_texels(double x0, double x1, int n) {
  TexelSpace s;
  s.width = n;
  s.height = 1;
  s.covered.assign(std::size_t(n), 1);
  s.face_normals = {Vec3f::UnitZ()};
  for (int i = 0; i < n; ++i) {
    Texel t;
    t.x = std::uint16_t(i);
    t.face = 0;
    t.position = Vec3f(float(x0 + (x1 - x0) * i / (n - 1)), 0.0f, 0.0f);
    t.normal = Vec3f::UnitZ();
    s.texels.push_back(t);
  }
  return s;
}

// The ambient occlusion of `space` among `blockers`, its texels' own mesh `own` (or none).
Image occlusion_image(const std::vector<const Mesh*>& blockers, const Mesh* own,
                      const TexelSpace& space, double distance, int samples, std::int64_t* traced) {
  auto rays = RayScene::build(blockers);
  EXPECT_TRUE(rays);
  AmbientOcclusionInputs in;
  in.rays = &*rays;
  in.mesh = own;
  in.distance = distance;
  in.samples = samples;
  in.seed = 5;
  return bake_ambient_occlusion(space, in, traced);
}

// Per texel A, and their mean.
std::vector<double> occlusion(const Mesh& blocker, const TexelSpace& space, double distance,
                              int samples, double* mean) {
  std::int64_t traced = 0;
  const Image image = occlusion_image({&blocker}, nullptr, space, distance, samples, &traced);
  EXPECT_EQ(traced, std::int64_t(space.texels.size()) * samples);
  std::vector<double> a;
  *mean = 0;
  for (const Texel& t : space.texels) {
    a.push_back(image.at(t.x, t.y)[0]);
    EXPECT_EQ(image.at(t.x, t.y)[0], image.at(t.x, t.y)[2]);
    *mean += a.back() / double(space.texels.size());
  }
  return a;
}

TEST(AmbientOcclusion, UnderAParallelCeilingIsTheSquareOfHeightOverDistance) {
  const Mesh ceiling = square(Vec3(0, 0, 1), Vec3::UnitX(), Vec3::UnitY(), 200);
  const TexelSpace space = floor_texels(-1, 1, 64);
  for (const double d : {1.25, 2.0, 4.0}) {
    double mean = 0;
    const double expected = 1.0 / (d * d);
    for (double a : occlusion(ceiling, space, d, 256, &mean)) EXPECT_NEAR(a, expected, 0.08) << d;
    EXPECT_NEAR(mean, expected, 0.006) << d;
  }
  // Nearer than the ceiling nothing occludes; far beyond it nearly every ray is closed.
  double mean = 0;
  for (double a : occlusion(ceiling, space, 0.9, 64, &mean)) EXPECT_EQ(a, 1.0);
  occlusion(ceiling, space, 1e4, 64, &mean);
  EXPECT_LT(mean, 1e-3);
}

TEST(AmbientOcclusion, BesideAWallHalfTheHemisphereIsClosed) {
  const Mesh wall = square(Vec3(0, 0, 0), Vec3::UnitY(), Vec3::UnitZ(), 200);
  const TexelSpace space = floor_texels(0.05, 1.0, 32);
  double mean = 0;
  occlusion(wall, space, 1e3, 256, &mean);
  EXPECT_NEAR(mean, 0.5, 0.005);
  // Within 0.2 m, a texel 0.1 m from the wall has a ray closed where its component towards the
  // wall exceeds 0.1 / 0.2. Cosine-weighted directions are uniform points of the unit disk lifted
  // up, so that component is a uniform disk point's x: closed with the probability of the disk's
  // segment beyond x = 1/2, (acos(1/2) − (1/2)·√(3/4)) / π, and A = 1 minus it.
  const TexelSpace near = floor_texels(0.1, 0.1001, 2);
  occlusion(wall, near, 0.2, 1024, &mean);
  EXPECT_NEAR(mean, 1 - (std::acos(0.5) - 0.5 * std::sqrt(0.75)) / M_PI, 0.01);
}

// Texels on z = height at x ∈ [x0, x1], y = 0, facing `up` or down, their face's winding
// `winding` (the same way as their normal unless a test says otherwise).
TexelSpace facing_texels(double x0, double x1, int n, double height, bool up, bool winding_agrees) {
  TexelSpace s = floor_texels(x0, x1, n);
  const Vec3f normal = up ? Vec3f::UnitZ() : Vec3f(-Vec3f::UnitZ());
  s.face_normals = {winding_agrees ? normal : Vec3f(-normal)};
  for (Texel& t : s.texels) {
    t.position.z() = float(height);
    t.normal = normal;
  }
  return s;
}

// Per texel A over `blockers`, the texels' own mesh `own` (or none), 256 rays each.
std::vector<double> occlusion_among(const std::vector<const Mesh*>& blockers, const Mesh* own,
                                    const TexelSpace& space, double distance) {
  const Image image = occlusion_image(blockers, own, space, distance, 256, nullptr);
  std::vector<double> a;
  for (const Texel& t : space.texels) a.push_back(image.at(t.x, t.y)[0]);
  return a;
}

// Mirrors a square's winding (its faces seen from the other side).
Mesh flipped(Mesh m) {
  TriMesh t;
  std::vector<TriMesh::VertexHandle> v;
  for (const auto vh : m.mesh.vertices()) v.push_back(t.add_vertex(m.mesh.point(vh)));
  for (const auto f : m.mesh.faces()) {
    std::vector<TriMesh::VertexHandle> corners;
    for (const auto vh : m.mesh.fv_range(f)) corners.push_back(v[std::size_t(vh.idx())]);
    t.add_face(corners[0], corners[2], corners[1]);
  }
  m.mesh = t;
  return m;
}

// A closed box between corners lo and hi, wound outwards, added to m (12 triangles).
void add_box(Mesh& m, const Vec3& lo, const Vec3& hi) {
  TriMesh& t = m.mesh;
  TriMesh::VertexHandle v[8];
  for (int i = 0; i < 8; ++i)
    v[i] = t.add_vertex(
        TriMesh::Point(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z()));
  // Each side's corners counter-clockwise seen from outside.
  const int sides[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : sides) {
    t.add_face(v[q[0]], v[q[1]], v[q[2]]);
    t.add_face(v[q[0]], v[q[2]], v[q[3]]);
  }
}

Mesh box(const Vec3& lo, const Vec3& hi) {
  Mesh m;
  m.name = "box";
  add_box(m, lo, hi);
  return m;
}

// The bottom of a leg standing on a floor, and the floor under it, see nothing: each is pressed
// against a surface facing it with the inside of a solid on one side, and their rays, which start
// a surface offset off the surface, would start beyond that cover and escape (every one of them,
// under a leg's bottom on a floor with nothing below it). The issue "Where engines look" found
// 144 such texels on the level's chair at 1.0.
TEST(AmbientOcclusion, ASurfacePressedAgainstAnotherIsClosed) {
  // A floor (facing up, z = 0) under the bottom of a leg (a box standing on it; the texels face
  // down on the leg's bottom, their own mesh).
  const Mesh floor = square(Vec3(0, 0, 0), Vec3::UnitX(), Vec3::UnitY(), 0.5);
  const Mesh leg = box(Vec3(-0.45, -0.05, 0), Vec3(0.45, 0.05, 0.7));
  for (double a :
       occlusion_among({&floor, &leg}, &leg, facing_texels(-0.4, 0.4, 16, 0, false, true), 0.1))
    EXPECT_EQ(a, 0.0);
  // Hovering 5 cm above it, the same texels see the floor as a ceiling: (h / d)² = 1/4.
  double mean = 0;
  for (double a :
       occlusion_among({&floor}, nullptr, facing_texels(-0.4, 0.4, 16, 0.05, false, true), 0.1))
    mean += a / 16;
  EXPECT_NEAR(mean, 0.25, 0.03);
  // A 1 mm plate lying on the floor closes the floor's texels under it, and only those (beside
  // it, its edge closes a ray in thousands).
  const Mesh plate = box(Vec3(-0.25, -0.25, 0), Vec3(0.25, 0.25, 0.001));
  const std::vector<double> under =
      occlusion_among({&plate}, nullptr, facing_texels(-0.5, 0.5, 21, 0, true, true), 1.0);
  for (std::size_t i = 0; i < under.size(); ++i) {
    const double x = -0.5 + 0.05 * double(i);
    if (std::abs(x) < 0.24) {
      EXPECT_EQ(under[i], 0.0) << x;
    } else if (std::abs(x) > 0.26) {
      EXPECT_GT(under[i], 0.99) << x;
    }
  }
  // The same within one mesh: a leg's top joined to the seat above it, the seat's bottom facing
  // against the texels' own face's winding.
  Mesh chair;
  add_box(chair, Vec3(-0.1, -0.1, 0), Vec3(0.1, 0.1, 0.5));
  add_box(chair, Vec3(-0.3, -0.3, 0.5), Vec3(0.3, 0.3, 0.55));
  for (double a :
       occlusion_among({&chair}, &chair, facing_texels(-0.08, 0.08, 9, 0.5, true, true), 1.0))
    EXPECT_EQ(a, 0.0);
}

// Surfaces facing the same way do not cover each other (a decal on a floor), nor does the texels'
// own face where its winding disagrees with their normal (a mesh whose normals were flipped but
// not its faces), nor the other face of a two-sided sheet, open on both sides (a level's thin
// wall or card, two coplanar faces back to back: Godot's zdm2 has 7,700 texels on such faces).
TEST(AmbientOcclusion, NoCoverFacingTheSameWayOrFromTheTexelsOwnFace) {
  const Mesh decal = square(Vec3(0, 0, 0), Vec3::UnitX(), Vec3::UnitY(), 0.5);
  for (double a :
       occlusion_among({&decal}, nullptr, facing_texels(-0.4, 0.4, 16, 0, true, true), 1.0))
    EXPECT_EQ(a, 1.0);
  const Mesh own = flipped(decal);
  for (double a : occlusion_among({&own}, &own, facing_texels(-0.4, 0.4, 16, 0, true, false), 1.0))
    EXPECT_EQ(a, 1.0);
  // A two-sided card, its faces in one mesh or two, seen from either side.
  Mesh card = decal;
  for (const auto f : own.mesh.faces()) {
    std::vector<TriMesh::VertexHandle> corners;
    for (const auto vh : own.mesh.fv_range(f))
      corners.push_back(card.mesh.add_vertex(own.mesh.point(vh)));
    card.mesh.add_face(corners[0], corners[1], corners[2]);
  }
  for (const bool up : {true, false}) {
    for (double a : occlusion_among({&card}, &card, facing_texels(-0.4, 0.4, 16, 0, up, true), 1.0))
      EXPECT_EQ(a, 1.0) << up;
    for (double a :
         occlusion_among({&decal, &own}, nullptr, facing_texels(-0.4, 0.4, 16, 0, up, true), 1.0))
      EXPECT_EQ(a, 1.0) << up;
  }
}

}  // namespace
}  // namespace sb
