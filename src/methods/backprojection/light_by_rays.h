// The rays' route of the `backprojection` bake (backprojection_bake.cpp), per light, after
// stage 1's shaft tests (tile_shafts.h): a light the estimator cannot weigh (a textured light's,
// whose emission is not uniform) or need not (a point's, whose shadows are hard) baked by the
// reference's own rays at the texels its shafts do not clear (light_by_rays.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "methods/backprojection/backprojection_settings.h"
#include "methods/backprojection/texel_grid.h"
#include "methods/backprojection/texel_routes.h"
#include "methods/backprojection/tile_shafts.h"
#include "methods/light_mix.h"
#include "texels/texel_space.h"

namespace sb {

// Light l over the tiles `in_reach` of `space`, set into `mix`: clear tiles and texels are 1,
// the rest the reference's estimate at `samples` rays; `counts` gets the pairs and rays.
void bake_light_by_rays(const TexelSpace& space, const TexelGrid& grid, const TileJoins& joins,
                        const BackprojectionInputs& in, std::span<const std::uint32_t> in_reach,
                        std::size_t l, int samples, LightMix& mix, RouteCounts& counts);

}  // namespace sb
