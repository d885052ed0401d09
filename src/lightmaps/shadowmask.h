// Shadow masks as Unity's Shadowmask mode and Unreal's stationary lights store them: each light's
// visibility in one channel (R, G, B or A) of an 8-bit texture with the lightmap's UV layout, at
// most four lights per texel. Lights whose influence overlaps (some receiver texel that both
// reach, within their shadowmask_range) need different channels; lights that never meet may
// share one. Channels are given in scene order, each light the first channel none of the lights
// before it that it overlaps holds (greedy colouring: the same scene gives the same channels on
// every run and in every shard); a light finding all four taken gets none and a warning names
// it. The engine multiplies a channel into the light it computes itself.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/tiled_images.h"
#include "scene/lights.h"
#include "texels/texel_space.h"

namespace sb {

inline constexpr int kShadowmaskChannels = 4;

// Per receiver and light, what the mask needs: channel 0 the light's visibility where it
// influences the texel (its H0-weighted mean over colour channels) and 1 elsewhere, channel 1
// 1 where it influences the texel and 0 elsewhere. These images are the methods' per-light
// visibility (LightMix, keep_visibility) after apply_shadowmask_range.

// Clears the influence of `light` at the covered texels of `space` farther than its
// shadowmask_range from its centre (there the mask holds 1 for it).
void apply_shadowmask_range(Image& light_visibility, const LightDesc& light,
                            const TexelSpace& space);

// Which lights' influences meet: overlaps[a·L + b] for lights a, b of L.
struct LightOverlaps {
  std::size_t lights = 0;
  std::vector<std::uint8_t> overlaps;  // L × L, symmetric
  explicit LightOverlaps(std::size_t count = 0)
      : lights(count), overlaps(count * count, std::uint8_t(0)) {}
  bool meet(std::size_t a, std::size_t b) const { return overlaps[a * lights + b] != 0; }
};

// Adds the overlaps one receiver's images show at its covered texels.
void add_overlaps(const TiledImages& light_visibility, const std::vector<std::uint8_t>& covered,
                  LightOverlaps& overlaps);

struct ShadowmaskChannels {
  std::vector<int> channel;           // per light: 0–3 (R, G, B, A), or −1: left out
  std::vector<std::string> warnings;  // one per light left out, naming it and those it overlaps
};

// The greedy assignment above. `lights` and `scene_file` give the warnings' names and lines.
ShadowmaskChannels assign_shadowmask_channels(const LightOverlaps& overlaps,
                                              const std::vector<LightDesc>& lights,
                                              const std::filesystem::path& scene_file);

// A receiver's RGBA mask: channel c is the product, over the lights given channel c, of their
// visibility images' channel 0 (at most one of them influences any texel); 1 where no light
// holds the channel.
Image compose_shadowmask(const TiledImages& light_visibility, const std::vector<int>& channel,
                         int width, int height);

// "R", "G", "B", "A".
const char* shadowmask_channel_name(int channel);

}  // namespace sb
