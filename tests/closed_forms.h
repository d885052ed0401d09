// Closed forms of the parallel-plane configuration of design-notes §2, shared by the tests:
// a 0.5 m square light at z = 1.5 facing down, a 0.6 m square blocker at z = 0.5 centred at
// (bx, by), a floor at z = 0 (d_b = 1, d_r = 1.5, α = 2/3). Seen from the floor point (x, y) the
// blocker hides the light-plane square of half-width 0.3/(1 − α) = 0.9 centred at
// (b − α·y)/(1 − α) = 3·b − 2·y.
#pragma once

#include <algorithm>
#include <cmath>

namespace sb::closed_forms {

inline bool parallel_light_point_hidden(double sx, double sy, double x, double y, double bx = 0,
                                        double by = 0) {
  return std::abs(sx - (3 * bx - 2 * x)) < 0.9 && std::abs(sy - (3 * by - 2 * y)) < 0.9;
}

// V_u: the unweighted visible fraction of the light, an overlap of two squares.
inline double parallel_unweighted_visibility(double x, double y, double bx = 0, double by = 0) {
  auto overlap = [](double c) {  // [−0.25, 0.25] ∩ [c − 0.9, c + 0.9]
    return std::max(0.0, std::min(0.25, c + 0.9) - std::max(-0.25, c - 0.9));
  };
  return 1.0 - overlap(3 * bx - 2 * x) * overlap(3 * by - 2 * y) / 0.25;
}

// V = H/H0: visibility weighted by cosθ_x cosθ_y / r², integrated by the midpoint rule on a
// k × k grid over the light (k = 2000 gives about 1e-6).
inline double parallel_weighted_visibility(double x, double y, double bx = 0, double by = 0,
                                           int k = 2000) {
  double visible = 0, total = 0;
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) {
      const double sx = -0.25 + 0.5 * (i + 0.5) / k, sy = -0.25 + 0.5 * (j + 0.5) / k;
      const double dx = sx - x, dy = sy - y, dz = 1.5;
      const double r2 = dx * dx + dy * dy + dz * dz;
      const double w = dz * dz / (r2 * r2);  // both cosines are dz / r
      total += w;
      if (!parallel_light_point_hidden(sx, sy, x, y, bx, by)) visible += w;
    }
  return visible / total;
}

}  // namespace sb::closed_forms
