// Checks of a mesh file's own structure before Assimp reads it. Assimp 5.2's readers trust what a
// file declares: a PLY header claiming two billion vertices makes it allocate tens of gigabytes
// for a 4 KB file, and its OBJ reader turns an unreadable number ("nan", "1.#INF") into 0 and a
// face's out-of-range UV index into a mesh without UVs. These checks refuse such files with a
// message that says where and what, and cost one pass over the bytes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "core/error.h"

namespace sb {

// A regular file of at most max_bytes; for .obj and .ply (by extension, any case) also the
// checks above. The error is the problem alone, e.g. "line 12: face references UV index 5, but
// the file has 2 'vt' lines"; the caller names the scene file and the object.
Status check_mesh_file(const std::filesystem::path& file, std::uint64_t max_bytes);

// The checks on a file's bytes, by format; exposed for tests and the fuzzer.
Status check_obj_text(std::string_view text);
Status check_ply_bytes(std::string_view bytes, std::uint64_t file_bytes);

}  // namespace sb
