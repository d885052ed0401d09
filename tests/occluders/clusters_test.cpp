// Tests of the blocker cluster hierarchy and the light–receiver shaft (clusters.cpp, docs/design.md
// §5): connected components, leaves partitioning the faces, exact depth ranges against brute
// force, convexity of components, and shaft culling that never drops a face in the shaft.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <set>
#include <vector>

#include "methods/method.h"
#include "occluders/clusters.h"
#include "scene/mesh.h"
#include "scene/scene.h"

namespace sb {
namespace {

constexpr double kPi = std::numbers::pi;

TriMesh::VertexHandle add_point(TriMesh& mesh, const Vec3& p) {
  return mesh.add_vertex(TriMesh::Point(p.x(), p.y(), p.z()));
}

Vec3 point(const TriMesh& mesh, TriMesh::VertexHandle v) {
  const auto& p = mesh.point(v);
  return Vec3(p[0], p[1], p[2]);
}

// A prism over a counter-clockwise polygon (seen from +z) from z0 to z1, faces wound outward.
// The caps are fans from polygon[0], which must see every other vertex (a convex polygon, or an
// L whose first vertex is the reflex one). Each prism has vertices of its own, so prisms that
// touch are still separate components.
void add_prism(Mesh& m, const std::vector<Vec2>& polygon, double z0, double z1) {
  TriMesh& mesh = m.mesh;
  const std::size_t n = polygon.size();
  std::vector<TriMesh::VertexHandle> bottom, top;
  for (const Vec2& p : polygon) {
    bottom.push_back(add_point(mesh, Vec3(p.x(), p.y(), z0)));
    top.push_back(add_point(mesh, Vec3(p.x(), p.y(), z1)));
  }
  for (std::size_t i = 1; i + 1 < n; ++i) {
    mesh.add_face(top[0], top[i], top[i + 1]);
    mesh.add_face(bottom[0], bottom[i + 1], bottom[i]);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    mesh.add_face(bottom[i], bottom[j], top[j]);
    mesh.add_face(bottom[i], top[j], top[i]);
  }
}

void add_box(Mesh& m, const Vec3& lo, const Vec3& hi) {
  add_prism(
      m, {Vec2(lo.x(), lo.y()), Vec2(hi.x(), lo.y()), Vec2(hi.x(), hi.y()), Vec2(lo.x(), hi.y())},
      lo.z(), hi.z());
}

// A (u, v) grid of quads, two triangles each, wound so that outward(p) is in front of them.
// wrap_u / wrap_v close the grid; a pole row collapses to one vertex when position gives it.
void add_grid(Mesh& m, int nu, int nv, bool wrap_u, bool wrap_v,
              const std::function<Vec3(double, double)>& position,
              const std::function<Vec3(const Vec3&)>& outward) {
  TriMesh& mesh = m.mesh;
  const int cols = wrap_u ? nu : nu + 1;
  const int rows = wrap_v ? nv : nv + 1;
  std::vector<TriMesh::VertexHandle> v(static_cast<std::size_t>(cols * rows));
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i)
      v[j * cols + i] = add_point(mesh, position(i / double(nu), j / double(nv)));
  }
  auto at = [&](int i, int j) { return v[(j % rows) * cols + (i % cols)]; };
  auto triangle = [&](TriMesh::VertexHandle a, TriMesh::VertexHandle b, TriMesh::VertexHandle c) {
    const Vec3 pa = point(mesh, a), pb = point(mesh, b), pc = point(mesh, c);
    const Vec3 cross = (pb - pa).cross(pc - pa);
    if (cross.norm() < 1e-12) return;  // a collapsed pole triangle
    if (cross.dot(outward((pa + pb + pc) / 3)) < 0) std::swap(b, c);
    mesh.add_face(a, b, c);
  };
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      triangle(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      triangle(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  }
}

Mesh box_mesh(const Vec3& lo, const Vec3& hi) {
  Mesh m;
  add_box(m, lo, hi);
  return m;
}

// A UV sphere whose poles are single vertices, so it is closed.
Mesh sphere_mesh(const Vec3& centre, double radius, int nu, int nv) {
  Mesh m;
  TriMesh& mesh = m.mesh;
  const auto north = add_point(mesh, centre + Vec3(0, 0, radius));
  const auto south = add_point(mesh, centre - Vec3(0, 0, radius));
  std::vector<std::vector<TriMesh::VertexHandle>> rings;
  for (int j = 1; j < nv; ++j) {
    const double theta = kPi * j / nv;
    rings.emplace_back();
    for (int i = 0; i < nu; ++i) {
      const double phi = 2 * kPi * i / nu;
      rings.back().push_back(add_point(
          mesh, centre + radius * Vec3(std::sin(theta) * std::cos(phi),
                                       std::sin(theta) * std::sin(phi), std::cos(theta))));
    }
  }
  for (int i = 0; i < nu; ++i) {
    const int k = (i + 1) % nu;
    mesh.add_face(north, rings.front()[i], rings.front()[k]);
    mesh.add_face(south, rings.back()[k], rings.back()[i]);
    for (std::size_t j = 0; j + 1 < rings.size(); ++j) {
      mesh.add_face(rings[j][i], rings[j + 1][i], rings[j + 1][k]);
      mesh.add_face(rings[j][i], rings[j + 1][k], rings[j][k]);
    }
  }
  return m;
}

Mesh torus_mesh(const Vec3& centre, double major, double minor, int nu, int nv) {
  Mesh m;
  auto ring_point = [&](const Vec3& p) -> Vec3 {
    const Vec3 d = p - centre;
    return centre + major * Vec3(d.x(), d.y(), 0).normalized();
  };
  add_grid(
      m, nu, nv, true, true,
      [&](double u, double v) -> Vec3 {
        const double a = 2 * kPi * u, b = 2 * kPi * v;
        return centre + Vec3((major + minor * std::cos(b)) * std::cos(a),
                             (major + minor * std::cos(b)) * std::sin(a), minor * std::sin(b));
      },
      [&](const Vec3& p) -> Vec3 { return p - ring_point(p); });
  return m;
}

// A flat n × n patch of quads in z = height over [0, size]².
Mesh plane_mesh(double size, int n, double height) {
  Mesh m;
  add_grid(
      m, n, n, false, false,
      [&](double u, double v) -> Vec3 { return Vec3(size * u, size * v, height); },
      [](const Vec3&) -> Vec3 { return Vec3(0, 0, 1); });
  return m;
}

// Table: a top and four legs that touch it without sharing vertices.
Mesh table_mesh() {
  Mesh m;
  add_box(m, Vec3(0, 0, 0.7), Vec3(1, 1, 0.75));
  for (double x : {0.0, 0.9}) {
    for (double y : {0.0, 0.9}) add_box(m, Vec3(x, y, 0), Vec3(x + 0.1, y + 0.1, 0.7));
  }
  return m;
}

Mesh l_prism_mesh() {
  Mesh m;
  // Starts at the reflex corner so the cap fans are valid.
  add_prism(m, {Vec2(1, 1), Vec2(1, 2), Vec2(0, 2), Vec2(0, 0), Vec2(2, 0), Vec2(2, 1)}, 0, 0.5);
  return m;
}

std::vector<Vec3> face_points(const TriMesh& mesh, int f) {
  std::vector<Vec3> out;
  for (auto v : mesh.fv_range(mesh.face_handle(f))) out.push_back(point(mesh, v));
  return out;
}

void collect_leaves(const ClusterTree& tree, int node, std::vector<int>* leaves) {
  const Cluster& c = tree.nodes[node];
  if (c.leaf()) {
    leaves->push_back(node);
    return;
  }
  collect_leaves(tree, c.children[0], leaves);
  collect_leaves(tree, c.children[1], leaves);
}

TEST(Clusters, TwoDisjointBoxesAreTwoRoots) {
  Mesh m;
  add_box(m, Vec3(0, 0, 0), Vec3(1, 1, 1));
  add_box(m, Vec3(3, 0, 0), Vec3(4, 1, 1));
  const Mesh plane = plane_mesh(1, 2, 0);
  const ClusterTree tree = build_clusters({&m, &plane});
  ASSERT_EQ(tree.roots.size(), 3u);
  ASSERT_EQ(tree.face_component.size(), 2u);
  EXPECT_EQ(tree.nodes[tree.roots[0]].mesh, 0);
  EXPECT_EQ(tree.nodes[tree.roots[1]].mesh, 0);
  EXPECT_EQ(tree.nodes[tree.roots[2]].mesh, 1);
  EXPECT_EQ(tree.component_convex[0].size(), 2u);
  EXPECT_EQ(tree.component_convex[1].size(), 1u);
  // The first 12 faces are the first box, the next 12 the second.
  for (int f = 0; f < 24; ++f)
    EXPECT_EQ(tree.face_component[0][f], tree.face_component[0][f < 12 ? 0 : 12]);
  EXPECT_NE(tree.face_component[0][0], tree.face_component[0][12]);
  for (int root : tree.roots)
    EXPECT_EQ(tree.nodes[root].component,
              tree.face_component[tree.nodes[root].mesh][tree.nodes[root].faces[0]]);
}

// A box whose six sides have vertices of their own, as importers leave hard-edged boxes.
Mesh split_box_mesh(const Vec3& lo, const Vec3& hi) {
  Mesh m;
  auto corner = [&](int c) {
    return Vec3(c & 1 ? hi.x() : lo.x(), c & 2 ? hi.y() : lo.y(), c & 4 ? hi.z() : lo.z());
  };
  // Corners of each side, counter-clockwise seen from outside.
  const int sides[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& side : sides) {
    TriMesh::VertexHandle v[4];
    for (int i = 0; i < 4; ++i) v[i] = add_point(m.mesh, corner(side[i]));
    m.mesh.add_face(v[0], v[1], v[2]);
    m.mesh.add_face(v[0], v[2], v[3]);
  }
  return m;
}

TEST(Clusters, SeamsDoNotSplitComponents) {
  const Mesh box = split_box_mesh(Vec3(0, 0, 0), Vec3(1, 2, 3));
  const ClusterTree tree = build_clusters({&box});
  ASSERT_EQ(tree.roots.size(), 1u);
  EXPECT_EQ(tree.nodes[tree.roots[0]].faces.size(), 12u);
  EXPECT_TRUE(tree.component_convex[0][0]);
  EXPECT_EQ(tree.nodes[tree.roots[0]].hull.size(), 8u);
}

TEST(Clusters, TableIsFiveComponents) {
  const Mesh table = table_mesh();
  const ClusterTree tree = build_clusters({&table});
  EXPECT_EQ(tree.roots.size(), 5u);
  for (int root : tree.roots) EXPECT_EQ(tree.nodes[root].faces.size(), 12u);
  EXPECT_EQ(std::count(tree.component_convex[0].begin(), tree.component_convex[0].end(), 1), 5);
}

TEST(Clusters, LeavesPartitionEachComponent) {
  const Mesh torus = torus_mesh(Vec3(0.2, -0.1, 0.3), 1.0, 0.3, 48, 24);
  const Mesh table = table_mesh();
  const int leaf_faces = 16;
  const ClusterTree tree = build_clusters({&torus, &table}, leaf_faces);
  ASSERT_EQ(tree.roots.size(), 6u);
  for (int root : tree.roots) {
    const Cluster& r = tree.nodes[root];
    std::vector<int> leaves;
    collect_leaves(tree, root, &leaves);
    std::vector<int> faces;
    for (int leaf : leaves) {
      const Cluster& c = tree.nodes[leaf];
      EXPECT_LE(static_cast<int>(c.faces.size()), leaf_faces);
      EXPECT_GE(c.faces.size(), 1u);
      EXPECT_EQ(c.mesh, r.mesh);
      EXPECT_EQ(c.component, r.component);
      faces.insert(faces.end(), c.faces.begin(), c.faces.end());
    }
    std::sort(faces.begin(), faces.end());
    EXPECT_EQ(std::adjacent_find(faces.begin(), faces.end()), faces.end())
        << "a face in two leaves";
    std::vector<int> expected = r.faces;
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(faces, expected);
    for (int f : expected) EXPECT_EQ(tree.face_component[r.mesh][f], r.component);
  }
  EXPECT_EQ(tree.nodes[tree.roots[0]].faces.size(), torus.mesh.n_faces());
  // Inner nodes hold their children's faces, and bounds hold every face's vertices.
  for (const Cluster& c : tree.nodes) {
    const TriMesh& mesh = c.mesh == 0 ? torus.mesh : table.mesh;
    for (int f : c.faces) {
      for (const Vec3& p : face_points(mesh, f)) {
        EXPECT_TRUE((p.array() >= c.bounds.lo.array()).all() &&
                    (p.array() <= c.bounds.hi.array()).all());
      }
    }
    if (c.leaf()) continue;
    EXPECT_EQ(c.faces.size(),
              tree.nodes[c.children[0]].faces.size() + tree.nodes[c.children[1]].faces.size());
  }
}

TEST(Clusters, DepthRangeMatchesBruteForce) {
  const Mesh torus = torus_mesh(Vec3(0, 0, 0.3), 0.5, 0.2, 40, 20);
  const Mesh sphere = sphere_mesh(Vec3(2, 1, 0.5), 0.4, 24, 12);
  const Mesh plane = plane_mesh(2, 8, 0.25);                                      // coplanar hulls
  const Mesh tiny = box_mesh(Vec3(5, 5, 5), Vec3(5 + 1e-7, 5 + 2e-7, 5 + 1e-7));  // tiny hulls
  std::vector<const Mesh*> meshes = {&torus, &sphere, &plane, &tiny};
  const ClusterTree tree = build_clusters(meshes, 8);
  std::mt19937 rng(7);
  std::normal_distribution<double> gauss;
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 axis = Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized();
    const Vec3 origin(gauss(rng), gauss(rng), gauss(rng));
    for (const Cluster& c : tree.nodes) {
      double lo = 0, hi = 0;
      c.depth_range(origin, axis, &lo, &hi);
      double brute_lo = std::numeric_limits<double>::infinity(), brute_hi = -brute_lo;
      for (int f : c.faces) {
        for (const Vec3& p : face_points(meshes[c.mesh]->mesh, f)) {
          brute_lo = std::min(brute_lo, (p - origin).dot(axis));
          brute_hi = std::max(brute_hi, (p - origin).dot(axis));
        }
      }
      ASSERT_NEAR(lo, brute_lo, 1e-12);
      ASSERT_NEAR(hi, brute_hi, 1e-12);
    }
  }
  // A coplanar patch's hull is its outline: fewer points than vertices.
  EXPECT_LT(tree.nodes[tree.roots[2]].hull.size(), plane.mesh.n_vertices());
}

TEST(Clusters, ConvexComponents) {
  const Mesh box = box_mesh(Vec3(0, 0, 0), Vec3(1, 2, 0.5));
  const Mesh sphere = sphere_mesh(Vec3(0.3, 0.4, 0.35), 0.35, 32, 16);
  const Mesh plane = plane_mesh(4, 6, 0);
  const Mesh l_prism = l_prism_mesh();
  const Mesh torus = torus_mesh(Vec3(0, 0, 0), 0.28, 0.07, 32, 16);
  const ClusterTree tree = build_clusters({&box, &sphere, &plane, &l_prism, &torus}, 4);
  ASSERT_EQ(tree.roots.size(), 5u);
  EXPECT_TRUE(tree.component_convex[0][0]) << "box";
  EXPECT_TRUE(tree.component_convex[1][0]) << "sphere";
  EXPECT_TRUE(tree.component_convex[2][0]) << "plane";
  EXPECT_FALSE(tree.component_convex[3][0]) << "L prism";
  EXPECT_FALSE(tree.component_convex[4][0]) << "torus";
}

TEST(Clusters, ClosedComponents) {
  const Mesh box = box_mesh(Vec3(0, 0, 0), Vec3(1, 2, 0.5));
  const Mesh split = split_box_mesh(Vec3(0, 0, 0), Vec3(1, 2, 3));
  const Mesh plane = plane_mesh(4, 6, 0);
  const Mesh l_prism = l_prism_mesh();
  // A box without its first triangle.
  const Mesh whole = box_mesh(Vec3(0, 0, 0), Vec3(1, 1, 1));
  Mesh open_box;
  for (auto v : whole.mesh.vertices()) open_box.mesh.add_vertex(whole.mesh.point(v));
  for (auto f : whole.mesh.faces()) {
    if (f.idx() == 0) continue;
    std::vector<TriMesh::VertexHandle> corners;
    for (auto v : whole.mesh.fv_range(f)) corners.push_back(open_box.mesh.vertex_handle(v.idx()));
    open_box.mesh.add_face(corners);
  }
  const ClusterTree tree = build_clusters({&box, &split, &plane, &l_prism, &open_box});
  ASSERT_EQ(tree.roots.size(), 5u);
  EXPECT_TRUE(tree.component_closed[0][0]) << "box";
  EXPECT_TRUE(tree.component_closed[1][0]) << "box with a seam at every edge";
  EXPECT_FALSE(tree.component_closed[2][0]) << "plane";
  EXPECT_TRUE(tree.component_closed[3][0]) << "L prism";
  EXPECT_FALSE(tree.component_closed[4][0]) << "box without one triangle";
}

// A 1 × 1 square light at z = 2 over a flat 1 × 1 receiver at z = 0: the shaft is a prism.
Shaft square_shaft() {
  const std::vector<Vec3> light = {Vec3(0, 0, 2), Vec3(1, 0, 2), Vec3(1, 1, 2), Vec3(0, 1, 2)};
  Bounds3 receiver;
  receiver.extend(Vec3(0, 0, 0));
  receiver.extend(Vec3(1, 1, 0));
  return Shaft(light, receiver);
}

TEST(Shaft, RejectsBesideKeepsInsideAndStraddling) {
  const Shaft shaft = square_shaft();
  const Mesh inside = box_mesh(Vec3(0.4, 0.4, 0.9), Vec3(0.6, 0.6, 1.1));
  const Mesh beside = box_mesh(Vec3(1.2, 0.4, 0.9), Vec3(1.4, 0.6, 1.1));
  const Mesh straddling = box_mesh(Vec3(0.9, 0.4, 0.9), Vec3(1.1, 0.6, 1.1));
  const Mesh touching = box_mesh(Vec3(1.0, 0.4, 0.9), Vec3(1.2, 0.6, 1.1));
  const ClusterTree tree = build_clusters({&inside, &beside, &straddling, &touching});
  auto hull = [&](int m) -> const std::vector<Vec3>& { return tree.nodes[tree.roots[m]].hull; };
  EXPECT_TRUE(shaft.contains_all(hull(0)));
  EXPECT_FALSE(shaft.may_contain_any(hull(1)));
  EXPECT_TRUE(shaft.may_contain_any(hull(2)));
  EXPECT_FALSE(shaft.contains_all(hull(2)));
  EXPECT_TRUE(shaft.may_contain_any(hull(3)));
  EXPECT_EQ(clusters_in_shaft(tree, shaft),
            (std::vector<int>{tree.roots[0], tree.roots[2], tree.roots[3]}));
  EXPECT_FALSE(shaft.may_contain_any({}));
}

TEST(Shaft, ContainsConvexCombinationsOfItsPoints) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Vec3> light;
    for (int i = 0; i < 1 + trial % 6; ++i)
      light.push_back(Vec3(uniform(rng), uniform(rng), 3 + uniform(rng)));
    Bounds3 receiver;
    receiver.extend(Vec3(uniform(rng), uniform(rng), uniform(rng)));
    receiver.extend(Vec3(uniform(rng), uniform(rng), trial % 2 ? receiver.lo.z() : uniform(rng)));
    const Shaft shaft(light, receiver);
    std::vector<Vec3> generators = light;
    for (int c = 0; c < 8; ++c) {
      generators.emplace_back(c & 1 ? receiver.hi.x() : receiver.lo.x(),
                              c & 2 ? receiver.hi.y() : receiver.lo.y(),
                              c & 4 ? receiver.hi.z() : receiver.lo.z());
    }
    EXPECT_TRUE(shaft.contains_all(generators));
    for (int k = 0; k < 50; ++k) {
      Vec3 p = Vec3::Zero();
      double total = 0;
      for (const Vec3& g : generators) {
        const double w = uniform(rng) + 1;
        p += w * g;
        total += w;
      }
      EXPECT_TRUE(shaft.contains_all({p / total}));
      // Past the farthest generator along a random direction is outside.
      const Vec3 d = Vec3(uniform(rng), uniform(rng), uniform(rng)).normalized();
      double farthest = -1e300;
      for (const Vec3& g : generators) farthest = std::max(farthest, g.dot(d));
      const Vec3 outside = p / total + (farthest - d.dot(p / total) + 0.01) * d;
      EXPECT_FALSE(shaft.may_contain_any({outside}));
    }
  }
}

TEST(Shaft, DegenerateShaftsStillCull) {
  // A point light over a flat receiver: a pyramid.
  Bounds3 floor;
  floor.extend(Vec3(0, 0, 0));
  floor.extend(Vec3(1, 1, 0));
  const Shaft pyramid({Vec3(0.5, 0.5, 1)}, floor);
  EXPECT_TRUE(pyramid.contains_all({Vec3(0.5, 0.5, 0.5), Vec3(0.25, 0.25, 0.5), Vec3(1, 1, 0)}));
  for (const Vec3& p : {Vec3(0.9, 0.9, 0.8), Vec3(0.5, 0.5, 1.1), Vec3(0.5, 0.5, -0.1)}) {
    EXPECT_FALSE(pyramid.may_contain_any({p})) << p.transpose();
  }
  // Points outside different faces, none outside all of one: kept (the test is conservative).
  EXPECT_TRUE(pyramid.may_contain_any({Vec3(0.5, 0.5, 1.1), Vec3(0.5, 0.5, -0.1)}));
  // A point light in the receiver's own plane: a flat shaft.
  const Shaft flat({Vec3(2, 0.5, 0)}, floor);
  EXPECT_TRUE(flat.contains_all({Vec3(1.5, 0.5, 0), Vec3(0.2, 0.9, 0)}));
  EXPECT_FALSE(flat.may_contain_any({Vec3(1.5, 0.5, 0.01)}));
  EXPECT_FALSE(flat.may_contain_any({Vec3(1.5, 0.9, 0)}));
  // A receiver that is a single point, lit by a point: a segment.
  Bounds3 dot;
  dot.extend(Vec3(0, 0, 0));
  const Shaft segment({Vec3(0, 0, 1)}, dot);
  EXPECT_TRUE(segment.contains_all({Vec3(0, 0, 0.5)}));
  EXPECT_FALSE(segment.may_contain_any({Vec3(0.01, 0, 0.5)}));
}

// A disk light's 16-gon outline over a single texel (the box of one point), as the planner
// builds it for the smallest receiver groups: the shaft holds the segment from the texel to the
// light, refuses points beside it, and decides every probe the same way however the heap is laid
// out when it is built. (CGAL's convex_hull_3, which the shaft used before, ordered these
// degenerate points by their addresses, and `shadowbake plan` on the hall on 2 threads printed
// different face counts from run to run; this test did not catch that in one thread, the
// repeated plans did: docs/methods.md.)
TEST(Shaft, DegenerateShaftIsTheSameWhateverTheHeap) {
  std::vector<Vec3> disk;
  const double r = 0.1 / std::cos(std::numbers::pi / 16);
  for (int i = 0; i < 16; ++i) {
    const double phi = 2 * std::numbers::pi * i / 16;
    disk.push_back(Vec3(-1, -1.6, 3.485) + r * Vec3(std::cos(phi), std::sin(phi), 0));
  }
  Bounds3 texel;
  texel.extend(Vec3(-2.9815893173217773, 1.4829732179641724, 0.4686336815357208));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vec3> probes;
  for (int i = 0; i < 20000; ++i) {
    const double t = 0.5 * (u(rng) + 1);
    const Vec3 on = texel.lo + t * (Vec3(-1, -1.6, 3.485) - texel.lo);
    probes.push_back(on + 0.15 * Vec3(u(rng), u(rng), u(rng)));
  }
  const auto decisions = [&] {
    const Shaft shaft(disk, texel);
    std::vector<bool> inside;
    for (const Vec3& p : probes) inside.push_back(shaft.may_contain_any({p}));
    return inside;
  };
  const std::vector<bool> first = decisions();
  for (int round = 0; round < 16; ++round) {
    // Another heap: blocks of many sizes, every other one freed again, so that the shaft's own
    // allocations land in holes in another order.
    std::vector<std::vector<char>> clutter;
    for (int i = 0; i < 200 * (round + 1); ++i) clutter.emplace_back(16 + rng() % 2000);
    for (std::size_t i = 0; i < clutter.size(); i += 2 + rng() % 2) clutter[i] = {};
    EXPECT_EQ(decisions(), first) << "round " << round;
  }
  const Shaft shaft(disk, texel);
  EXPECT_TRUE(shaft.contains_all({texel.lo, 0.5 * (texel.lo + Vec3(-1, -1.6, 3.485))}));
  EXPECT_FALSE(shaft.may_contain_any({texel.lo + Vec3(0.05, 0, 0)}));
  EXPECT_GT(std::count(first.begin(), first.end(), false), 1000);
}

// True when some point of the triangle (on a dense barycentric grid) is in the shaft.
bool triangle_hits_shaft(const Shaft& shaft, const std::vector<Vec3>& t) {
  const int n = 12;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; i + j <= n; ++j) {
      const Vec3 p = t[0] + (t[1] - t[0]) * (i / double(n)) + (t[2] - t[0]) * (j / double(n));
      if (shaft.contains_all({p})) return true;
    }
  }
  return false;
}

TEST(Shaft, ClustersInShaftNeverMissAFaceInIt) {
  const Mesh floor = plane_mesh(4, 24, 0);
  const Mesh torus = torus_mesh(Vec3(1.2, 1.5, 0.07), 0.28, 0.07, 32, 16);
  const Mesh sphere = sphere_mesh(Vec3(2.5, 2.2, 0.35), 0.35, 24, 12);
  const Mesh table = table_mesh();
  const std::vector<const Mesh*> meshes = {&floor, &torus, &sphere, &table};
  const ClusterTree tree = build_clusters(meshes, 8);
  const std::vector<Vec3> panel = {Vec3(1.6, 1.6, 1.8), Vec3(2.4, 1.6, 1.9), Vec3(2.4, 2.1, 1.9),
                                   Vec3(1.6, 2.1, 1.8)};
  Bounds3 receiver;
  receiver.extend(Vec3(1.0, 1.0, 0));
  receiver.extend(Vec3(2.0, 2.0, 0));
  const Shaft shaft(panel, receiver);

  std::set<std::pair<int, int>> kept;
  for (int node : clusters_in_shaft(tree, shaft)) {
    const Cluster& c = tree.nodes[node];
    EXPECT_TRUE(shaft.may_contain_any(c.hull));
    for (int f : c.faces) EXPECT_TRUE(kept.insert({c.mesh, f}).second) << "a face kept twice";
  }
  std::size_t total = 0, hit = 0;
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    for (auto f : meshes[m]->mesh.faces()) {
      ++total;
      if (!triangle_hits_shaft(shaft, face_points(meshes[m]->mesh, f.idx()))) continue;
      ++hit;
      EXPECT_TRUE(kept.count({static_cast<int>(m), f.idx()}))
          << "mesh " << m << " face " << f.idx();
    }
  }
  EXPECT_GT(hit, 0u);
  EXPECT_LT(kept.size(), total / 2) << "culling kept most of the scene";
}

TEST(Clusters, ShowcaseObjectsAreOneComponentEach) {
  const auto scene = load_scene(SB_SOURCE_DIR "/scenes/showcase/scene.toml");
  ASSERT_TRUE(scene) << scene.error().message;
  std::vector<Mesh> meshes;
  for (const ObjectDesc& obj : scene->objects) {
    auto mesh = import_mesh(obj, scene->file);
    ASSERT_TRUE(mesh) << mesh.error().message;
    meshes.push_back(std::move(mesh.value()));
  }
  std::vector<const Mesh*> pointers;
  for (const Mesh& m : meshes) pointers.push_back(&m);
  const ClusterTree tree = build_clusters(pointers);
  // Every object is one piece despite its UV and normal seams; only the torus is not convex.
  ASSERT_EQ(tree.roots.size(), meshes.size());
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    ASSERT_EQ(tree.component_convex[m].size(), 1u) << meshes[m].name;
    EXPECT_EQ(tree.component_convex[m][0], meshes[m].name == "torus" ? 0 : 1) << meshes[m].name;
    // Solids are closed across their seams (the sphere's copies of its seam at longitude 0 and
    // 2π differ in the last bits); the floor and the wall are open sheets.
    const bool sheet = meshes[m].name == "floor" || meshes[m].name == "wall";
    EXPECT_EQ(tree.component_closed[m][0], sheet ? 0 : 1) << meshes[m].name;
  }
}

}  // namespace
}  // namespace sb
