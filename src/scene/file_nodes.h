// A mesh file's node hierarchy in world space: each node's world transform (in double precision,
// the file's unit scale applied), and the parts of the file an object places. A whole file is one
// object when a scene's [[object]] names it; a level (level_file.h) makes one object per node.
#pragma once

#include <cstdint>
#include <vector>

#include "core/geometry.h"
#include "scene/mesh_reader.h"

namespace sb {

// A part of a mesh file placed in the world: the transform takes the part's own coordinates to
// world space.
struct PartInstance {
  std::uint32_t part = 0;
  Affine3 transform = Affine3::Identity();
};

// Every node's transform from its coordinates to the file's world, metres: the product of its
// ancestors' transforms and its own, the root's scaled by the file's unit scale where it has one
// (FBX). Computed in double from the file's float matrices.
std::vector<Affine3> node_world_transforms(const RawMeshFile& file);

// The parts an object places, in node order, each with placement × its node's world transform:
// every node's parts when `node` < 0 (the whole file as one object), else the node's own parts
// (not its children's), or only those listed in `parts` when it is not empty.
std::vector<PartInstance> part_instances(const RawMeshFile& file, const std::vector<Affine3>& world,
                                         int node, const std::vector<std::uint32_t>& parts,
                                         const Affine3& placement);

}  // namespace sb
