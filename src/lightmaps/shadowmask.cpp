// Shadow-mask channels and images (shadowmask.h).
#include "lightmaps/shadowmask.h"

#include <fmt/format.h>

#include <cmath>

namespace sb {

void apply_shadowmask_range(Image& light_visibility, const LightDesc& light,
                            const TexelSpace& space) {
  const double range = light.shadowmask_range;
  if (!std::isfinite(range)) return;
  for (const Texel& t : space.texels) {
    if ((t.position.cast<double>() - light.position).norm() <= range) continue;
    float* px = light_visibility.at(t.x, t.y);
    px[0] = 1.0f;
    px[1] = 0.0f;
  }
}

void add_overlaps(const std::vector<Image>& light_visibility,
                  const std::vector<std::uint8_t>& covered, LightOverlaps& overlaps) {
  const std::size_t lights = light_visibility.size();
  std::vector<std::size_t> present;
  for (std::size_t i = 0; i < covered.size(); ++i) {
    if (!covered[i]) continue;
    present.clear();
    for (std::size_t l = 0; l < lights; ++l)
      if (light_visibility[l].pixels[2 * i + 1] > 0) present.push_back(l);
    for (std::size_t a : present)
      for (std::size_t b : present) overlaps.overlaps[a * overlaps.lights + b] = 1;
  }
}

const char* shadowmask_channel_name(int channel) {
  static const char* const names[] = {"R", "G", "B", "A"};
  return channel >= 0 && channel < kShadowmaskChannels ? names[channel] : "none";
}

ShadowmaskChannels assign_shadowmask_channels(const LightOverlaps& overlaps,
                                              const std::vector<LightDesc>& lights,
                                              const std::filesystem::path& scene_file) {
  ShadowmaskChannels out;
  out.channel.assign(overlaps.lights, -1);
  for (std::size_t l = 0; l < overlaps.lights; ++l) {
    bool taken[kShadowmaskChannels] = {};
    std::string holders;
    for (std::size_t k = 0; k < l; ++k) {
      if (out.channel[k] < 0 || !overlaps.meet(l, k)) continue;
      taken[out.channel[k]] = true;
      holders += fmt::format("{}'{}' ({})", holders.empty() ? "" : ", ", lights[k].name,
                             shadowmask_channel_name(out.channel[k]));
    }
    for (int c = 0; c < kShadowmaskChannels && out.channel[l] < 0; ++c)
      if (!taken[c]) out.channel[l] = c;
    if (out.channel[l] >= 0) continue;
    out.warnings.push_back(fmt::format(
        "{}:{}: light '{}': no shadow-mask channel is free where it reaches: it overlaps {}; the "
        "shadow masks leave it out (give it a smaller shadowmask_range, move it before a light "
        "it overlaps, or bake it into the lightmap)",
        scene_file.string(), lights[l].line, lights[l].name, holders));
  }
  return out;
}

Image compose_shadowmask(const std::vector<Image>& light_visibility,
                         const std::vector<int>& channel, int width, int height) {
  Image mask(width, height, kShadowmaskChannels, 1.0f);
  const std::size_t texels = std::size_t(width) * std::size_t(height);
  for (std::size_t l = 0; l < light_visibility.size(); ++l) {
    if (channel[l] < 0) continue;
    const auto& v = light_visibility[l].pixels;
    for (std::size_t i = 0; i < texels; ++i)
      mask.pixels[4 * i + std::size_t(channel[l])] *= v[2 * i];
  }
  return mask;
}

}  // namespace sb
