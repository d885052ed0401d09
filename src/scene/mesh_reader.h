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
// count and its elements, then its material, u32); the nodes (u64 count; each: name, parent (i32,
// -1 for the root), its transform as 16 floats row by row, its parts as an array of u32); the
// materials (u64 count; each: name, emissive colour as 3 floats); the lights (u64 count; each:
// name, type (u32, Assimp's aiLightSourceType), position, direction, up, colour (3 floats each),
// inner and outer cone angles, and size (2 floats)); the file's unit scale (f64).
inline constexpr std::uint32_t kMeshReaderMagic = 0x324d4253;  // "SBM2"

// One of the file's meshes after Assimp's triangulation, in its node's own coordinates: per
// vertex 3 floats of position, and of normal and of each UV channel where present (empty
// otherwise); the triangles as vertex indices, each checked to be in range; the index of its
// material. Points and lines are left out.
struct RawMeshPart {
  std::vector<float> positions, normals;
  std::array<std::vector<float>, kMaxUvChannels> uvs;
  std::vector<std::uint32_t> triangles;
  std::uint32_t material = 0;
  std::size_t vertex_count() const { return positions.size() / 3; }
  int uv_channel_count() const;  // channels present from 0 on
};

// A node of the file's hierarchy, in depth-first order (a parent before its children): its name
// as Assimp gives it, its parent's index, its transform relative to the parent (row-major 4×4, the
// last row 0 0 0 1) and the parts it places.
struct RawNode {
  std::string name;
  std::int32_t parent = -1;
  std::array<float, 16> transform = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  std::vector<std::uint32_t> parts;
};

struct RawMaterial {
  std::string name;
  std::array<float, 3> emissive = {0, 0, 0};  // Assimp's emissive colour (glTF emissiveFactor)
};

// A light of the file, in its node's coordinates (Assimp names the light after its node).
struct RawLight {
  enum Type : std::uint32_t {
    undefined = 0,
    directional = 1,
    point = 2,
    spot = 3,
    ambient = 4,
    area = 5
  };
  std::string name;
  std::uint32_t type = 0;
  std::array<float, 3> position = {0, 0, 0}, direction = {0, 0, -1}, up = {0, 1, 0};
  std::array<float, 3> color = {0, 0, 0};  // colour times intensity, as Assimp gives it
  float inner_cone = 0, outer_cone = 0;    // radians, from the axis (spot)
  std::array<float, 2> size = {0, 0};      // area lights
};

struct RawMeshFile {
  std::vector<RawMeshPart> parts;
  std::vector<RawNode> nodes;  // nodes[0] is the root
  std::vector<RawMaterial> materials;
  std::vector<RawLight> lights;
  // Metres per unit of the file where it says (FBX's UnitScaleFactor is centimetres per unit:
  // 0.01 × it); 0 where it does not.
  double unit_scale = 0;
  std::vector<std::string> warnings;  // Assimp's warnings and errors while it read the file
};

struct MeshReadLimits {
  std::uint64_t max_memory = std::uint64_t(4) << 30;  // bytes the reader may allocate
  double max_seconds = 120;                           // wall-clock time it may take
};

// Reads `file` with Assimp (triangulate, smooth normals where missing, validate), keeping its
// node hierarchy, materials and lights.
// Errors are the problem alone ("Assimp crashed reading it (signal 11)", Assimp's own message,
// ...); the caller names the scene file and the object.
Expected<RawMeshFile> read_mesh_file(const std::filesystem::path& file,
                                     const MeshReadLimits& limits);

}  // namespace sb
