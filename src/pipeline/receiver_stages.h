// The stages of a bake around the method, shared by the bake (bake.cpp) and the join of a
// receiver's tiles (tiles.cpp): the scene's meshes and lights as a bake reads them, a receiver's
// UV layout warnings and the lights that reach it, and what follows the method (shadow-mask
// ranges, dilation into the margin, UV seams).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/error.h"
#include "pipeline/bake_types.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "scene/scene.h"
#include "texels/texel_space.h"
#include "texels/uv_checks.h"

namespace sb {

// Every object's mesh, in scene order; skipped degenerate triangles become warnings (when
// `warnings` is given). A receiver with uv = "auto" gets its lightmap UVs here.
Expected<std::vector<Mesh>> load_meshes(const Scene& scene, std::vector<std::string>* warnings);

// Whether the scene's world is Y up, glTF's frame: a level's world is its file's
// (docs/scene-format.md), so a scene with an object of a level (ObjectDesc::node ≥ 0) is; a scene
// file's own world is Z up.
bool world_is_y_up(const Scene& scene);

// The blockers' meshes, in scene order.
std::vector<const Mesh*> blocker_meshes(const Scene& scene, const std::vector<Mesh>& meshes);

// The scene's lights with every sun and sky placed for the meshes' bounds (sun_light.h, sky.h).
std::vector<LightDesc> placed_lights(const Scene& scene, const std::vector<Mesh>& meshes);

// Per scene light: 1 where it (or a part of a mesh light) reaches a texel of `space`.
std::vector<std::uint8_t> lights_reaching(const Scene& scene, const TexelSpace& space,
                                          const std::vector<Light>& lights);

// A receiver's UV layout warnings, each naming it in the scene file; an error where its UVs
// cover no texel and the scene does not allow it (allow_uncovered).
Expected<std::vector<std::string>> layout_warnings(const Scene& scene, const ObjectDesc& obj,
                                                   const UvLayoutReport& layout,
                                                   std::int64_t covered, int side);

// What follows the method, on out's images as the method left them (the covered texels' values):
// each light's shadow-mask range, dilation into the margin, the UV seams stitched; then out's
// coverage, texel count and, with [output] gltf, its glTF mesh. Times out.seconds_dilate and
// out.seconds_seams.
void finish_receiver(const Scene& scene, const Mesh& mesh, const TexelSpace& space,
                     const std::vector<Light>& lights, ReceiverBake& out);

}  // namespace sb
