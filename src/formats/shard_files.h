// A shard's receivers on disk (shards.h): per receiver (or tile of one, pipeline/tiles.h) its
// metadata as JSON (in shard.json) and its arrays in one binary file, receiver_<object>.bin (a
// tile's: receiver_<object>_rows_<first row>.bin): a header (magic "SBSR", version, sizes) then
// the image (float RGB; a tile's rows alone), the coverage (bytes, padded to 4), the per-light
// images and visibility (float), and the glTF mesh's arrays, in this machine's byte order (a shard
// and its merge run on one cluster). Reading checks every size against the header and the file.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "core/error.h"
#include "pipeline/bake_types.h"

namespace sb {

// The name of receiver (object index) `object`'s binary file, or of its tile's.
std::string receiver_data_file(std::size_t object, std::optional<RowRange> tile = std::nullopt);

// The receiver's metadata: everything but its arrays and timings.
nlohmann::ordered_json receiver_metadata(const ReceiverBake& r);

// The binary file's bytes.
std::string receiver_data(const ReceiverBake& r);

// A binary file's checksum (XXH3-64, 16 hex digits), kept in shard.json: a merge refuses data
// damaged in any byte.
std::string data_checksum(const std::string& bytes);

// The receiver `metadata` and the binary file at `data` describe, the file's checksum being
// metadata's "checksum"; errors name `where`.
Expected<ReceiverBake> read_receiver(const nlohmann::ordered_json& metadata,
                                     const std::filesystem::path& data, const std::string& where);

// A glTF mesh's arrays as a binary file, and back (the blockers' meshes, written by shard 0).
std::string gltf_mesh_data(const GltfMesh& mesh);
Expected<GltfMesh> read_gltf_mesh(const std::filesystem::path& data, const std::string& checksum);

}  // namespace sb
