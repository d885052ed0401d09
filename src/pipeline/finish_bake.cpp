// The last stage of a bake (bake_stages.h), and of the merge of shards (shards.cpp): what needs
// every receiver.
#include <fmt/format.h>

#include "lightmaps/shadowmask.h"
#include "pipeline/bake_stages.h"
#include "pipeline/receiver_stages.h"

namespace sb {

void finish_bake(const Scene& scene, BakeResult& result, bool whole) {
  std::vector<std::string> warnings = result.setup_warnings;
  for (const ReceiverBake& r : result.receivers)
    warnings.insert(warnings.end(), r.uv_warnings.begin(), r.uv_warnings.end());
  // A light that reaches no receiver texel (facing away, or below every texel's horizon) is
  // most often a normal pointing the wrong way: say so.
  std::int64_t texels = 0;
  for (const ReceiverBake& r : result.receivers) texels += r.covered_texels;
  const bool lit = scene.bake.quantity != Quantity::ambient_occlusion;
  std::vector<const LightDesc*> unreached;
  for (std::size_t l = 0; whole && lit && texels > 0 && l < scene.lights.size(); ++l) {
    bool reached = false;
    for (const ReceiverBake& r : result.receivers)
      reached = reached || (l < r.lights_reached.size() && r.lights_reached[l]);
    if (!reached) unreached.push_back(&scene.lights[l]);
  }
  // One warning each for a few; for many (a level's lights beyond their range of every
  // receiver), one for all, naming the first few; and where none reaches, that the lightmaps
  // are black.
  warn_lights(scene, unreached,
              "reaches no texel of any receiver (is its 'normal' the right way, its 'position' "
              "behind the receivers, or its 'range' short of them?); it adds nothing",
              "lights reach no texel of any receiver (facing away, below every texel's horizon, "
              "or out of range)",
              "they add nothing", warnings);
  if (!unreached.empty() && unreached.size() == scene.lights.size())
    warnings.push_back(fmt::format(
        "{}: none of the scene's {} light(s) reaches any receiver; every lightmap is black",
        scene.file.string(), scene.lights.size()));
  for (const ReceiverBake& r : result.receivers)
    warnings.insert(warnings.end(), r.report.warnings.begin(), r.report.warnings.end());
  result.shadowmask_channels.clear();
  if (whole && scene.output.shadowmask) {
    LightOverlaps overlaps(scene.lights.size());
    for (const ReceiverBake& r : result.receivers)
      add_overlaps(r.per_light_visibility, r.covered, overlaps);
    ShadowmaskChannels channels = assign_shadowmask_channels(overlaps, scene.lights, scene.file);
    result.shadowmask_channels = std::move(channels.channel);
    // A level's thousand lights leave most without a channel: the first few by name, then a
    // count.
    constexpr std::size_t kNamed = 5;
    for (std::size_t i = 0; i < channels.warnings.size() && i < kNamed; ++i)
      warnings.push_back(std::move(channels.warnings[i]));
    if (channels.warnings.size() > kNamed)
      warnings.push_back(fmt::format(
          "{}: {} more lights have no free shadow-mask channel where they reach; the shadow "
          "masks leave them out (a mask holds four lights per texel)",
          scene.file.string(), channels.warnings.size() - kNamed));
  }
  result.warnings = std::move(warnings);
}

}  // namespace sb
