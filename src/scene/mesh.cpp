// Access to the working mesh's triangles as plain project types.
#include "scene/mesh.h"

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

}  // namespace sb
