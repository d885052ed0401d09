// A mesh light's parts (lights.h, mesh_light_parts): its triangles, each paired with the one
// across an edge into a convex quad where the two lie in one plane, so that the estimator and the
// reference weigh each part as one polygon light; power shared by area.
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "scene/lights.h"

namespace sb {

std::vector<LightDesc> mesh_light_parts(const LightDesc& mesh) {
  std::vector<LightDesc> out;
  const double total = Light(mesh).area();
  if (!(total > 0)) return out;
  const std::vector<Vec3>& c = mesh.corners;
  const std::size_t triangles = c.size() / 3;
  const auto corner = [&](std::size_t t, int k) -> const Vec3& {
    return c[3 * t + std::size_t(k % 3)];
  };
  std::vector<Vec3> normal(triangles);
  std::vector<double> area(triangles);
  // Each triangle's edges by their ends (as they run in it), for the triangle across each.
  std::map<std::array<double, 6>, std::pair<std::size_t, int>> edges;
  const auto edge_key = [](const Vec3& a, const Vec3& b) {
    return std::array<double, 6>{a.x(), a.y(), a.z(), b.x(), b.y(), b.z()};
  };
  for (std::size_t t = 0; t < triangles; ++t) {
    const Vec3 cross = (corner(t, 1) - corner(t, 0)).cross(corner(t, 2) - corner(t, 0));
    area[t] = 0.5 * cross.norm();
    normal[t] = area[t] > 0 ? Vec3(cross.normalized()) : Vec3::Zero();
    for (int k = 0; k < 3; ++k)
      edges.emplace(edge_key(corner(t, k), corner(t, k + 1)), std::pair{t, k});
  }
  std::vector<std::uint8_t> taken(triangles, 0);
  const auto add = [&](std::vector<Vec3> corners, double part_area) {
    LightDesc part = mesh;
    part.shape = LightShape::polygon;
    part.name = mesh.name + "#" + std::to_string(out.size());
    part.corners = std::move(corners);
    part.power = mesh.power * part_area / total;
    out.push_back(std::move(part));
  };
  for (std::size_t t = 0; t < triangles; ++t) {
    if (taken[t] || !(area[t] > 0)) continue;  // a degenerate triangle emits nothing
    taken[t] = 1;
    bool paired = false;
    for (int k = 0; k < 3 && !paired; ++k) {
      // The triangle (p, q, r) and the one across p–q, (q, p, s): the quad p, s, q, r when the
      // two lie in one plane, face the same way and make a convex outline.
      const Vec3 &p = corner(t, k), &q = corner(t, k + 1), &r = corner(t, k + 2);
      const auto across = edges.find(edge_key(q, p));
      if (across == edges.end()) continue;
      const auto [u, m] = across->second;
      if (u == t || taken[u] || !(area[u] > 0) || normal[t].dot(normal[u]) < 1 - 1e-9) continue;
      const Vec3& s_corner = corner(u, m + 2);
      if (std::abs(normal[t].dot(s_corner - p)) > 1e-6 * (q - p).norm()) continue;
      const std::vector<Vec3> quad = {p, s_corner, q, r};
      bool convex = true;
      for (int i = 0; i < 4 && convex; ++i) {
        const Vec3& a = quad[std::size_t(i)];
        const Vec3& b = quad[std::size_t((i + 1) % 4)];
        const Vec3& d = quad[std::size_t((i + 2) % 4)];
        convex = (b - a).cross(d - b).dot(normal[t]) > 0;
      }
      if (!convex) continue;
      taken[u] = 1;
      paired = true;
      add(quad, area[t] + area[u]);
    }
    if (!paired) add({corner(t, 0), corner(t, 1), corner(t, 2)}, area[t]);
  }
  return out;
}

}  // namespace sb
