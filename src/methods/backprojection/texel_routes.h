// Where a (light, texel) pair's visibility comes from in the `backprojection` method: the one
// place that names the routes, what each one computes, and in which order a pair is offered to
// them (backprojection_bake.cpp follows it; the manifest's method_stats and --explain count
// pairs by route).
//
//   clear         The shaft test (occluders/shaft_culling.cpp) finds no blocker triangle between
//                 the texel and the light, for its patch (its tile of 8 × 8 texels' piece of
//                 surface it lies on) or for the texel alone: V = 1 exactly, nothing else is
//                 computed.
//   umbra         The shaft test's other sure answer: one triangle hides all of the light from
//                 the eight corners of the patch's box of ray origins, so from every texel of it
//                 (a triangle's umbra is convex): the triangle the ray from the box's centre to
//                 the light's centre meets, or one of the patch's candidates; or, for one texel,
//                 the triangle the ray from its origin to the light's centre meets hides all of
//                 the light from it. V = 0 exactly, nothing else is computed.
//   exact         The back-projection estimator (penumbra_estimator.cpp): the blockers of the
//                 texel's own shaft projected onto the light and integrated with the irradiance
//                 weight in closed form; no noise.
//   interpolated  Inside a cell of 2, 4 or 8 texels whose corners and centre are exact, where the
//                 centre agrees with what the corners predict, the surface is one smooth piece,
//                 every blocker of its texels' shafts is among the samples' and far enough away
//                 that no penumbra is narrower than two cells (texel_refinement.cpp).
//   traced        The same estimate with the blocking of each pair of cells found by a shadow ray
//                 to a fixed point of the light, where a shaft holds more polygons than listing
//                 them is worth; or, for a textured light, the reference's own estimate at
//                 `samples` rays (the estimator weighs a uniform light only); or, for a point
//                 light, one ray to it (exact: its shadows are hard).
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

namespace sb {

enum class TexelRoute : std::uint8_t {
  none,  // the light does not reach the texel (H0 = 0), or the texel is not covered
  clear,
  umbra,
  exact,
  interpolated,
  traced
};

constexpr std::array<TexelRoute, 5> kTexelRoutes = {TexelRoute::clear, TexelRoute::umbra,
                                                    TexelRoute::exact, TexelRoute::interpolated,
                                                    TexelRoute::traced};

constexpr std::string_view to_string(TexelRoute r) {
  switch (r) {
    case TexelRoute::none:
      return "none";
    case TexelRoute::clear:
      return "clear";
    case TexelRoute::umbra:
      return "umbra";
    case TexelRoute::exact:
      return "exact";
    case TexelRoute::interpolated:
      return "interpolated";
    case TexelRoute::traced:
      return "traced";
  }
  return "none";
}

// (light, texel) pairs by route, and the rays traced.
struct RouteCounts {
  std::array<std::int64_t, 7> pairs{};  // indexed by TexelRoute
  std::int64_t rays = 0;
  std::int64_t& operator[](TexelRoute r) { return pairs[std::size_t(r)]; }
  std::int64_t operator[](TexelRoute r) const { return pairs[std::size_t(r)]; }
  // Every pair but none.
  std::int64_t reached() const {
    std::int64_t sum = 0;
    for (TexelRoute r : kTexelRoutes) sum += (*this)[r];
    return sum;
  }
};

}  // namespace sb
