// Shadow-mask channels and images (shadowmask.h).
#include "lightmaps/shadowmask.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
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
  // Where each light has influence (covered pixels with influence > 0), as a mask of its tile's
  // pixels, read one light at a time (its values may be in a scratch file); beyond its tiles a
  // light has none. Two lights meet where their masks of one tile share a pixel.
  struct Held {
    std::uint32_t tile, light;
    std::uint64_t pixels;
    bool operator<(const Held& o) const { return tile != o.tile ? tile < o.tile : light < o.light; }
  };
  constexpr int side = TiledImages::kSide;
  static_assert(side * side == 64, "a tile's pixels are the bits of one 64-bit mask");
  const std::size_t width = std::size_t(light_visibility.width());
  std::vector<Held> held;
  for (std::size_t l = 0; l < light_visibility.size(); ++l) {
    const std::span<const std::uint32_t> tiles = light_visibility.tiles(l);
    const std::size_t first = held.size();
    for (const std::uint32_t tile : tiles) held.push_back({tile, std::uint32_t(l), 0});
    light_visibility.each_pixel(l, [&](int x, int y, const float* v) {
      if (!covered[std::size_t(y) * width + std::size_t(x)] || !(v[1] > 0)) return;
      const std::uint32_t tile =
          std::uint32_t(y / side) * std::uint32_t(light_visibility.tiles_x()) +
          std::uint32_t(x / side);
      const std::size_t s =
          std::size_t(std::lower_bound(tiles.begin(), tiles.end(), tile) - tiles.begin());
      held[first + s].pixels |= std::uint64_t(1) << ((y % side) * side + x % side);
    });
  }
  std::sort(held.begin(), held.end());
  for (std::size_t first = 0; first < held.size();) {
    std::size_t last = first;
    while (last < held.size() && held[last].tile == held[first].tile) ++last;
    for (std::size_t a = first; a < last; ++a)
      for (std::size_t b = first; b < last; ++b)
        if (held[a].pixels & held[b].pixels)
          overlaps.overlaps[std::size_t(held[a].light) * overlaps.lights + held[b].light] = 1;
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
