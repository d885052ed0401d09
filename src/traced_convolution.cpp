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
#include "traced_convolution.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>

#include "shadow_rays.h"

namespace sb {

Expected<Image> bake_traced_convolution(const TexelSpace& space, const TracedConvolutionInputs& in,
                                        std::vector<PairReport>* reports, ConvolutionPlan* plan,
                                        TracedConvolutionStats* stats) {
  const std::vector<Light>& lights = *in.convolution.lights;
  const std::size_t n = space.texels.size();
  ConvolutionInputs conv = in.convolution;
  // The convolution may cost at most half what the reference at 64 samples would per texel
  // (the method must never be slower than the rays it replaces), or half what tracing the texel
  // at `samples` would, where it traces.
  conv.cost_budget_per_texel = 0.5 * 64 * kRayCostUnits;
  if (in.rays) {
    conv.ray_cost_per_texel = in.samples * kRayCostUnits;
    conv.trace_error_texels = in.trace_error_texels;
    conv.cost_budget_per_texel =
        std::min(conv.cost_budget_per_texel, 0.5 * conv.ray_cost_per_texel);
  }
  std::vector<std::vector<std::uint8_t>> maybe;
  if (in.culler) {
    const double offset = in.rays ? in.rays->surface_offset() : 0.0;
    for (const Light& light : lights)
      maybe.push_back(in.culler->maybe_blocked(space, light, offset));
    conv.maybe_blocked = &maybe;
  }
  ConvolutionVisibility per_light;
  auto convolved = bake_convolution(space, conv, reports, plan, &per_light);
  if (!convolved) return convolved.error();

  const bool weights_needed = lights.size() > 1 || conv.quantity == Quantity::irradiance;
  Image out(space.width, space.height, 3, 0.0f);
  std::atomic<std::int64_t> pairs{0}, clear{0}, traced{0}, rays_traced{0};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const auto& r) {
    ShadowRays batch(in.samples);
    std::vector<Vec2> strata;
    std::int64_t local_pairs = 0, local_clear = 0, local_traced = 0, local_rays = 0;
    for (std::size_t t = r.begin(); t != r.end(); ++t) {
      const Texel& tx = space.texels[t];
      const Vec3 p = tx.position.cast<double>(), normal = tx.normal.cast<double>();
      Vec3 sum = Vec3::Zero(), weight = Vec3::Zero();
      const bool buried = !per_light.buried.empty() && per_light.buried[t];
      for (std::size_t l = 0; l < lights.size() && !buried; ++l) {
        if (!lights[l].reaches(p, normal)) continue;
        ++local_pairs;
        const bool planned = !per_light.visible[l].empty() && per_light.reached[l][t];
        Vec3 v = planned ? Vec3(per_light.visible[l][t].cast<double>()) : Vec3::Ones();
        if (!maybe.empty() && !maybe[l][t]) {
          ++local_clear;
        } else if (in.rays) {
          // A texel the plan left out (behind a frustum's near plane) is not vouched for either.
          const float e = planned ? per_light.error_texels[l][t] : -1.0f;
          if (e < 0 || e > in.trace_error_texels) {
            Vec3 traced_v;
            if (estimate_visibility(tx, l, lights[l], *in.rays, in.samples, in.seed, in.stream,
                                    space.width, batch, strata, &traced_v)) {
              v = traced_v;
              local_rays += batch.size();
            }
            ++local_traced;
          }
        }
        const Vec3 w =
            weights_needed ? lights[l].unoccluded_irradiance(p, normal) : lights[l].exitance();
        sum += w.cwiseProduct(v);
        weight += w;
      }
      float* px = out.at(tx.x, tx.y);
      for (int c = 0; c < 3; ++c) {
        px[c] = float(conv.quantity == Quantity::irradiance
                          ? sum[c]
                          : (weight[c] > 0 ? sum[c] / weight[c] : 0.0));
      }
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
  return out;
}

}  // namespace sb
