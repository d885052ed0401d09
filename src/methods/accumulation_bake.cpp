// The `accumulation` baseline: the accumulation buffer of Heckbert & Herf ("Simulating soft
// shadows with graphics hardware", CMU-CS-97-104, 1997), as Marschner's notes describe it
// (docs/design.md [S2], "Accumulating shadow textures"): the area light is
// replaced by a constellation of point lights, "one random set of points ... kept fixed", and the
// soft shadow texture is the sum of their hard shadow textures.
//
// What it computes, per light: `samples` stratified points on the light, drawn once from the seed
// and the light's index and then shared by every texel of every receiver, so the result is
// exactly an average of `samples` hard shadows (and two receivers meeting at a seam see the same
// hard shadows). Each hard shadow is weighted as that point light's irradiance would be,
// w = cosθ_light·cosθ_receiver / r² (Light::sample's weight), times the light's texture at the
// point, per channel, and V = Σ w·v / Σ w: the estimator the reference uses, with the difference
// that the reference draws fresh points per texel. With few points the shadow is a stack of
// hard-edged copies of the blocker's silhouette: at most `samples` + 1 visibility levels across a
// penumbra (the banding users compare), where the reference shows noise instead.
//
// Hard shadows by shadow rays (Embree, batched as reference_bake.cpp batches them), not by one
// shadow map per point: ray-cast hard shadows are exact, so the error measured against the
// reference is the method's own (banding from a finite point set), not shadow-map resolution,
// aliasing or depth bias, which belong to the shadow-map baselines. Ray origins, offsets and
// lengths follow reference_bake.cpp exactly.
//
// A sphere light: Light::sample maps its strata into the cone the sphere subtends from each
// receiver point, so the points would move with the texel. Here "a fixed point set" is `samples`
// points stratified uniformly over the sphere's whole surface (Archimedes' equal-area map:
// z = 1 − 2u, φ = 2πv), each a point light emitting into its own hemisphere. A texel uses the
// points on the cap facing it (cosθ_light > 0), with the area-sampling weight above, so about half
// of them: a sphere needs twice the points of a disk for the same banding.
//
// Lights are combined with LightMix (closed-form H0 weights, as every method).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <numbers>

#include "core/sampling.h"
#include "methods/baselines.h"
#include "occluders/shadow_rays.h"

namespace sb {

namespace {

// Keys the fixed point sets apart from the reference's per-texel streams.
constexpr std::uint64_t kAccumulationStream = 0xACC0'0000'0000'0001ull;

// One light's fixed constellation: stratified points in [0,1)² (rectangle, disk: mapped by
// Light::sample, whose point does not depend on the receiver) or world points with outward
// normals on a sphere.
struct Constellation {
  std::vector<Vec2> strata;
  std::vector<Vec3> sphere_points, sphere_normals;
};

Constellation make_constellation(const Light& light, int samples, std::uint64_t seed) {
  Constellation c;
  Rng rng(stream_seed(seed, kAccumulationStream, light.stream()));
  stratified_samples(samples, rng, c.strata);
  if (light.shape() == LightShape::sphere) {
    const double radius = light.desc().radius;
    for (const Vec2& u : c.strata) {
      const double z = 1.0 - 2.0 * u.x();
      const double ring = std::sqrt(std::max(0.0, 1.0 - z * z));
      const double phi = 2.0 * std::numbers::pi * u.y();
      const Vec3 m(ring * std::cos(phi), ring * std::sin(phi), z);
      c.sphere_normals.push_back(m);
      c.sphere_points.push_back(light.centre() + radius * m);
    }
  }
  return c;
}

// Point k of the constellation seen from (y, n): its position and weight (0: it faces away or
// lies below the horizon), the weight per channel including the light's texture.
LightSample constellation_point(const Light& light, const Constellation& c, int k, const Vec3& y,
                                const Vec3& n) {
  if (c.sphere_points.empty()) return light.sample(y, n, c.strata[k]);
  LightSample s;
  s.point = c.sphere_points[k];
  const Vec3 d = s.point - y;
  const double dist2 = d.squaredNorm();
  if (dist2 <= 0) return s;
  const double inv = 1.0 / std::sqrt(dist2);
  const double cos_light = -d.dot(c.sphere_normals[k]) * inv;
  const double cos_receiver = d.dot(n) * inv;
  if (cos_light > 0 && cos_receiver > 0) s.weight = cos_light * cos_receiver / dist2;
  return s;
}

}  // namespace

MixedImages bake_accumulation(const TexelSpace& space, const BaselineInputs& in, MethodStats* stats,
                              std::int64_t* rays_traced) {
  const auto& lights = *in.lights;
  const RayScene& rays = *in.rays;
  const BaselineSettings& settings = in.settings;
  const int samples = std::max(1, settings.samples);
  const double offset = rays.surface_offset();

  // Seeded by the light alone (not in.stream): every receiver sees the same hard shadows.
  std::vector<Constellation> constellations;
  for (std::size_t l = 0; l < lights.size(); ++l)
    constellations.push_back(make_constellation(lights[l], samples, settings.seed));

  LightMix mix(space, lights, settings.quantity, LightMix::Order::texel_major, in.keep_per_light);
  std::atomic<std::int64_t> traced{0}, contributing{0}, pairs{0};

  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, space.texels.size(), 64),
      [&](const tbb::blocked_range<std::size_t>& range) {
        ShadowRays batch(samples);
        std::int64_t local_rays = 0, local_points = 0, local_pairs = 0;
        for (std::size_t t = range.begin(); t != range.end(); ++t) {
          const Texel& texel = space.texels[t];
          const Vec3 position = texel.position.cast<double>();
          const Vec3 normal = texel.normal.cast<double>();
          const Vec3 origin = space.ray_origin(t, offset);
          LightMix::Sum sum;
          for (std::size_t l = 0; l < lights.size(); ++l) {
            if (!lights[l].reaches(position, normal)) continue;
            batch.clear();
            for (int k = 0; k < samples; ++k)
              batch.add(origin,
                        constellation_point(lights[l], constellations[l], k, position, normal),
                        offset);
            ++local_pairs;
            local_points += batch.size();
            // No point of the constellation faces the texel (a sphere light with very few
            // points, a panel mostly below the horizon): like the reference, the light adds
            // nothing here rather than a guess.
            Vec3 v;
            if (!batch.visible_fraction(rays, &v)) continue;
            local_rays += batch.size();
            mix.add(sum, l, t, mix.unoccluded(l, t), v);
          }
          mix.write(t, sum);
        }
        traced += local_rays;
        contributing += local_points;
        pairs += local_pairs;
      });

  if (rays_traced) *rays_traced += traced.load();
  if (stats) {
    stats->emplace_back("points per light", double(samples));
    // Below `points per light` only where points face away: a sphere (about half) or a light
    // partly below texels' horizons.
    stats->emplace_back("mean points facing a texel",
                        pairs.load() > 0 ? double(contributing.load()) / double(pairs.load()) : 0);
  }
  return mix.finish();
}

}  // namespace sb
