// The convolution method with exact shaft culling and traced fallbacks (traced_convolution.h).
//
// Why this shape. Soler & Sillion's convolution is exact for parallel planes and approximate
// elsewhere by a penumbra error ε that its plan knows per leaf. On scenes as artists make them
// most of what a light reaches has nothing in its way (a floor is in shadow only around its
// furniture): there the answer is exactly 1 and costs a shaft test (shaft_culling.cpp), not a
// convolution. What remains splits by what the plan can promise: where its leaves' ε is within
// `trace_error_texels`, the convolution's value stands; where it is not (walls crossing the
// light's depth, curved blockers near the light, lights among geometry), or where a blocker may
// cross a texel's shaft that no leaf accounted for, the texel takes the reference's own estimate
// (estimate_visibility, same stream), so it costs what the reference costs there and is as good.
#include "methods/convolution/traced_convolution.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>

#include "occluders/shadow_rays.h"

namespace sb {

namespace {

// How close to 0 or 1 the convolution's V must be to count as wholly hidden or wholly seen.
constexpr float kCertain = 2e-3f;
// Texels around a traced one that are traced too (either axis), against a penumbra the
// convolution placed up to its ε (1 texel at the default target) off.
constexpr int kTraceMargin = 2;

// The convolution's inputs with the budget that tracing sets: the convolution may cost at most
// half what the reference at 64 samples would per texel (the method must never be slower than
// the rays it replaces), or half what tracing the texel at `samples` would, where it traces.
ConvolutionInputs budgeted_inputs(const TracedConvolutionInputs& in) {
  ConvolutionInputs conv = in.convolution;
  conv.plan.cost_budget_per_texel = 0.5 * 64 * kRayCostUnits;
  if (in.rays) {
    conv.plan.ray_cost_per_texel = in.samples * kRayCostUnits;
    conv.plan.trace_error_texels = in.trace_error_texels;
    conv.plan.cost_budget_per_texel =
        std::min(conv.plan.cost_budget_per_texel, 0.5 * conv.plan.ray_cost_per_texel);
  }
  return conv;
}

// Per light and texel, whether a blocker may lie in the shaft between them (the culler's
// answer); empty without a culler.
std::vector<std::vector<std::uint8_t>> maybe_blocked(const TexelSpace& space,
                                                     const TracedConvolutionInputs& in) {
  const std::vector<Light>& lights = *in.convolution.plan.lights;
  std::vector<std::vector<std::uint8_t>> maybe;
  if (in.culler) {
    const double offset = in.rays ? in.rays->surface_offset() : 0.0;
    for (const Light& light : lights)
      maybe.push_back(in.culler->maybe_blocked(space, light, offset));
  }
  return maybe;
}

// Per texel, whether light l's convolved value there cannot stand (bake_traced_convolution
// says when): the seeds around which texels are traced.
std::vector<std::uint8_t> trace_seeds(const TexelSpace& space, const TracedConvolutionInputs& in,
                                      const ConvolutionVisibility& per_light,
                                      const std::vector<std::vector<std::uint8_t>>& maybe,
                                      std::size_t l) {
  const std::size_t n = space.texels.size();
  std::vector<std::uint8_t> seed(n, 0);
  for (std::size_t t = 0; t < n; ++t) {
    if (!maybe.empty() && !maybe[l][t]) continue;
    const bool planned = !per_light.visible[l].empty() && per_light.reached[l][t];
    const float e = planned ? per_light.error_texels[l][t] : -1.0f;
    bool partial = false;
    if (planned)
      for (int c = 0; c < 3; ++c) {
        const float v = per_light.visible[l][t][c];
        partial = partial || (v > kCertain && v < 1 - kCertain);
      }
    seed[t] = e < 0 || e > in.trace_error_texels || partial;
  }
  return seed;
}

// Per light and texel, whether the pair is traced: each seed and the texels within
// kTraceMargin of it that the shaft test keeps.
std::vector<std::vector<std::uint8_t>> traced_pairs(
    const TexelSpace& space, const TracedConvolutionInputs& in,
    const ConvolutionVisibility& per_light, const std::vector<std::vector<std::uint8_t>>& maybe) {
  const std::vector<Light>& lights = *in.convolution.plan.lights;
  const std::size_t n = space.texels.size();
  std::vector<std::vector<std::uint8_t>> trace(lights.size());
  std::vector<std::int32_t> texel_at(std::size_t(space.width) * space.height, -1);
  for (std::size_t t = 0; t < n; ++t)
    texel_at[std::size_t(space.texels[t].y) * space.width + std::size_t(space.texels[t].x)] =
        std::int32_t(t);
  for (std::size_t l = 0; l < lights.size(); ++l) {
    const std::vector<std::uint8_t> seed = trace_seeds(space, in, per_light, maybe, l);
    trace[l].assign(n, 0);
    for (std::size_t t = 0; t < n; ++t) {
      if (!seed[t]) continue;
      const int x = space.texels[t].x, y = space.texels[t].y;
      for (int dy = -kTraceMargin; dy <= kTraceMargin; ++dy)
        for (int dx = -kTraceMargin; dx <= kTraceMargin; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= space.width || yy >= space.height) continue;
          const std::int32_t u = texel_at[std::size_t(yy) * space.width + std::size_t(xx)];
          if (u >= 0 && (maybe.empty() || maybe[l][std::size_t(u)])) trace[l][std::size_t(u)] = 1;
        }
    }
  }
  return trace;
}

}  // namespace

Expected<MixedImages> bake_traced_convolution(const TexelSpace& space,
                                              const TracedConvolutionInputs& in,
                                              std::vector<PairReport>* reports,
                                              ConvolutionPlan* plan,
                                              TracedConvolutionStats* stats) {
  const std::vector<Light>& lights = *in.convolution.plan.lights;
  const std::size_t n = space.texels.size();
  ConvolutionInputs conv = budgeted_inputs(in);
  const std::vector<std::vector<std::uint8_t>> maybe = maybe_blocked(space, in);
  if (in.culler) conv.plan.maybe_blocked = &maybe;
  ConvolutionVisibility per_light;
  if (in.convolve || !in.rays) {
    auto convolved = bake_convolution(space, conv, reports, plan);
    if (!convolved) return convolved.error();
    per_light = std::move(*convolved);
  } else {  // no leaf: every pair the shaft test keeps is traced
    per_light.visible.resize(lights.size());
    per_light.reached.resize(lights.size());
    per_light.error_texels.resize(lights.size());
  }

  // Which (light, texel) pairs are traced. The convolution's penumbra values are approximate
  // beyond what ε measures (the slabs' shares, the first-order weighting), so a texel it finds
  // partly lit is traced, as is one whose leaves' ε is above trace_error_texels or which no leaf
  // accounted for; its own answer stands only where it finds the light wholly seen or wholly
  // hidden, and not within kTraceMargin texels of a traced one (where a penumbra it placed up
  // to ε off may begin).
  const std::vector<std::vector<std::uint8_t>> trace =
      in.rays ? traced_pairs(space, in, per_light, maybe)
              : std::vector<std::vector<std::uint8_t>>(lights.size());

  LightMix mix(space, lights, conv.quantity, LightMix::Order::texel_major, in.keep_per_light);
  std::atomic<std::int64_t> pairs{0}, clear{0}, traced{0}, rays_traced{0};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const auto& r) {
    ShadowRays batch(in.samples);
    std::vector<Vec2> strata;
    std::int64_t local_pairs = 0, local_clear = 0, local_traced = 0, local_rays = 0;
    for (std::size_t t = r.begin(); t != r.end(); ++t) {
      const Texel& tx = space.texels[t];
      const Vec3 p = tx.position.cast<double>(), normal = tx.normal.cast<double>();
      LightMix::Sum sum;
      const bool buried = !per_light.buried.empty() && per_light.buried[t];
      for (std::size_t l = 0; l < lights.size() && !buried; ++l) {
        if (!lights[l].reaches(p, normal)) continue;
        ++local_pairs;
        const bool planned = !per_light.visible[l].empty() && per_light.reached[l][t];
        Vec3 v = planned ? Vec3(per_light.visible[l][t].cast<double>()) : Vec3::Ones();
        if (!maybe.empty() && !maybe[l][t]) {
          ++local_clear;
        } else if (in.rays && trace[l][t]) {
          Vec3 traced_v;
          ++local_traced;
          // As the reference does: a light none of whose samples contributes is left out.
          if (!estimate_visibility(space, t, lights[l], *in.rays, in.samples, in.seed, in.stream,
                                   batch, strata, &traced_v))
            continue;
          v = traced_v;
          local_rays += batch.size();
        }
        mix.add(sum, l, t, mix.unoccluded(l, t), v);
      }
      mix.write(t, sum);
    }
    pairs += local_pairs;
    clear += local_clear;
    traced += local_traced;
    rays_traced += local_rays;
  });
  if (stats) {
    stats->pairs += pairs;
    stats->clear += clear;
    stats->traced += traced;
    stats->convolved += pairs - clear - traced;
    stats->rays += rays_traced;
  }
  return mix.finish();
}

}  // namespace sb
