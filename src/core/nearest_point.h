// The point of a triangle nearest to a point, in any dimension.
#pragma once

namespace sb {

// The point of triangle (a, b, c) nearest to p, as barycentrics; returns its squared distance to p.
// V: a fixed-size Eigen vector (2D in the UV rasteriser, 3D for the blockers' inner balls).
// Ericson, "Real-Time Collision Detection", §5.1.5, by Voronoi regions of the vertices and edges.
template <class V>
double nearest_point(const V& a, const V& b, const V& c, const V& p, double bary[3]) {
  const V ab = b - a, ac = c - a, ap = p - a;
  const auto result = [&](double wa, double wb, double wc) {
    bary[0] = wa;
    bary[1] = wb;
    bary[2] = wc;
    return (wa * a + wb * b + wc * c - p).squaredNorm();
  };
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return result(1, 0, 0);
  const V bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return result(0, 1, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double t = d1 / (d1 - d3);
    return result(1 - t, t, 0);
  }
  const V cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return result(0, 0, 1);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double t = d2 / (d2 - d6);
    return result(1 - t, 0, t);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return result(0, 1 - t, t);
  }
  const double denom = va + vb + vc;
  return result(va / denom, vb / denom, vc / denom);
}

}  // namespace sb
