// Sutherland–Hodgman against one depth plane (depth_clipping.h): each edge (a, b) keeps a when a
// is on the kept side and adds the crossing point when a and b lie on opposite sides.
#include "occluders/depth_clipping.h"

namespace sb {

std::vector<Vec3> clip_to_depth(const std::vector<Vec3>& polygon, const ProjectionFrame& frame,
                                double limit, KeepDepth keep) {
  // Signed distances are sign·(depth − limit): >= 0 on the kept side.
  const double sign = keep == KeepDepth::at_least ? 1.0 : -1.0;
  std::vector<Vec3> out;
  out.reserve(polygon.size() + 1);
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Vec3& a = polygon[i];
    const Vec3& b = polygon[(i + 1) % polygon.size()];
    const double da = sign * (frame.depth(a) - limit), db = sign * (frame.depth(b) - limit);
    if (da >= 0) out.push_back(a);
    if ((da >= 0) != (db >= 0)) out.push_back(a + (b - a) * (da / (da - db)));
  }
  return out;
}

}  // namespace sb
