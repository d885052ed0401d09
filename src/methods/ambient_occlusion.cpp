// Ambient occlusion by rays (ambient_occlusion.h). Cosine-weighted directions make every ray
// count equally, so A is a plain fraction; stratified per texel (core/sampling.h), it has the
// reference's noise per sample and no bias. Rays leave from the texel's shadow origin lifted off
// its surface as the reference's shadow rays do (occluders/shadow_rays.h), so flat surfaces do
// not occlude themselves and smooth-shaded coarse ones do not darken along their terminators.
#include "methods/ambient_occlusion.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <vector>

#include "core/sampling.h"

namespace sb {
namespace {

// Where RayScene::buried asks about texel t: its position, or, where that lies on an edge of its
// triangle (the centre fell off it: uv_rasterizer's nearest-point rule), a few surface offsets
// towards the triangle's centroid, so that buried()'s rays do not graze the faces meeting there
// (the edge of a wall's bottom on a floor).
Vec3 buried_query_point(const TexelSpace& space, std::size_t t, const Mesh* mesh, double offset) {
  const Texel& texel = space.texels[t];
  const Vec3 p = texel.position.cast<double>();
  if (mesh == nullptr || std::size_t(texel.face) >= mesh->mesh.n_faces()) return p;
  const Triangle tri = triangle(mesh->mesh, mesh->mesh.face_handle(texel.face));
  const Vec3 towards = (tri.p[0] + tri.p[1] + tri.p[2]) / 3.0 - p;
  const double length = towards.norm();
  return length > 0 ? Vec3(p + std::min(4.0 * offset, 0.5 * length) / length * towards) : p;
}

}  // namespace

Image bake_ambient_occlusion(const TexelSpace& space, const AmbientOcclusionInputs& in,
                             std::int64_t* rays_traced) {
  Image out(space.width, space.height, 3);
  const RayScene& rays = *in.rays;
  const double offset = rays.surface_offset();
  const int own = rays.blocker_index(in.mesh);
  std::atomic<std::int64_t> traced{0};
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, space.texels.size(), 64),
      [&](const tbb::blocked_range<std::size_t>& range) {
        std::vector<Vec2> strata;
        const std::size_t n = std::size_t(in.samples);
        std::vector<Vec3> origins(n), directions(n);
        const std::vector<double> lengths(n, in.distance);
        std::vector<std::uint8_t> hit(n);
        std::int64_t range_traced = 0;
        for (std::size_t t = range.begin(); t != range.end(); ++t) {
          const Texel& texel = space.texels[t];
          if (rays.buried(buried_query_point(space, t, in.mesh, offset),
                          space.geometric_normal(t).cast<double>(), own,
                          space.face_normals[std::size_t(texel.face)].cast<double>())) {
            for (int c = 0; c < 3; ++c) out.at(texel.x, texel.y)[c] = 0.0f;
            continue;
          }
          const Vec3 normal = texel.normal.cast<double>();
          const Vec3 origin = space.ray_origin(t, offset);
          Rng rng(stream_seed(in.seed, in.stream, std::uint64_t(texel.y) * space.width + texel.x));
          stratified_samples(in.samples, rng, strata);
          for (std::size_t s = 0; s < n; ++s) {
            origins[s] = origin;
            directions[s] = cosine_direction(normal, strata[s]);
          }
          rays.occluded(int(n), origins.data(), directions.data(), lengths.data(), hit.data());
          range_traced += std::int64_t(n);
          std::size_t open = 0;
          for (std::size_t s = 0; s < n; ++s) open += hit[s] ? 0 : 1;
          const float a = float(double(open) / double(n));
          for (int c = 0; c < 3; ++c) out.at(texel.x, texel.y)[c] = a;
        }
        traced += range_traced;
        if (in.texels_done) {
          const auto done = (*in.texels_done += std::int64_t(range.size()));
          if (in.progress) in.progress(double(done));
        }
      });
  if (rays_traced) *rays_traced += traced.load();
  return out;
}

namespace {

class AmbientOcclusionMethod final : public Method {
 public:
  explicit AmbientOcclusionMethod(const BakeContext& context) : context_(context) {}

  Expected<MethodResult> bake(const ReceiverInput& receiver) override {
    const BakeSettings& settings = context_.scene->bake;
    AmbientOcclusionInputs in;
    in.rays = context_.rays;
    in.mesh = receiver.mesh;
    in.distance = settings.ao_distance;
    in.samples = settings.samples;
    in.seed = settings.seed;
    in.stream = receiver.stream;
    in.texels_done = context_.texels_done;
    in.progress = context_.progress;
    MethodResult result;
    result.images.image = bake_ambient_occlusion(*receiver.space, in, &result.rays);
    return result;
  }

 private:
  BakeContext context_;
};

}  // namespace

MethodEntry ambient_occlusion_method() {
  MethodEntry e;
  e.name = "ambient-occlusion";
  e.settings = {"samples", "seed", "ao_distance"};
  e.needs = [](const BakeSettings&) { return MethodNeeds{.rays = true}; };
  e.make = [](const BakeContext& context) -> Expected<std::unique_ptr<Method>> {
    return std::unique_ptr<Method>(std::make_unique<AmbientOcclusionMethod>(context));
  };
  e.tile_halo = 0;  // each texel's rays are its own
  e.local = true;
  e.only_quantity = Quantity::ambient_occlusion;
  return e;
}

}  // namespace sb
