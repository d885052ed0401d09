// Reading a mesh file with Assimp, isolated in a child process. Assimp 5.2 (Debian) crashes,
// hangs or exhausts memory on some broken files (the fuzzer finds such files in minutes, in its
// PLY, glTF and FBX readers); a lightmap baker must refuse them with a message, not die with
// them. So the file is read in a helper process (shadowbake_mesh_reader, beside the program or
// named by $SHADOWBAKE_MESH_READER) under a memory limit and a time limit, and comes back as
// plain arrays; a helper that crashes, runs out of time or memory is an error naming what
// happened.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"

namespace sb {

inline constexpr int kMaxUvChannels = 8;  // Assimp's AI_MAX_NUMBER_OF_TEXTURECOORDS

// The helper's answer, in this machine's byte order: this magic; a status (u32: 0 read, 1
// failed); the error (u64 length, bytes); Assimp's messages (u64 count, each a string); the parts
// (u64 count; each: positions, normals, kMaxUvChannels UV arrays, triangles, each array a u64
// count and its elements).
inline constexpr std::uint32_t kMeshReaderMagic = 0x524d4253;  // "SBMR"

// One of the file's meshes after Assimp's triangulation and pre-transformation: per vertex 3
// floats of position, and of normal and of each UV channel where present (empty otherwise); the
// triangles as vertex indices, each checked to be in range. Points and lines are left out.
struct RawMeshPart {
  std::vector<float> positions, normals;
  std::array<std::vector<float>, kMaxUvChannels> uvs;
  std::vector<std::uint32_t> triangles;
  std::size_t vertex_count() const { return positions.size() / 3; }
  int uv_channel_count() const;  // channels present from 0 on
};

struct RawMeshFile {
  std::vector<RawMeshPart> parts;
  std::vector<std::string> warnings;  // Assimp's warnings and errors while it read the file
};

struct MeshReadLimits {
  std::uint64_t max_memory = std::uint64_t(4) << 30;  // bytes the reader may allocate
  double max_seconds = 120;                           // wall-clock time it may take
};

// Reads `file` with Assimp (triangulate, pre-transform, smooth normals where missing, validate).
// Errors are the problem alone ("Assimp crashed reading it (signal 11)", Assimp's own message,
// ...); the caller names the scene file and the object.
Expected<RawMeshFile> read_mesh_file(const std::filesystem::path& file,
                                     const MeshReadLimits& limits);

}  // namespace sb
