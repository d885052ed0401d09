// The ray-traced reference (design-notes §1 and §7): the ground truth every other method is
// measured against. For each covered texel and each light, `samples` stratified points on the
// light, one shadow ray each; the light's visibility is the ratio estimate Σ w·v / Σ w (lights.cpp
// says why), per colour channel with w scaled by the light's texture at the sample, its
// unoccluded irradiance H0 is exact (for a textured light, see Light::unoccluded_irradiance),
// and H = H0 · V. Parallel over texels with
// oneTBB; each texel has its own random stream, so the result is the same for any thread count.
#include "methods/reference_bake.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "occluders/shadow_rays.h"

namespace sb {

Image bake_reference(const TexelSpace& space, const ReferenceInputs& in,
                     std::int64_t* rays_traced) {
  Image out(space.width, space.height, 3, 0.0f);
  const auto& lights = *in.lights;
  const RayScene& rays = *in.rays;
  std::atomic<std::int64_t> traced{0};

  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, space.texels.size(), 64),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      std::vector<Vec2> strata;
                      ShadowRays batch(in.samples);
                      std::int64_t local_rays = 0;
                      for (std::size_t t = range.begin(); t != range.end(); ++t) {
                        const Texel& texel = space.texels[t];
                        const Vec3 position = texel.position.cast<double>();
                        const Vec3 normal = texel.normal.cast<double>();
                        Vec3 h_sum = Vec3::Zero(), h0_sum = Vec3::Zero();
                        for (std::size_t l = 0; l < lights.size(); ++l) {
                          const Vec3 h0 = lights[l].unoccluded_irradiance(position, normal);
                          if (h0.maxCoeff() <= 0) continue;
                          Vec3 v;
                          if (!estimate_visibility(texel, l, lights[l], rays, in.samples, in.seed,
                                                   in.stream, space.width, batch, strata, &v))
                            continue;
                          local_rays += batch.size();
                          h_sum += h0.cwiseProduct(v);
                          h0_sum += h0;
                        }
                        float* px = out.at(texel.x, texel.y);
                        for (int c = 0; c < 3; ++c) {
                          double v = 0;
                          if (in.quantity == Quantity::irradiance) {
                            v = h_sum[c];
                          } else if (h0_sum[c] > 0) {
                            v = h_sum[c] / h0_sum[c];
                          }
                          px[c] = float(v);
                        }
                      }
                      traced += local_rays;
                      if (in.texels_done) {
                        const auto done = (*in.texels_done += std::int64_t(range.size()));
                        if (in.progress) in.progress(double(done));
                      }
                    });
  if (rays_traced) *rays_traced += traced.load();
  return out;
}

}  // namespace sb
