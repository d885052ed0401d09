// The fourth stage of a bake (bake_stages.h): texel space per receiver, its UV layout's checks
// and the lights that reach it; a tile's rows with the halo its method needs; nothing for a
// receiver the cache gives.
#include "core/stopwatch.h"
#include "pipeline/bake_stages.h"
#include "pipeline/receiver_stages.h"
#include "pipeline/tiles.h"

namespace sb {

Expected<Texels> build_texels(const Scene& scene, const MethodEntry& method,
                              const LoadedScene& loaded, const Reuse& reuse) {
  const std::size_t n = loaded.receivers.size();
  Texels out;
  out.warnings.resize(n);
  out.reached.resize(n);
  out.lists.resize(n);
  for (std::size_t r = 0; r < n; ++r) {
    const std::size_t i = loaded.receivers[r];
    const Mesh& mesh = loaded.meshes[i];
    const auto start = std::chrono::steady_clock::now();
    const int side = loaded.sides[r];
    std::int64_t covered = 0;
    if (reuse.reused[r]) {  // taken from the cache: nothing to rasterise, its layout as it was
      out.spaces.emplace_back();
      out.seconds.push_back(0);
      out.layouts.push_back(reuse.reused[r]->uv_layout);
      out.reached[r] = reuse.reused[r]->lights_reached;
      covered = reuse.reused[r]->covered_texels;
    } else if (loaded.tiles[r]) {  // its rows and the method's halo; the rest at the join
      out.spaces.push_back(rasterise_texels(mesh, side, side,
                                            tile_window(*loaded.tiles[r], method.tile_halo, side)));
      out.spaces.back().kept = *loaded.tiles[r];
      out.lists[r].emplace(out.spaces.back(), loaded.lights);
      out.seconds.push_back(seconds_since(start));
      out.layouts.emplace_back();
      out.total += std::int64_t(out.spaces.back().texels.size());
      continue;
    } else {
      out.spaces.push_back(rasterise_texels(mesh, side, side));
      out.lists[r].emplace(out.spaces.back(), loaded.lights);
      out.seconds.push_back(seconds_since(start));
      covered = std::int64_t(out.spaces.back().texels.size());
      out.layouts.push_back(check_uv_layout(mesh, out.spaces.back(), scene.bake.margin));
      // Which lights reach any of its texels (for the warning about lights that reach nothing).
      out.reached[r] = lights_reaching(scene, out.spaces.back(), loaded.lights, *out.lists[r]);
    }
    out.total += covered;
    auto warnings = layout_warnings(scene, scene.objects[i], out.layouts.back(), covered, side);
    if (!warnings) return warnings.error();
    out.warnings[r] = std::move(*warnings);
  }
  return out;
}

}  // namespace sb
