// Stage 2 of the `backprojection` bake (backprojection_bake.cpp), per light: the exact
// evaluations of one uniform light over one receiver, made ready for the refinement
// (texel_refinement.h, stage 3) to ask for samples: per texel, its shaft's blockers (the tile's
// list, prepared once per tile) back-projected onto the light (penumbra_estimator.h), the ray to
// the light's centre first where it settles an umbra, the reference's rays where a sliver of the
// light or a sphere's parallax needs them.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "methods/backprojection/backprojection_settings.h"
#include "methods/backprojection/texel_routes.h"
#include "methods/backprojection/tile_shafts.h"
#include "scene/lights.h"
#include "texels/texel_space.h"

namespace sb {

// One exact evaluation of the light at a texel.
struct PairSample {
  float visibility = 1;
  TexelRoute route = TexelRoute::none;  // clear, exact or traced; none: the light does not reach
  // Lower bound on the distance to the nearest blocker of its shaft, metres (infinity: none).
  float nearest = std::numeric_limits<float>::infinity();
  // The blockers (ShaftCuller::blocker_key: triangles, or convex solids) that reach the light
  // from the texel, sorted, when listed.
  std::vector<std::uint32_t> triangles;
  // False where the blockers were not listed (a shaft traced past the estimator's budget):
  // then the distance bound is all the refinement has to go on.
  bool listed = true;
  // A convex solid or one polygon that hides all of the light by itself, or
  // PenumbraSample::kNoUmbra.
  std::uint32_t umbra = 0xffffffffu;
};

// Stage 2's output: one evaluator of a light's (light, texel) pairs, which the refinement asks
// for what it needs. It is asked, not filled ahead, because the refinement alone knows which
// texels need an exact sample (its cells' corners, and the texels of the cells whose checks
// fail) and which cells need the three cell-wide questions below: evaluating every texel first
// would cost what the refinement exists to save. Its tests give it a synthetic field instead
// (texel_refinement_test.cpp), hence an interface.
class PairSource {
 public:
  virtual ~PairSource() = default;
  virtual void evaluate(std::size_t t, PairSample& out) const = 0;
  // The light's narrowest apparent width seen from texel t, radians: a blocker at distance d
  // from the texel casts no penumbra on it narrower than this times d.
  virtual double angular_width(std::size_t t) const = 0;
  // Whether a blocker not among `listed` (keys, sorted) may lie in the shaft of one of `texels`
  // (a cell's, all in one tile): one that none of the cell's samples saw.
  virtual bool sees_unlisted(const std::vector<std::size_t>& texels,
                             const std::vector<std::uint32_t>& listed) const = 0;
  // Whether one triangle of the blockers `seen` (keys, sorted) hides all of the light from each
  // of `samples` (a cell's five, the first in its tile): a triangle's umbra is convex, so it holds
  // every point between them. False where the source cannot tell.
  virtual bool one_triangle_hides(const std::array<std::size_t, 5>& samples,
                                  const std::vector<std::uint32_t>& seen) const {
    (void)samples, (void)seen;
    return false;
  }
  // Whether a ball inside one closed blocker of `seen` hides all of the light from every point
  // of the box of `texels`' ray origins (a cell's, all outside the blocker): the ball's umbra is
  // convex, and a ray into the ball from outside the blocker meets the blocker's surface. False
  // where the source cannot tell.
  virtual bool ball_hides(const std::vector<std::size_t>& texels,
                          const std::vector<std::uint32_t>& seen) const {
    (void)texels, (void)seen;
    return false;
  }
};

// The evaluations of `light` over `space`, whose tiles' shaft tests are `tiles`.
std::unique_ptr<PairSource> light_pairs(const TexelSpace& space, const Light& light,
                                        const BackprojectionInputs& in, const TileShafts& tiles);

}  // namespace sb
