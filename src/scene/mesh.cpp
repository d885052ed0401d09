// Access to the working mesh's triangles as plain project types.
#include "scene/mesh.h"

#include <cmath>

namespace sb {

Triangle triangle(const TriMesh& mesh, TriMesh::FaceHandle f) {
  Triangle t;
  int i = 0;
  for (auto v : mesh.fv_range(f)) {
    const auto& p = mesh.point(v);
    const auto& n = mesh.normal(v);
    const auto& uv = mesh.texcoord2D(v);
    t.p[i] = Vec3(p[0], p[1], p[2]);
    t.n[i] = Vec3(n[0], n[1], n[2]);
    t.uv[i] = Vec2(uv[0], uv[1]);
    ++i;
  }
  return t;
}

SurfaceAreas surface_areas(const Mesh& mesh) {
  SurfaceAreas areas;
  for (auto f : mesh.mesh.faces()) {
    const Triangle t = triangle(mesh.mesh, f);
    areas.world += 0.5 * (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).norm();
    const Vec2 a = t.uv[1] - t.uv[0], b = t.uv[2] - t.uv[0];
    areas.uv += 0.5 * std::abs(a.x() * b.y() - a.y() * b.x());
  }
  return areas;
}

}  // namespace sb
