// The refinement step of plan_convolution (convolution_plan.cpp), in plan_refinement.cpp.
#pragma once

#include <cstddef>

#include "methods/convolution/convolution_plan.h"

namespace sb {

// Refines every root of the frames [frame_begin, frame_end) of `plan` within `budget` leaves:
// while a leaf's ε exceeds in.error_texels and the leaf and cost budgets allow, the worst leaf is
// split by whichever candidate (blocker depth, blocker space, receiver depth) lowers ε most per
// unit of estimated work.
void refine_triples(ConvolutionPlan& plan, const PlanInputs& in, std::size_t frame_begin,
                    std::size_t frame_end, int budget);

}  // namespace sb
