// Least-squares conformal maps with CGAL (chart_lscm.h). CGAL's LSCM_parameterizer_3 pins two
// far-apart border vertices (Two_vertices_parameterizer_3) and solves the sparse least-squares
// system with Eigen; we only build its Surface_mesh and check the topology it needs first.
#include "texels/chart_lscm.h"

#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_parameterization/LSCM_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/Two_vertices_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/parameterize.h>

#include <cstddef>
#include <vector>

namespace sb {

namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using ChartMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using VertexIndex = ChartMesh::Vertex_index;

}  // namespace

std::optional<std::vector<Vec2>> lscm_unwrap(const std::vector<Vec3>& positions,
                                             const std::vector<std::array<int, 3>>& triangles) {
  ChartMesh mesh;
  std::vector<VertexIndex> vertex;
  vertex.reserve(positions.size());
  for (const Vec3& p : positions) vertex.push_back(mesh.add_vertex({p.x(), p.y(), p.z()}));
  for (const auto& t : triangles) {
    const auto face = mesh.add_face(vertex[std::size_t(t[0])], vertex[std::size_t(t[1])],
                                    vertex[std::size_t(t[2])]);
    if (face == ChartMesh::null_face()) return std::nullopt;  // non-manifold here
  }
  // A disc: one border loop and Euler characteristic V − E + F = 1 (every vertex used).
  std::vector<ChartMesh::Halfedge_index> borders;
  CGAL::Polygon_mesh_processing::extract_boundary_cycles(mesh, std::back_inserter(borders));
  for (const VertexIndex v : mesh.vertices())
    if (mesh.is_isolated(v)) return std::nullopt;
  const long euler =
      long(mesh.number_of_vertices()) - long(mesh.number_of_edges()) + long(mesh.number_of_faces());
  if (borders.size() != 1 || euler != 1) return std::nullopt;

  namespace smp = CGAL::Surface_mesh_parameterization;
  using Border = smp::Two_vertices_parameterizer_3<ChartMesh>;
  using Lscm = smp::LSCM_parameterizer_3<ChartMesh, Border>;
  auto uv = mesh.add_property_map<VertexIndex, Kernel::Point_2>("v:uv").first;
  if (smp::parameterize(mesh, Lscm(), borders.front(), uv) != smp::OK) return std::nullopt;
  std::vector<Vec2> out;
  out.reserve(positions.size());
  for (const VertexIndex v : vertex) {
    const Kernel::Point_2 p = uv[v];
    out.emplace_back(p.x(), p.y());
    if (!out.back().allFinite()) return std::nullopt;
  }
  return out;
}

}  // namespace sb
