// The memory a bake will need, estimated before it is allocated and checked against
// `[bake] max_memory`, so that a bake too large for the machine stops at once with a message
// naming the setting instead of dying of std::bad_alloc (or the kernel's OOM killer) after
// minutes. Estimates are upper bounds of the large allocations (texel space, lightmaps, the
// convolution's images); the constants say where they come from.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/memory_size.h"
#include "scene/scene.h"

namespace sb {

double total_bytes(const std::vector<MemoryItem>& items);

// The bake's memory that depends on its settings, not its meshes: texel space of the largest
// receiver at `resolution`² (every texel covered, the upper bound), every receiver's lightmap and
// coverage kept until they are written, the images written, and the method's own per-texel
// arrays and maps.
std::vector<MemoryItem> bake_memory_estimate(const Scene& scene);

// An error when the items need more than `budget` bytes: "<scene file>: [bake] max_memory: the
// bake needs about 21.4 GiB (texel space 16 GiB, ...), more than max_memory = 17.9 GiB; <advice>".
Status check_memory(const Scene& scene, const std::vector<MemoryItem>& items, std::uint64_t budget,
                    const std::string& advice);

// The budget a scene's bake runs under: its max_memory, or the default.
std::uint64_t memory_budget(const BakeSettings& settings);

}  // namespace sb
