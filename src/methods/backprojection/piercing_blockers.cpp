// Blocker triangles through a sphere light's ball, and their parts outside it
// (piercing_blockers.h).
#include "methods/backprojection/piercing_blockers.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sb {

namespace {

using Polygon2 = std::vector<Vec2>;

// 2 × the signed area of (a, b, p): > 0 where p lies left of a → b.
double side(const Vec2& a, const Vec2& b, const Vec2& p) {
  return (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
}

// The part of convex `p` on the left of a → b, or on its right.
Polygon2 clip(const Polygon2& p, const Vec2& a, const Vec2& b, bool left) {
  Polygon2 out;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec2& u = p[i];
    const Vec2& v = p[(i + 1) % p.size()];
    const double su = side(a, b, u), sv = side(a, b, v);
    if (left ? su >= 0 : su <= 0) out.push_back(u);
    if ((su > 0 && sv < 0) || (su < 0 && sv > 0)) out.push_back(u + (v - u) * (su / (su - sv)));
  }
  return out;
}

double area(const Polygon2& p) {
  double twice = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    twice += p[i].x() * p[(i + 1) % p.size()].y() - p[i].y() * p[(i + 1) % p.size()].x();
  return 0.5 * twice;
}

// Triangle `corners` less the regular kSides-gon inscribed in the circle (centre, radius) of its
// plane, as triangles: the parts outside each side in turn of what is left.
void parts_outside(const Vec3* corners, const Vec3& centre, double radius,
                   std::vector<std::array<Vec3, 3>>& out) {
  Vec3 n = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
  if (!(n.norm() > 0)) return;
  n.normalize();
  const Vec3 u = (corners[1] - corners[0]).normalized(), v = n.cross(u);
  const auto flat = [&](const Vec3& p) { return Vec2(u.dot(p - centre), v.dot(p - centre)); };
  const auto lift = [&](const Vec2& p) { return Vec3(centre + p.x() * u + p.y() * v); };
  Polygon2 rest = {flat(corners[0]), flat(corners[1]), flat(corners[2])};
  if (area(rest) < 0) std::swap(rest[1], rest[2]);
  const double tiny = 1e-12 * std::abs(area(rest));
  constexpr int k = PiercingBlockers::kSides;
  for (int s = 0; s < k && rest.size() >= 3; ++s) {
    const double a0 = 2 * std::numbers::pi * s / k, a1 = 2 * std::numbers::pi * (s + 1) / k;
    const Vec2 a = radius * Vec2(std::cos(a0), std::sin(a0));
    const Vec2 b = radius * Vec2(std::cos(a1), std::sin(a1));
    const Polygon2 outside = clip(rest, a, b, false);  // right of a counter-clockwise side
    if (outside.size() >= 3 && std::abs(area(outside)) > tiny)
      for (std::size_t i = 1; i + 1 < outside.size(); ++i)
        out.push_back({lift(outside[0]), lift(outside[i]), lift(outside[i + 1])});
    rest = clip(rest, a, b, true);
  }
}

}  // namespace

bool PiercingBlockers::pierces(std::uint32_t triangle) const {
  return std::binary_search(triangles.begin(), triangles.end(), triangle);
}

std::span<const std::array<Vec3, 3>> PiercingBlockers::parts_of(std::uint32_t triangle) const {
  const auto k = std::size_t(std::lower_bound(triangles.begin(), triangles.end(), triangle) -
                             triangles.begin());
  return {parts.data() + first[k], parts.data() + first[k + 1]};
}

PiercingBlockers piercing_blockers(const ShaftCuller& culler, const Light& light) {
  PiercingBlockers out;
  if (light.shape() != LightShape::sphere) return out;
  const Vec3 c = light.centre();
  const double r = light.desc().radius;
  out.triangles = culler.triangles_within(c, r);
  out.first.push_back(0);
  for (const std::uint32_t t : out.triangles) {
    const Vec3* corners = culler.triangle_corners(t);
    const Vec3& n = culler.triangle_normal(t);
    const double height = n.dot(c - corners[0]);
    // The circle the ball cuts from the triangle's plane.
    const double radius = std::sqrt(std::max(0.0, r * r - height * height));
    parts_outside(corners, c - height * n, radius, out.parts);
    out.first.push_back(std::uint32_t(out.parts.size()));
  }
  return out;
}

}  // namespace sb
