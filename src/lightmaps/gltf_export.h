// A bake as a glTF 2.0 binary (.glb) an engine or a web viewer loads as it is: every receiver's
// mesh with its lightmap UVs as TEXCOORD_1 and its lightmap bound through MOZ_lightmap (the
// material extension three.js-based viewers read: {index, texCoord, intensity}), with
// KHR_texture_transform on it for a receiver's rectangle in an atlas. glTF has no KHR extension
// for lightmaps; MOZ_lightmap is what the loaders that exist read (Mozilla Hubs, Spoke,
// Third Room). Written by hand on nlohmann-json because the format is a JSON chunk and a binary
// chunk, and no Debian library writes glTF (Assimp's exporter drops the second UV set's role
// and knows no MOZ_lightmap).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/mesh.h"

namespace sb {

// A receiver's mesh as glTF stores it: world space in glTF's frame (Y up: a scene file's Z-up
// (x, y, z) is glTF (x, z, −y); a level's world is Y up already), UVs with v down (glTF's
// convention: 1 − v of the OBJ/Blender one).
struct GltfMesh {
  std::vector<float> positions;  // x, y, z per vertex
  std::vector<float> normals;    // unit, per vertex
  std::vector<float> texcoord0;  // the texture UVs (Mesh::texture_uv), or the lightmap UVs
  std::vector<float> texcoord1;  // the lightmap UVs; both empty for a mesh without UVs
  std::vector<std::uint32_t> indices;
};
// `with_uvs` false (a blocker's mesh): positions, normals and triangles only. `world_y_up`: the
// scene's world is glTF's own frame (a level's, world_is_y_up in pipeline/receiver_stages.h),
// taken as it is; else it is a scene file's Z up, turned to Y up.
GltfMesh gltf_mesh(const Mesh& mesh, bool with_uvs = true, bool world_y_up = false);

// One lightmap texture: PNG bytes (8-bit, linear values over its intensity).
struct GltfTexture {
  std::string name;
  std::vector<std::uint8_t> png;
};

// A receiver's lightmap: which texture, and where in it.
struct GltfLightmap {
  int texture = 0;       // index into the textures
  double intensity = 1;  // MOZ_lightmap intensity: the value a texel of 1.0 stands for
  // KHR_texture_transform of the lightmap (glTF's v-down UVs): {scale_u, scale_v, offset_u,
  // offset_v}; none for a receiver with a texture of its own.
  std::optional<std::array<double, 4>> transform;
};

// An object of the scene: a receiver with its lightmap, or a blocker without (it casts the
// shadows the lightmaps show, so a viewer shows it too).
struct GltfObject {
  std::string name;
  const GltfMesh* mesh = nullptr;
  std::optional<GltfLightmap> lightmap;
};

// The .glb file's bytes: a node, mesh and material per object (white, rough, not metallic), the
// textures embedded, a clamp-to-edge linear sampler (no mip-maps, whose lower levels would mix an
// atlas's neighbours). `quantity` ("visibility" or "irradiance") and `generator` go into the
// asset's extras and generator.
Expected<std::vector<std::uint8_t>> glb_bytes(const std::vector<GltfObject>& objects,
                                              const std::vector<GltfTexture>& textures,
                                              const std::string& quantity,
                                              const std::string& generator);

}  // namespace sb
