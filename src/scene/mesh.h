// The project's working mesh: an OpenMesh triangle mesh in world space (object transform
// applied) with per-vertex normals and the object's lightmap UVs. Imported with Assimp by
// import_mesh (mesh_import.cpp); every later stage reads geometry from here.
#pragma once

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include <array>
#include <bit>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/geometry.h"
#include "scene/scene.h"

namespace sb {

struct MeshTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
  using TexCoord2D = OpenMesh::Vec2d;
  VertexAttributes(OpenMesh::Attributes::Normal | OpenMesh::Attributes::TexCoord2D);
  FaceAttributes(OpenMesh::Attributes::Normal);
};

using TriMesh = OpenMesh::TriMesh_ArrayKernelT<MeshTraits>;

struct Mesh {
  std::string name;     // the object's name
  TriMesh mesh;         // world space; vertex texcoords are the lightmap UVs
  bool has_uv = false;  // false when the mesh has no UV set at the object's uv channel
  // Per vertex, a receiver's UV channel 0 when its lightmap UVs are another channel (its texture
  // UVs, which a glTF of the bake carries beside the lightmap UVs); empty otherwise.
  std::vector<Vec2> texture_uv;
  int skipped_degenerate = 0;  // zero-area triangles dropped on import
  // Triangles OpenMesh would not link to their neighbours (a vertex or edge a 2-manifold cannot
  // have: three faces on an edge, a vertex whose fan cannot be re-linked), kept on copies of
  // their corners (add_triangle).
  int split_nonmanifold = 0;
  bool uv_generated = false;  // the lightmap UVs were made by the bake (texels/auto_uv.h)
};

// Loads every mesh of every node of obj.mesh (one object = the whole file), applies node
// transforms and then obj.transform, takes UVs from obj.uv_channel, drops zero-area triangles
// (counted in skipped_degenerate). Errors name scene_file, the object and the problem: an
// unreadable file, no triangles, NaN/infinite vertices, or a receiver without the UV channel.
// What a mesh file may cost: its size, and the memory and time its reader may take
// (mesh_reader.h).
struct ImportLimits {
  std::uint64_t max_file_bytes = std::uint64_t(1) << 32;  // refused before it is read
  std::uint64_t max_memory = std::uint64_t(4) << 30;      // Assimp's allocations
  double max_seconds = 0;  // Assimp's time; 0: 60 s plus 10 s per MB of file
};
Expected<Mesh> import_mesh(const ObjectDesc& obj, const std::filesystem::path& scene_file,
                           const ImportLimits& limits = {});

// The two halves of import_mesh, for objects that share a file (a level's nodes): the file read
// once (its checks, Assimp in the helper, dropped data refused), and an object's mesh built from
// it. Errors name scene_file and the object as import_mesh's do; read_checked_mesh_file's name
// only the mesh file.
struct RawMeshFile;
Expected<RawMeshFile> read_checked_mesh_file(const std::filesystem::path& file,
                                             const ImportLimits& limits);
Expected<std::shared_ptr<const RawMeshFile>> read_object_file(
    const ObjectDesc& obj, const std::filesystem::path& scene_file, const ImportLimits& limits);
Expected<Mesh> build_object_mesh(const ObjectDesc& obj, const RawMeshFile& file,
                                 const std::filesystem::path& scene_file);

// Adds triangle (a, b, c) to mesh; a face OpenMesh refuses (it would make a vertex or an edge
// non-manifold) is added on three fresh copies of its vertices, and of their texture UVs when
// `texture_uv` holds them (mesh_import.cpp). Returns false for such a face. OpenMesh's own
// messages about it (its `omerr` stream, on standard error) are silenced: the count is the
// caller's to report, naming the object.
bool add_triangle(TriMesh& mesh, TriMesh::VertexHandle a, TriMesh::VertexHandle b,
                  TriMesh::VertexHandle c, std::vector<Vec2>& texture_uv);

// A point's coordinates bit for bit, to match points that are the same exactly (the two sides of
// a mesh edge whose vertices were split for their UVs or normals).
using PositionBits = std::array<std::uint64_t, 3>;
inline PositionBits position_bits(const Vec3& p) {
  return {std::bit_cast<std::uint64_t>(p.x()), std::bit_cast<std::uint64_t>(p.y()),
          std::bit_cast<std::uint64_t>(p.z())};
}

// World-space triangle of face f, as three points.
struct Triangle {
  Vec3 p[3];
  Vec3 n[3];   // vertex normals (unit)
  Vec2 uv[3];  // lightmap UVs
};
Triangle triangle(const TriMesh& mesh, TriMesh::FaceHandle f);

// The mesh's surface area in world space (m²) and its lightmap UV triangles' total area (Σ of
// |area|, the unit square being 1): their ratio is the world area a unit of UV area stands for.
struct SurfaceAreas {
  double world = 0, uv = 0;
};
SurfaceAreas surface_areas(const Mesh& mesh);

}  // namespace sb
