#include "methods/convolution/buried_texels.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace sb {

namespace {
// A face lies against the receiver's surface where their normals are opposite within ~0.8°.
constexpr double kAgainst = 0.9999;
}  // namespace

std::vector<std::uint8_t> buried_texels(const TexelSpace& space, const Mesh& receiver,
                                        const std::vector<const Mesh*>& blockers,
                                        const ClusterTree& clusters, double tolerance) {
  std::vector<std::uint8_t> buried(space.texels.size(), 0);
  for (std::size_t m = 0; m < blockers.size(); ++m) {
    const TriMesh& mesh = blockers[m]->mesh;
    const bool own = blockers[m] == &receiver;
    const std::size_t components = clusters.component_convex[m].size();
    // Each convex closed component as its face planes (outward normal n, n·x <= offset inside)
    // and its bounding box.
    std::vector<std::vector<std::pair<Vec3, double>>> planes(components);
    std::vector<Bounds3> boxes(components);
    for (const auto f : mesh.faces()) {
      const int c = clusters.face_component[m][std::size_t(f.idx())];
      if (!clusters.component_convex[m][std::size_t(c)] ||
          !clusters.component_closed[m][std::size_t(c)])
        continue;
      Vec3 v[3];
      int k = 0;
      for (const auto vh : mesh.fv_range(f)) {
        const auto p = mesh.point(vh);
        v[k++] = Vec3(p[0], p[1], p[2]);
        boxes[std::size_t(c)].extend(v[k - 1]);
      }
      const Vec3 n = (v[1] - v[0]).cross(v[2] - v[0]);
      if (n.norm() <= 0) continue;  // a degenerate face bounds nothing
      const Vec3 u = n.normalized();
      planes[std::size_t(c)].emplace_back(u, u.dot(v[0]));
    }
    for (std::size_t c = 0; c < components; ++c) {
      if (planes[c].empty()) continue;
      const Bounds3& box = boxes[c];
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, space.texels.size(), 4096),
                        [&](const auto& r) {
                          for (std::size_t t = r.begin(); t != r.end(); ++t) {
                            const Texel& tx = space.texels[t];
                            if (buried[t]) continue;
                            if (own && clusters.face_component[m][std::size_t(tx.face)] == int(c))
                              continue;
                            const Vec3 p = tx.position.cast<double>();
                            if (((p - box.lo).array() < -tolerance).any() ||
                                ((p - box.hi).array() > tolerance).any())
                              continue;
                            const Vec3 normal = space.geometric_normal(t).cast<double>();
                            bool inside = true;
                            for (const auto& [n, offset] : planes[c]) {
                              // A face lying against the receiver's surface (a box's bottom on the
                              // floor) holds the texels on it; any other face must have the texel
                              // strictly behind it: a texel on a side's plane sees out through that
                              // side, as in the reference.
                              const bool against = n.dot(normal) < -kAgainst;
                              if (n.dot(p) > offset + (against ? tolerance : -tolerance)) {
                                inside = false;
                                break;
                              }
                            }
                            buried[t] = inside;
                          }
                        });
    }
  }
  return buried;
}

}  // namespace sb
