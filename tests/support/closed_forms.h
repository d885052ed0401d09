// Closed forms of the parallel-plane configuration of docs/design.md §2, shared by the tests:
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

namespace sb::closed_forms {

// The same configuration with the blocker at any height h (0 < h < 1.5): seen from the floor point
// (x, y), the blocker hides the light-plane square of half-width 0.3/(1 − α) centred at
// (b − α·y)/(1 − α), with α = (1.5 − h)/1.5.
struct HiddenSquare {
  double cx, cy, half;
};
inline HiddenSquare parallel_hidden_square(double x, double y, double bx, double by, double h) {
  const double alpha = (1.5 - h) / 1.5;
  return {(bx - alpha * x) / (1 - alpha), (by - alpha * y) / (1 - alpha), 0.3 / (1 - alpha)};
}

// V_u under the 0.5 m square light.
inline double square_light_unweighted_visibility(double x, double y, double bx, double by,
                                                 double h) {
  const HiddenSquare s = parallel_hidden_square(x, y, bx, by, h);
  auto overlap = [&](double c) {
    return std::max(0.0, std::min(0.25, c + s.half) - std::max(-0.25, c - s.half));
  };
  return 1.0 - overlap(s.cx) * overlap(s.cy) / 0.25;
}

// Area of the disk of radius r at the origin inside the rectangle [x0, x1] × [y0, y1], by the
// midpoint rule over x of the clipped chord (error below 1e-6 r² with 4000 steps).
inline double disk_rectangle_overlap(double r, double x0, double x1, double y0, double y1) {
  const double a = std::max(-r, x0), b = std::min(r, x1);
  if (a >= b) return 0.0;
  const int steps = 4000;
  const double dx = (b - a) / steps;
  double area = 0;
  for (int i = 0; i < steps; ++i) {
    const double x = a + (i + 0.5) * dx;
    const double h = std::sqrt(std::max(0.0, r * r - x * x));
    area += std::max(0.0, std::min(h, y1) - std::max(-h, y0)) * dx;
  }
  return area;
}

// V_u under a disk light of radius r (facing the floor) in place of the square.
inline double disk_light_unweighted_visibility(double x, double y, double bx, double by, double h,
                                               double r) {
  const HiddenSquare s = parallel_hidden_square(x, y, bx, by, h);
  // Wholly hidden or wholly visible: no integral needed.
  if (std::abs(s.cx) + r <= s.half && std::abs(s.cy) + r <= s.half) return 0.0;
  if (std::abs(s.cx) >= s.half + r || std::abs(s.cy) >= s.half + r) return 1.0;
  const double pi = 3.14159265358979323846;
  return 1.0 -
         disk_rectangle_overlap(r, s.cx - s.half, s.cx + s.half, s.cy - s.half, s.cy + s.half) /
             (pi * r * r);
}

}  // namespace sb::closed_forms

namespace sb::closed_forms {

// ∫∫ h²/(s² + t² + h²)² over [0, a] × [0, b] (π times the form factor of that rectangle of a
// light parallel to the receiver, seen from the receiver point under its corner at distance h):
// the weight cos θ_light · cos θ_receiver / r² integrated in closed form. Odd in a and in b, so
// any rectangle is four corners' sum (rectangle_weight).
inline double corner_weight(double a, double b, double h) {
  const double ra = std::sqrt(a * a + h * h), rb = std::sqrt(b * b + h * h);
  return 0.5 * (a / ra * std::atan(b / ra) + b / rb * std::atan(a / rb));
}

// The weight of the light rectangle [x0, x1] × [y0, y1] seen from (x, y) at distance h below.
inline double rectangle_weight(double x0, double x1, double y0, double y1, double x, double y,
                               double h) {
  if (x0 >= x1 || y0 >= y1) return 0.0;
  x0 -= x, x1 -= x, y0 -= y, y1 -= y;
  return corner_weight(x1, y1, h) - corner_weight(x0, y1, h) - corner_weight(x1, y0, h) +
         corner_weight(x0, y0, h);
}

// V = H/H0 under the 0.5 m square light 1.5 m above the floor, blocker at height h: the light's
// weight less that of its hidden part, exact.
inline double square_light_weighted_visibility(double x, double y, double bx, double by, double h) {
  const HiddenSquare s = parallel_hidden_square(x, y, bx, by, h);
  const double total = rectangle_weight(-0.25, 0.25, -0.25, 0.25, x, y, 1.5);
  const double hidden =
      rectangle_weight(std::max(-0.25, s.cx - s.half), std::min(0.25, s.cx + s.half),
                       std::max(-0.25, s.cy - s.half), std::min(0.25, s.cy + s.half), x, y, 1.5);
  return 1.0 - hidden / total;
}

// V = H/H0 at floor point (x, y) under a square light of half-width `light` centred above the
// origin at height `light_height`, facing down, with a square blocker of half-width `half`
// centred on (bx, by) at height h parallel to both: the blocker seen from (x, y) hides, on the
// light's plane, the square of centre (x, y) + (b − (x, y))·H/h and half-width half·H/h; V is
// the light's weight less that hidden part's, exact.
inline double parallel_square_visibility(double x, double y, double light, double light_height,
                                         double bx, double by, double half, double h) {
  const double k = light_height / h;
  const double cx = x + (bx - x) * k, cy = y + (by - y) * k, reach = half * k;
  const double total = rectangle_weight(-light, light, -light, light, x, y, light_height);
  const double hidden = rectangle_weight(std::max(-light, cx - reach), std::min(light, cx + reach),
                                         std::max(-light, cy - reach), std::min(light, cy + reach),
                                         x, y, light_height);
  return 1.0 - hidden / total;
}

// V = H/H0 under a disk light of radius r in place of the square: exact along the light's y
// (∫ dt/(A + t²)² in closed form), midpoint rule over its x in `steps` columns.
inline double disk_light_weighted_visibility(double x, double y, double bx, double by, double h,
                                             double r, int steps = 2000) {
  const HiddenSquare s = parallel_hidden_square(x, y, bx, by, h);
  const double d = 1.5;
  // ∫ h²/(A + t²)² dt from t0 to t1, A = (sx − x)² + d².
  auto column = [&](double A, double t0, double t1) {
    if (t0 >= t1) return 0.0;
    auto F = [&](double t) {
      return t / (2 * A * (A + t * t)) + std::atan(t / std::sqrt(A)) / (2 * A * std::sqrt(A));
    };
    return d * d * (F(t1) - F(t0));
  };
  double total = 0, hidden = 0;
  const double dx = 2 * r / steps;
  for (int i = 0; i < steps; ++i) {
    const double sx = -r + (i + 0.5) * dx;
    const double half = std::sqrt(std::max(0.0, r * r - sx * sx));
    const double A = (sx - x) * (sx - x) + d * d;
    total += column(A, -half - y, half - y) * dx;
    if (std::abs(sx - s.cx) < s.half)
      hidden +=
          column(A, std::max(-half, s.cy - s.half) - y, std::min(half, s.cy + s.half) - y) * dx;
  }
  return 1.0 - hidden / total;
}

}  // namespace sb::closed_forms
