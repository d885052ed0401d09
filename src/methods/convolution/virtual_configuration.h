// The convolution's virtual parallel configuration of one (light, blockers, receiver) triple, and
// the penumbra error metric that places its planes (docs/design.md §3–4; docs/design.md [S1],
// "General Configuration" and "Measuring the Error").
#pragma once

#include "occluders/projection_frame.h"

namespace sb {

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
