// A level: one mesh file (glTF, FBX, OBJ, anything Assimp reads) holding a whole scene, its
// objects as nodes and its lights. `shadowbake bake level.glb` bakes one alone
// (load_level_scene); a scene file brings one in with [[import]] (scene_file_imports.cpp) and
// overrides what it needs by name.
//
// What a file's contents become (docs/scene-format.md, "Levels"):
// - every node that places a mesh is an object, named by its node (file-name-safe: other
//   characters become '_'); where two such nodes share a name, the names of their parents are put
//   in front ("Shelf-Book"), and a name still repeated gets "-2", "-3", ... with a warning;
// - each object is a receiver and a blocker, with its world transform (the file's node
//   hierarchy, FBX's unit scale, then the import's placement), lightmap UVs from the second UV
//   set where every part of it has one, else the first;
// - a mesh part whose material emits (glTF emissiveFactor × KHR_materials_emissive_strength) is
//   a light, not a surface: a planar rectangle or a planar disc becomes a rectangle or disk light
//   emitting from its front side, any other emissive mesh a mesh light of its triangles (front
//   sides, at most kMaxMeshLightTriangles of them), of radiant exitance π × the emission (the
//   emission read as radiance, W/(m²·sr), as Blender's Emission shader and its glTF exporter
//   take it);
// - point and spot lights (glTF's KHR_lights_punctual, FBX's lights) become point lights (scene.h,
//   kPointLightRadius) of power 4π × intensity / 683 for glTF (candela to watts, as Blender's
//   exporter and importer convert) and the intensity as watts otherwise (as Blender's FBX
//   exporter writes the light's power); a spot keeps its cone (LightDesc::spot_axis), which
//   scales its irradiance;
// - directional lights become suns (sun_light.h) of Blender's 0.526° and the light's irradiance
//   (lux / 683 for glTF, W/m² otherwise);
// - area and ambient lights are not read: each is a warning naming it, as is an emissive mesh of
//   no area or of too many triangles.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/geometry.h"
#include "scene/mesh.h"
#include "scene/scene.h"

namespace sb {

// The most triangles an emissive mesh may have to be a mesh light: every method bakes each as a
// light of its own, so the bake's time grows with their number (docs/methods.md, mesh lights).
inline constexpr std::size_t kMaxMeshLightTriangles = 1024;

struct LevelContents {
  std::vector<ObjectDesc> objects;
  std::vector<LightDesc> lights;
  std::vector<std::string> warnings;  // one line each, naming the file and the node
};

// Reads `file` and makes its objects and lights, each placed by `placement` after the file's
// own transforms; `line` is given to each (the [[import]] table's line, 0 for a level baked
// alone). Errors name the file, the node and the problem.
Expected<LevelContents> import_level(const std::filesystem::path& file, const Affine3& placement,
                                     int line, const ImportLimits& limits = {});

// Whether `file` is baked as a level rather than read as a scene file: any extension but .toml.
bool is_level_file(const std::filesystem::path& file);

// A scene of one level file alone: the default [bake] and [output] settings, the file's objects
// and lights. Errors as load_scene's.
Expected<Scene> load_level_scene(const std::filesystem::path& file, bool need_lights = true);

}  // namespace sb
