// A whole bake, as a list of stages (bake.cpp): check the request, load the scene (meshes,
// lightmap sizes, lights, what the method needs built), take unchanged receivers from the
// cache, build texel space per receiver, run the method on each (then dilation and seams), and
// finish what needs every receiver. The CLI writes the result with write_outputs (outputs.h).
#pragma once

#include <string>
#include <vector>

#include "core/error.h"
#include "pipeline/bake_types.h"
#include "scene/scene.h"

namespace sb {

// Bakes scene.bake.method for every receiver (or a shard's). Errors name the scene file and the
// item.
Expected<BakeResult> bake(const Scene& scene, const BakeOptions& options = {});

// The scene's method's plan for every receiver (MethodEntry::plan's text, in scene order),
// without baking: what `shadowbake plan` prints.
Expected<std::vector<std::string>> plan(const Scene& scene, const BakeOptions& options = {});

}  // namespace sb
