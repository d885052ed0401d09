// The ray-traced reference (docs/design.md §1 and §7): the ground truth every other method is
// measured against. For each covered texel and each light, `samples` stratified points on the
// light, one shadow ray each; the light's visibility is the ratio estimate Σ w·v / Σ w (lights.cpp
// says why), per colour channel with w scaled by the light's texture at the sample, its
// unoccluded irradiance H0 is exact (for a textured light, see Light::unoccluded_irradiance),
// and H = H0 · V. A sky is estimated as itself, not as its parts: rays over the whole sky
// (methods/sky_rays.h), its H0 and V from the same directions, added as its first part's.
// Parallel over texels with
// oneTBB; each texel has its own random stream, so the result is the same for any thread count.
#include "methods/reference_bake.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <optional>

#include "methods/sky_rays.h"
#include "occluders/shadow_rays.h"

namespace sb {

MixedImages bake_reference(const TexelSpace& space, const ReferenceInputs& in,
                           std::int64_t* rays_traced) {
  const auto& lights = *in.lights;
  const RayScene& rays = *in.rays;
  std::optional<LightLists> own;
  const LightLists& lists = in.lists ? *in.lists : own.emplace(space, lights);
  LightMix mix(space, lights, in.quantity, LightMix::Order::texel_major, in.keep_per_light, &lists);
  std::atomic<std::int64_t> traced{0};
  // Counted: the kept rows' rays (a tile's halo, traced for the terminators' neighbours, is not).
  const auto [kept0, kept1] = kept_texels(space);

  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, space.texels.size(), 64),
      [&](const tbb::blocked_range<std::size_t>& range) {
        std::vector<Vec2> strata;
        ShadowRays batch(in.samples);
        SkyRays sky_rays;
        std::int64_t local_rays = 0;
        for (std::size_t t = range.begin(); t != range.end(); ++t) {
          const Texel& texel = space.texels[t];
          const std::int64_t before = local_rays;
          LightMix::Sum sum;
          // The lights that may reach it (its block's list): the others add nothing.
          for (const std::uint32_t light : lists.lights_of(lists.block_of(texel.x, texel.y))) {
            const std::size_t l = light;
            if (const Sky* sky = lights[l].sky()) {
              // The whole sky at its first part; its other parts add nothing.
              if (l > 0 && lights[l - 1].sky() == sky) continue;
              Vec3 h0, v;
              if (estimate_sky(space, t, *sky, rays, in.samples, in.seed,
                               stream_seed(in.stream, lights[l].stream()),
                               (lights[l].centre() - texel.position.cast<double>()).norm(),
                               sky_rays, &h0, &v, &local_rays))
                mix.add(sum, l, t, h0, v);
              continue;
            }
            const Vec3 h0 = mix.unoccluded(l, t);
            if (h0.maxCoeff() <= 0) continue;
            Vec3 v;
            if (!estimate_visibility(space, t, lights[l], rays, in.samples, in.seed, in.stream,
                                     batch, strata, &v))
              continue;
            local_rays += batch.size();
            mix.add(sum, l, t, h0, v);
          }
          mix.write(t, sum);
          if (t < kept0 || t >= kept1) local_rays = before;
        }
        traced += local_rays;
        if (in.texels_done) {
          const auto done = (*in.texels_done += std::int64_t(range.size()));
          if (in.progress) in.progress(double(done));
        }
      });
  if (rays_traced) *rays_traced += traced.load();
  return mix.finish();
}

namespace {

class ReferenceMethod final : public Method {
 public:
  explicit ReferenceMethod(const BakeContext& context) : context_(context) {}

  Expected<MethodResult> bake(const ReceiverInput& receiver) override {
    const BakeSettings& settings = context_.scene->bake;
    ReferenceInputs in;
    in.lights = context_.lights;
    in.rays = context_.rays;
    in.quantity = settings.quantity;
    in.samples = settings.samples;
    in.seed = settings.seed;
    in.stream = receiver.stream;
    in.texels_done = context_.texels_done;
    in.progress = context_.progress;
    in.keep_per_light = context_.keep_per_light;
    in.lists = receiver.lists;
    MethodResult result;
    result.images = bake_reference(*receiver.space, in, &result.rays);
    return result;
  }

 private:
  BakeContext context_;
};

}  // namespace

MethodEntry reference_method() {
  MethodEntry e;
  e.name = "reference";
  e.settings = {"samples", "seed"};
  e.needs = [](const BakeSettings&) { return MethodNeeds{.rays = true}; };
  e.make = [](const BakeContext& context) -> Expected<std::unique_ptr<Method>> {
    return std::unique_ptr<Method>(std::make_unique<ReferenceMethod>(context));
  };
  e.tile_halo = 1;  // its rays are its own; a terminator's texel reads its 8 neighbours
  e.local = true;
  return e;
}

}  // namespace sb
