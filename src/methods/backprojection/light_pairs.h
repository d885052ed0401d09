// Stage 2's exact evaluations of one uniform light over one receiver, the PairSource the
// refinement (texel_refinement.h) asks for samples: per texel, its shaft's blockers (the tile's
// list, prepared once per tile) back-projected onto the light (penumbra_estimator.h), the ray to
// the light's centre first where it settles an umbra, the reference's rays where a sliver of the
// light or a sphere's parallax needs them.
#pragma once

#include <cstddef>
#include <memory>

#include "methods/backprojection/backprojection_bake.h"
#include "methods/backprojection/texel_refinement.h"
#include "scene/lights.h"
#include "texels/texel_space.h"

namespace sb {

// The most candidates a tile lists (tile_shafts.h) before its texels search the hierarchy one by
// one.
inline constexpr std::size_t kTileCandidates = 1 << 16;

// The evaluations of `light` over `space`, whose tiles' shaft tests are `tiles`.
std::unique_ptr<PairSource> light_pairs(const TexelSpace& space, const Light& light,
                                        const BackprojectionInputs& in, const TileShafts& tiles);

}  // namespace sb
