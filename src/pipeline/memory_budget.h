// The memory a bake will need, estimated before it is allocated and checked against
// `[bake] max_memory`, so that a bake too large for the machine stops at once with a message
// naming the setting instead of dying of std::bad_alloc (or the kernel's OOM killer) after
// minutes. Estimates are upper bounds of the large allocations (texel space, lightmaps, the
// convolution's images); the constants say where they come from.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/memory_size.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "scene/scene.h"

namespace sb {

double total_bytes(const std::vector<MemoryItem>& items);

// The receivers' lightmap sides, in scene order, where the settings alone give them: every one
// `resolution` (clamped to an atlas); empty with texels_per_metre, where they follow from the
// meshes (texels/lightmap_sizes.h).
std::vector<int> sides_from_settings(const Scene& scene);

// The bake's memory for receivers of these `sides`: texel space of the largest receiver (every
// texel covered, the upper bound), every receiver's lightmap and coverage kept until they are
// written, the images written (an atlas at a time with an atlas), and the method's own
// per-texel arrays and maps.
std::vector<MemoryItem> bake_memory_estimate(const Scene& scene, const std::vector<int>& sides);

// The per-light images ([output] per_light, shadowmask) of receivers with these meshes and
// sides, once the meshes and lights are known: per_light's values, a few whole images in
// flight (the rest wait in a scratch file, TiledImages); shadowmask's, each light's share of
// each receiver's surface its reach may touch (by pieces of 64 faces), times the texels, as if
// they stayed in memory (they spill as well: an estimate from above). None where no per-light
// image is kept.
std::optional<MemoryItem> per_light_memory(const Scene& scene,
                                           const std::vector<const Mesh*>& receivers,
                                           const std::vector<int>& sides,
                                           const std::vector<Light>& lights);

// An error when the items need more than `budget` bytes: "<scene file>: [bake] max_memory: the
// bake needs about 21.4 GiB (texel space 16 GiB, ...), more than max_memory = 17.9 GiB; <advice>".
Status check_memory(const Scene& scene, const std::vector<MemoryItem>& items, std::uint64_t budget,
                    const std::string& advice);

// The budget a scene's bake runs under: its max_memory, or the default.
std::uint64_t memory_budget(const BakeSettings& settings);

}  // namespace sb
