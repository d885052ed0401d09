// A bake's settings ([bake] and [output], after command-line overrides) as JSON, and back: what
// a shard records so that its merge writes what the whole bake would have, and what the scene's
// content hash covers (pipeline/shards.h).
#pragma once

#include <nlohmann/json.hpp>

#include <string>

#include "core/error.h"
#include "scene/scene.h"

namespace sb {

// Every setting that changes what a bake writes; max_memory, which changes only whether it
// fits, is left out.
nlohmann::ordered_json settings_to_json(const BakeSettings& bake, const OutputSettings& output);

// The settings `json` holds; an error naming `where` and the key when one is missing or wrong.
Status settings_from_json(const nlohmann::ordered_json& json, const std::string& where,
                          BakeSettings& bake, OutputSettings& output);

}  // namespace sb
