// The virtual parallel configuration (docs/design.md §3) and the penumbra error metric (§4).
//
// Soler & Sillion project blockers and receiver onto planes perpendicular to a direction D
// chosen as the axis of the frustum from the light to the receiver; here D runs from the light's
// centre to the centre of the receiver's lit texels. For a blocker point at depth d and a
// receiver point at depth r (along D), the penumbra on the receiver is L·(r − d)/d = L·(ρ − 1)
// with ρ = r/d, so one pair of planes, which fixes one ρ*, gets every penumbra width wrong by
// L·|ρ − ρ*|; the middle of ρ's range halves the worst case.
#include "methods/convolution/virtual_configuration.h"

#include <algorithm>
#include <cmath>

namespace sb {

VirtualConfiguration choose_configuration(const ProjectionFrame& frame, const DepthRange& blockers,
                                          const DepthRange& receiver, double light_extent) {
  VirtualConfiguration c;
  c.frame = frame;
  c.blocker_depths = blockers;
  c.receiver_depths = receiver;
  c.light_extent = light_extent;
  c.receiver_plane = receiver.empty() ? 1.0 : std::max(receiver.mid(), 1e-9);
  if (blockers.empty() || receiver.empty() || blockers.lo <= 0) {
    c.rho_lo = c.rho_hi = c.rho = 1.0;
  } else {
    c.rho_lo = std::max(1.0, receiver.lo / blockers.hi);
    c.rho_hi = std::max(c.rho_lo, receiver.hi / blockers.lo);
    c.rho = 0.5 * (c.rho_lo + c.rho_hi);
  }
  c.blocker_plane = c.receiver_plane / c.rho;
  c.penumbra_error = light_extent * 0.5 * (c.rho_hi - c.rho_lo);
  return c;
}

}  // namespace sb
