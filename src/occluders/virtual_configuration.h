// The virtual parallel configuration of one (light, blockers, receiver) triple, and the penumbra
// error metric that places its planes (docs/design.md §3–4; docs/design.md [S1],
// "General Configuration" and "Measuring the Error").
#pragma once

#include <limits>

#include "core/geometry.h"

namespace sb {

struct DepthRange {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void extend(double d) {
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  bool empty() const { return hi < lo; }
  double mid() const { return 0.5 * (lo + hi); }
};

// A projection direction D from the light's centre with two unit axes across it. Images live in
// "tangent" coordinates: a point p maps to ((p − o)·e1, (p − o)·e2) / ((p − o)·D), its central
// projection onto the plane at unit depth; the blocker plane at depth d is that plane scaled by d.
struct ProjectionFrame {
  Vec3 origin = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
  Vec3 e1 = Vec3::UnitX(), e2 = Vec3::UnitY();

  double depth(const Vec3& p) const { return (p - origin).dot(axis); }
  // Tangent coordinates of p (depth must be positive).
  Vec2 tangent(const Vec3& p) const {
    const Vec3 v = p - origin;
    const double inv = 1.0 / v.dot(axis);
    return Vec2(v.dot(e1) * inv, v.dot(e2) * inv);
  }
};

// The frame whose axis runs from `origin` towards `target`.
ProjectionFrame frame_towards(const Vec3& origin, const Vec3& target);

struct VirtualConfiguration {
  ProjectionFrame frame;
  DepthRange blocker_depths;   // along D, metres, of the blocker geometry that can shadow
  DepthRange receiver_depths;  // along D, metres, of the receiver's lit texels
  double light_extent = 0;     // L: the light's width across D, metres
  double rho_lo = 1, rho_hi = 1, rho = 1;  // ρ = r/d: its range and the chosen ρ*
  double receiver_plane = 0;               // r*: the receiver range's centre
  double blocker_plane = 0;                // d* = r*/ρ*
  double penumbra_error = 0;  // ε = L·(ρ_hi − ρ_lo)/2: worst penumbra-width error, metres
};

// Places the planes by the penumbra error metric: ρ spans [r_min/d_max, r_max/d_min]; the
// middle ρ* = (ρ_lo + ρ_hi)/2 minimises the worst error ε = L·max(ρ_hi − ρ*, ρ* − ρ_lo).
// Blocker depths beyond the receiver are the caller's to exclude; with no blockers, ρ* = 1.
VirtualConfiguration choose_configuration(const ProjectionFrame& frame, const DepthRange& blockers,
                                          const DepthRange& receiver, double light_extent);

}  // namespace sb
