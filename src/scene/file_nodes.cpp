#include "scene/file_nodes.h"

#include <algorithm>

namespace sb {

std::vector<Affine3> node_world_transforms(const RawMeshFile& file) {
  std::vector<Affine3> world(file.nodes.size(), Affine3::Identity());
  for (std::size_t i = 0; i < file.nodes.size(); ++i) {
    const RawNode& node = file.nodes[i];
    Affine3 local = Affine3::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c)
        local.matrix()(r, c) = double(node.transform[std::size_t(4 * r + c)]);
    if (node.parent >= 0) {
      world[i] = world[std::size_t(node.parent)] * local;  // the reader gives parents first
    } else if (file.unit_scale > 0 && file.unit_scale != 1) {
      world[i] = Eigen::Scaling(file.unit_scale) * local;
    } else {
      world[i] = local;
    }
  }
  return world;
}

std::vector<PartInstance> part_instances(const RawMeshFile& file, const std::vector<Affine3>& world,
                                         int node, const std::vector<std::uint32_t>& parts,
                                         const Affine3& placement) {
  std::vector<PartInstance> instances;
  const auto add_node = [&](std::size_t n) {
    for (std::uint32_t part : file.nodes[n].parts) {
      if (!parts.empty() && std::find(parts.begin(), parts.end(), part) == parts.end()) continue;
      instances.push_back({part, placement * world[n]});
    }
  };
  if (node < 0) {
    for (std::size_t n = 0; n < file.nodes.size(); ++n) add_node(n);
  } else if (std::size_t(node) < file.nodes.size()) {
    add_node(std::size_t(node));
  }
  return instances;
}

}  // namespace sb
