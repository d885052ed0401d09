// The stages of a bake around the method, shared by the bake (bake.cpp) and the join of a
// receiver's tiles (tiles.cpp): the scene's meshes and lights as a bake reads them, a receiver's
// UV layout warnings and the lights that reach it, and what follows the method (shadow-mask
// ranges, dilation into the margin, UV seams).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "methods/light_lists.h"
#include "occluders/ray_scene.h"
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

// The scene's lights with every sun and sky placed for the meshes' bounds (sun_light.h, sky.h),
// and, under [bake] irradiance_floor, a range for each light that has none (range_for_floor).
std::vector<LightDesc> placed_lights(const Scene& scene, const std::vector<Mesh>& meshes);

// Warnings about `lights` that share a problem: for at most five, one each, "<file>:<line>:
// light '<name>': <each>"; for more (a level's thousand), one for all, "<file>: <count> <many>,
// '<first>', ... and <rest> more; <then>", naming the first five.
void warn_lights(const Scene& scene, const std::vector<const LightDesc*>& lights,
                 std::string_view each, std::string_view many, std::string_view then,
                 std::vector<std::string>& warnings);

// Lights whose centre lies inside solid geometry (RayScene::inside_solid: a level's light inside a
// wall) reach nothing: their range becomes 0 (every method skips them, and they add nothing), and
// a warning names them (the first few by name where they are many). Points, spots, spheres,
// rectangles and disks; suns, skies and mesh lights are not tested. `rays`: the blockers' ray
// scene where the bake built one, else one is built here.
Status cut_enclosed_lights(const Scene& scene, const std::vector<const Mesh*>& blockers,
                           const RayScene* rays, std::vector<LightDesc>& lights,
                           std::vector<std::string>& warnings);

// Per scene light: 1 where it (or a part of a mesh light) reaches a texel of `space`, whose
// blocks' lights are `lists`.
std::vector<std::uint8_t> lights_reaching(const Scene& scene, const TexelSpace& space,
                                          const std::vector<Light>& lights,
                                          const LightLists& lists);

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
                     const std::vector<Light>& lights, const LightLists& lists, ReceiverBake& out);

}  // namespace sb
