// Lightmap sides from a texel density (lightmap_sizes.h).
#include "texels/lightmap_sizes.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace sb {

LightmapSide lightmap_side(const Mesh& mesh, double texels_per_metre, int max_side) {
  const SurfaceAreas areas = surface_areas(mesh);
  const double world_area = areas.world, uv_area = std::min(areas.uv, 1.0);
  LightmapSide out;
  out.wanted = mesh.has_uv && uv_area > 0 ? texels_per_metre * std::sqrt(world_area / uv_area) : 0;
  const double rounded = std::ceil(out.wanted - 1e-9);
  const int lo = kMinLightmapSide, hi = std::max(kMinLightmapSide, max_side);
  out.side = int(std::clamp(rounded, double(lo), double(hi)));
  out.clamped = mesh.has_uv && uv_area > 0 && (rounded < lo || rounded > hi);
  return out;
}

int largest_lightmap_side(const Scene& scene) {
  if (scene.output.atlas) return scene.output.atlas->size - 2 * scene.output.atlas->padding;
  return scene.bake.texels_per_metre > 0 ? kMaxLightmapSide : scene.bake.resolution;
}

std::vector<int> lightmap_sides(const Scene& scene, const std::vector<Mesh>& meshes,
                                std::vector<std::string>* warnings) {
  const int largest = largest_lightmap_side(scene);
  std::vector<int> sides;
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const ObjectDesc& obj = scene.objects[i];
    if (!obj.receiver) continue;
    const std::string where =
        fmt::format("{}:{}: object '{}': ", scene.file.string(), obj.line, obj.name);
    if (scene.bake.texels_per_metre <= 0) {
      const int side = std::min(scene.bake.resolution, largest);
      if (side < scene.bake.resolution && warnings) {
        warnings->push_back(fmt::format(
            "{}its {}² lightmap does not fit an atlas of {}² with padding {}; it gets {}²", where,
            scene.bake.resolution, scene.output.atlas->size, scene.output.atlas->padding, side));
      }
      sides.push_back(side);
      continue;
    }
    const double density = scene.bake.texels_per_metre * obj.lightmap_scale;
    const LightmapSide s = lightmap_side(meshes[i], density, largest);
    if (s.clamped && warnings) {
      const double got = density * double(s.side) / s.wanted;
      warnings->push_back(fmt::format(
          "{}at {:.4g} texels per metre its lightmap would be {}² texels; it gets {}² ({:.4g} "
          "texels per metre){}",
          where, density, int(std::ceil(s.wanted)), s.side, got,
          s.side == largest ? (scene.output.atlas ? ", the atlas's size less its padding"
                                                  : ", the largest lightmap side")
                            : ", the smallest lightmap side"));
    }
    sides.push_back(s.side);
  }
  return sides;
}

}  // namespace sb
