// Which lights may reach which blocks of a receiver's texels: tiled light culling (Olsson,
// Billeter & Assarsson, "Clustered deferred and forward shading", HPG 2012), with the blocks of
// texels (TexelBlock, 8 × 8 pixels) as the tiles and each light's reach (Light::may_reach: its
// range, the side a flat light faces, a spot's cone) as its bound. A light a block's list leaves
// out reaches none of its texels (Light::reaches is false at each), so a method that visits a
// texel's lights, or a light's texels, through these lists spends nothing on the pairs beyond
// the lights' reach, and its values are those of a visit of every pair.
//
// In a level whose lights each light their own room, a texel sees a small share of them
// (OpenArena's oacmpctf3: at most 197 of 1,916 reach one texel); a light without a range (and
// every sun and sky) is on every block it faces.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "scene/lights.h"
#include "texels/texel_space.h"

namespace sb {

class LightLists {
 public:
  static constexpr int kSide = TexelBlock::kSide;

  // The lists of `space`'s blocks (its TexelBlock summaries, or its texels' boxes where it has
  // none) for `lights`. Lights with a range are found through a bounding volume hierarchy of
  // their reach (Eigen's KdBVH), so the cost grows with the pairs found, not blocks × lights.
  LightLists(const TexelSpace& space, const std::vector<Light>& lights);

  int blocks_x() const { return blocks_x_; }
  std::size_t block_count() const { return block_first_.size() - 1; }
  std::size_t light_count() const { return light_first_.size() - 1; }
  std::size_t block_of(int x, int y) const {
    return std::size_t(y / kSide) * std::size_t(blocks_x_) + std::size_t(x / kSide);
  }
  // The lights that may reach block b, ascending (scene order).
  std::span<const std::uint32_t> lights_of(std::size_t block) const {
    return {block_lights_.data() + block_first_[block],
            block_lights_.data() + block_first_[block + 1]};
  }
  // The blocks light l may reach, ascending (row-major).
  std::span<const std::uint32_t> blocks_of(std::size_t light) const {
    return {light_blocks_.data() + light_first_[light],
            light_blocks_.data() + light_first_[light + 1]};
  }
  // (light, block) pairs listed.
  std::size_t pairs() const { return block_lights_.size(); }
  // The most lights any one block lists.
  std::size_t most_per_block() const;

 private:
  int blocks_x_ = 0;
  std::vector<std::uint32_t> block_first_, block_lights_;  // per block, its lights
  std::vector<std::uint32_t> light_first_, light_blocks_;  // per light, its blocks
};

}  // namespace sb
