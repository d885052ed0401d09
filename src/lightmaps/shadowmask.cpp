// Shadow-mask channels and images (shadowmask.h).
#include "lightmaps/shadowmask.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

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

void add_overlaps(const TiledImages& light_visibility, const std::vector<std::uint8_t>& covered,
                  LightOverlaps& overlaps) {
  // The lights holding each tile (beyond its tiles a light has no influence), tile by tile.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> holders;  // (tile, light)
  for (std::size_t l = 0; l < light_visibility.size(); ++l)
    for (std::size_t s = 0; s < light_visibility.tiles(l).size(); ++s)
      holders.emplace_back(light_visibility.tiles(l)[s], std::uint32_t(l));
  std::sort(holders.begin(), holders.end());
  constexpr int side = TiledImages::kSide;
  const int width = light_visibility.width(), height = light_visibility.height();
  std::vector<std::size_t> present;
  for (std::size_t first = 0; first < holders.size();) {
    std::size_t last = first;
    while (last < holders.size() && holders[last].first == holders[first].first) ++last;
    const std::uint32_t tile = holders[first].first;
    const int x0 = int(tile % std::uint32_t(light_visibility.tiles_x())) * side;
    const int y0 = int(tile / std::uint32_t(light_visibility.tiles_x())) * side;
    for (int y = y0; y < std::min(y0 + side, height); ++y)
      for (int x = x0; x < std::min(x0 + side, width); ++x) {
        if (!covered[std::size_t(y) * std::size_t(width) + std::size_t(x)]) continue;
        present.clear();
        for (std::size_t k = first; k < last; ++k)
          if (light_visibility.at(holders[k].second, x, y)[1] > 0)
            present.push_back(holders[k].second);
        for (std::size_t a : present)
          for (std::size_t b : present) overlaps.overlaps[a * overlaps.lights + b] = 1;
      }
    first = last;
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

Image compose_shadowmask(const TiledImages& light_visibility, const std::vector<int>& channel,
                         int width, int height) {
  Image mask(width, height, kShadowmaskChannels, 1.0f);
  // Beyond a light's tiles its visibility is 1: only its tiles change the mask.
  for (std::size_t l = 0; l < light_visibility.size(); ++l) {
    if (channel[l] < 0) continue;
    light_visibility.each_pixel(l, [&](int x, int y, const float* v) {
      if (x < width && y < height) mask.at(x, y)[channel[l]] *= v[0];
    });
  }
  return mask;
}

}  // namespace sb
