// LightLists (light_lists.h): per block of texels the lights whose reach meets it, and per light
// its blocks.
#include "methods/light_lists.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <unsupported/Eigen/BVH>

namespace sb {

namespace {

using Box = Eigen::AlignedBox3d;

// Each block's texels in groups that share a shading normal (at most kGroups a block; the
// rest, and every texel whose face turns its normal across its square, in one group without a
// normal), each group's box of positions: a light may reach the block where it may reach a
// group. A point light lies behind half the faces of a level, and an 8 × 8 block of a packed
// atlas holds pieces of several faces: by its one box alone, most of a light's blocks would be
// listed and reach nothing. A normal is kept only for flat-shaded faces because the terminators'
// fill weighs lights under the other normals of a texel's square (terminator_fill.h).
struct BlockGroups {
  static constexpr int kGroups = 4;
  struct Group {
    Bounds3 box;
    Vec3f normal = Vec3f::Zero();  // zero: texels of several normals
  };
  std::vector<std::array<Group, kGroups + 1>> groups;  // the last: those without a normal
};

BlockGroups block_groups(const TexelSpace& space, int blocks_x, int blocks_y) {
  constexpr int k = LightLists::kSide;
  BlockGroups out;
  out.groups.resize(std::size_t(blocks_x) * std::size_t(blocks_y));
  const auto flat = [&](const Texel& t) {
    if (space.face_shading.empty()) return true;
    const TexelSpace::FaceShading& face = space.face_shading[std::size_t(t.face)];
    return face.normal[0] == face.normal[1] && face.normal[0] == face.normal[2];
  };
  // Texels are row-major: rows of blocks are independent.
  const auto first_of_row = [&](int y) {
    return std::size_t(std::lower_bound(space.texels.begin(), space.texels.end(), y,
                                        [](const Texel& t, int row) { return t.y < row; }) -
                       space.texels.begin());
  };
  tbb::parallel_for(tbb::blocked_range<int>(0, blocks_y), [&](const auto& r) {
    for (std::size_t i = first_of_row(r.begin() * k), end = first_of_row(r.end() * k); i < end;
         ++i) {
      const Texel& t = space.texels[i];
      auto& groups =
          out.groups[std::size_t(t.y / k) * std::size_t(blocks_x) + std::size_t(t.x / k)];
      const Vec3 p = t.position.cast<double>();
      std::size_t g = BlockGroups::kGroups;
      if (flat(t)) {
        for (std::size_t c = 0; c < std::size_t(BlockGroups::kGroups); ++c) {
          if (groups[c].box.empty()) {
            groups[c].normal = t.normal;
            g = c;
            break;
          }
          if (groups[c].normal == t.normal) {
            g = c;
            break;
          }
        }
      }
      groups[g].box.extend(p);
    }
  });
  return out;
}

// The query of one block against the hierarchy of ranged lights (Eigen's BVIntersect protocol):
// the lights whose reach box meets the block's and that may reach one of its groups.
struct BlockQuery {
  const std::vector<Light>& lights;
  const BlockGroups::Group* groups;  // kGroups + 1
  const Box& box;
  std::vector<std::uint32_t>& found;
  bool intersectVolume(const Box& volume) const { return volume.intersects(box); }
  bool intersectObject(int l) const {
    if (may_reach_groups(lights[std::size_t(l)], groups)) found.push_back(std::uint32_t(l));
    return false;  // every light, not the first
  }
  static bool may_reach_groups(const Light& light, const BlockGroups::Group* groups) {
    for (int g = 0; g <= BlockGroups::kGroups; ++g) {
      const BlockGroups::Group& group = groups[g];
      if (group.box.empty()) continue;
      if (group.normal.isZero() ? light.may_reach(group.box)
                                : light.may_reach(group.box, group.normal.cast<double>()))
        return true;
    }
    return false;
  }
};

}  // namespace

LightLists::LightLists(const TexelSpace& space, const std::vector<Light>& lights) {
  blocks_x_ = (space.width + kSide - 1) / kSide;
  const int blocks_y = (space.height + kSide - 1) / kSide;
  const std::size_t count = std::size_t(blocks_x_) * std::size_t(blocks_y);
  const BlockGroups blocks = block_groups(space, blocks_x_, blocks_y);

  // Lights with a range in the hierarchy, by the box of their reach; the rest tried per block.
  std::vector<int> ranged, unbounded;
  std::vector<Box> reach;
  for (std::size_t l = 0; l < lights.size(); ++l) {
    const LightDesc& d = lights[l].desc();
    if (std::isfinite(d.range)) {
      ranged.push_back(int(l));
      reach.emplace_back(d.position - Vec3::Constant(d.range),
                         d.position + Vec3::Constant(d.range));
    } else {
      unbounded.push_back(int(l));
    }
  }
  const Eigen::KdBVH<double, 3, int> tree(ranged.begin(), ranged.end(), reach.begin(), reach.end());

  // Per block, in parallel: its lights, sorted.
  std::vector<std::vector<std::uint32_t>> found(count);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 64), [&](const auto& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      const BlockGroups::Group* groups = blocks.groups[b].data();
      Bounds3 box;
      for (int g = 0; g <= BlockGroups::kGroups; ++g) box.extend(groups[g].box);
      if (box.empty()) continue;
      std::vector<std::uint32_t>& list = found[b];
      if (!ranged.empty()) {
        const Box query(box.lo, box.hi);
        BlockQuery q{lights, groups, query, list};
        Eigen::BVIntersect(tree, q);
      }
      for (int l : unbounded) {
        const Light& light = lights[std::size_t(l)];
        // A sky's parts are listed on every block: the reference traces a sky as a whole at
        // its first part (reference_bake.cpp).
        if (light.sky() || BlockQuery::may_reach_groups(light, groups))
          list.push_back(std::uint32_t(l));
      }
      std::sort(list.begin(), list.end());
    }
  });

  // Flattened per block, then per light (a counting sort keeps each light's blocks ascending).
  block_first_.assign(count + 1, 0);
  for (std::size_t b = 0; b < count; ++b)
    block_first_[b + 1] = block_first_[b] + std::uint32_t(found[b].size());
  block_lights_.resize(block_first_[count]);
  light_first_.assign(lights.size() + 1, 0);
  for (std::size_t b = 0; b < count; ++b) {
    std::copy(found[b].begin(), found[b].end(), block_lights_.begin() + block_first_[b]);
    for (std::uint32_t l : found[b]) ++light_first_[l + 1];
  }
  for (std::size_t l = 0; l < lights.size(); ++l) light_first_[l + 1] += light_first_[l];
  light_blocks_.resize(block_lights_.size());
  std::vector<std::uint32_t> next(light_first_.begin(), light_first_.end() - 1);
  for (std::size_t b = 0; b < count; ++b)
    for (std::uint32_t l : found[b]) light_blocks_[next[l]++] = std::uint32_t(b);
}

std::size_t LightLists::most_per_block() const {
  std::size_t most = 0;
  for (std::size_t b = 0; b + 1 < block_first_.size(); ++b)
    most = std::max<std::size_t>(most, block_first_[b + 1] - block_first_[b]);
  return most;
}

}  // namespace sb
