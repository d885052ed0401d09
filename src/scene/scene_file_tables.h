// The readers of a scene file's tables (scene_file_bake.cpp, scene_file_objects.cpp,
// scene_file_lights.cpp), each checking every key against docs/scene-format.md; load_scene
// (scene_file.cpp) calls them.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string_view>

#include <toml++/toml.h>

#include "core/error.h"
#include "scene/scene.h"

namespace sb {

// An object's lightmap UVs as TableReader::uv_set read them: a channel, or generated.
void set_uv(ObjectDesc& obj, int uv_set);

// The [bake] table.
Expected<BakeSettings> read_bake(const std::filesystem::path& file, const toml::table& table,
                                 const MethodVocabulary& methods);

// The [output] table.
Expected<OutputSettings> read_output(const std::filesystem::path& file, const toml::table& table);

// The [[object]] table at `index` (from 0) among the file's objects.
Expected<ObjectDesc> read_object(const std::filesystem::path& file, const toml::table& table,
                                 std::size_t index);

// The [[light]] table at `index` (from 0) among the file's lights.
Expected<LightDesc> read_light(const std::filesystem::path& file, const toml::table& table,
                               std::size_t index);

// Each Preetham sky's sun (LightDesc::sky_sun_direction): the sun light it names, else the
// direction it gives, else the scene's one sun light; an error (at the sky's line) where it names
// no sun light, where it names none and the scene has not exactly one, or where its sun lies
// below its horizon. After the imports, whose lights a sky may name.
Status resolve_sky_suns(const std::filesystem::path& file, std::vector<LightDesc>& lights);

// The [[import]] table at `index` (from 0): its level file's objects and lights, placed and
// overridden as the table says.
struct LevelContents;
Expected<LevelContents> read_import(const std::filesystem::path& file, const toml::table& table,
                                    std::size_t index);

}  // namespace sb
