// Mesh import: reads one object's mesh file with Assimp (any format it knows: OBJ, PLY, glTF,
// FBX, ...) and builds the project's working mesh (mesh.h) in world space.
//
// Why each choice:
// - Assimp post-processing triangulates and generates smooth normals only where the file has
//   none. It is not asked to pre-transform vertices: the node hierarchy comes back, and node
//   transforms are applied here in double precision (file_nodes.h), every node's meshes making
//   one object, or one node's making one object of a level (level_file.h). It is not asked to
//   remove degenerate triangles (we count them, so the user is told) nor to convert axes (world
//   coordinates are the file's own; the scene's transform places the object).
// - Vertices are welded here, not by Assimp's JoinIdenticalVertices: in Assimp 5.2.5 that step
//   compares only the first UV channel, so on a mesh whose lightmap UVs (channel 1) have seams
//   where its texture UVs (channel 0) have none, vertices on either side of a lightmap seam are
//   merged and triangles stretch across the atlas. Two vertices are one when their position,
//   normal and every UV channel are bitwise equal (weld_vertices), so OpenMesh sees the shared
//   vertices and connectivity of each chart and no seam of any channel is lost.
// - Before Assimp reads a file, check_mesh_file (mesh_file_checks.h) refuses files it would
//   misread or exhaust memory on; Assimp then reads it in a helper process (mesh_reader.h), so a
//   crash, a hang or a runaway allocation inside Assimp is an error too; Assimp's own warnings
//   that it dropped faces are errors here.
// - obj.transform after the node's world transform is applied here, in double precision: points
//   by the affine map, normals by the inverse transpose of its linear part. A mirroring transform
//   (negative determinant) reverses every triangle's winding so that the winding-derived face
//   normals keep agreeing with the transformed vertex normals (both stay on the file's outward
//   side); any triangle whose winding still disagrees with its vertex normals is reversed too:
//   the normals say which side is out.
// - OpenMesh refuses non-manifold faces; such a face is added on fresh copies of its vertices so
//   no triangle, hence no blocker or receiver surface, is ever lost.
// - Bad input (unreadable file, no triangles, non-finite positions or ones beyond a thousand
//   kilometres of the origin, only degenerate triangles, a receiver without its UV channel) is
//   an Error, never a crash or an exception.
#include <fmt/core.h>
#include <OpenMesh/Core/System/omstream.hh>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <system_error>
#include <unordered_map>
#include <utility>
#include <vector>

#include "scene/file_nodes.h"
#include "scene/mesh.h"
#include "scene/mesh_file_checks.h"
#include "scene/mesh_reader.h"

namespace sb {
namespace {

// A triangle smaller than this fraction of the squared bounding-box diagonal has no area worth
// shading or tracing; it is skipped and counted.
constexpr double kDegenerateAreaFraction = 1e-12;

// One vertex of the file after Assimp's post-processing, in world space.
struct ImportedVertex {
  Vec3 position;
  Vec3 normal;  // unit, or zero when the file's normal is unusable (fixed after face normals)
  Vec2 uv = Vec2::Zero();
  Vec2 texture_uv = Vec2::Zero();  // channel 0, kept for outputs that carry the mesh (glTF)
};

class ErrorPrefix {
 public:
  ErrorPrefix(const ObjectDesc& obj, const std::filesystem::path& scene_file)
      : prefix_(object_location(scene_file, obj) + ": ") {}
  Error operator()(const std::string& problem) const { return scene_error(prefix_ + problem); }

 private:
  std::string prefix_;
};

// Assimp reports what it dropped from a broken file only as a log warning ("Some faces had
// out-of-range indices. Those faces were dropped." in its glTF 2 reader): the first such message
// of the reader's, or "".
std::string dropped_data_message(const std::vector<std::string>& messages) {
  for (const std::string& m : messages) {
    if (m.find("dropped") != std::string::npos || m.find("out-of-range") != std::string::npos ||
        m.find("out of range") != std::string::npos)
      return m;
  }
  return "";
}

// Assimp's messages may span lines and quote bytes of a broken file; errors are one line.
std::string one_line(std::string text) {
  for (char& c : text) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

// obj.mesh is resolved against the scene file's folder by the scene reader; a path still
// relative to that folder (an ObjectDesc built by hand) is accepted too.
std::filesystem::path mesh_path(const ObjectDesc& obj, const std::filesystem::path& scene_file) {
  std::error_code ec;
  if (obj.mesh.is_absolute() || std::filesystem::exists(obj.mesh, ec)) return obj.mesh;
  const std::filesystem::path beside_scene = scene_file.parent_path() / obj.mesh;
  if (std::filesystem::exists(beside_scene, ec)) return beside_scene;
  return obj.mesh;
}

// A captured Assimp message without its "Warn,  T0: " prefix, on one line.
std::string assimp_message(const std::string& message) {
  const auto colon = message.find(": ");
  return one_line(colon != std::string::npos && colon < 16 ? message.substr(colon + 2) : message);
}

// The largest world coordinate accepted, metres: a thousand kilometres, where a float's step is
// already 6 cm.
constexpr double kMaxCoordinate = 1e6;

std::string format_vec(const Vec3& v) {
  std::ostringstream out;
  out << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return out.str();
}

}  // namespace

namespace {

// OpenMesh prints why add_face refuses a face on its `omerr` stream, which goes to standard error
// ("PolyMeshT::add_face: patch re-linking failed", once per face of a level's non-manifold
// vertices): disconnected once, the first time a mesh is built, so that nothing but the bake's own
// warnings reaches the terminal.
void quiet_openmesh() {
  static const bool quiet = [] { return omerr().disconnect(std::cerr); }();
  (void)quiet;
}

}  // namespace

// OpenMesh's add_face refuses a face that would make a vertex or an edge non-manifold; the checks
// below are its own, done first, and a face that passes them may still be refused (a vertex whose
// fan of faces cannot be re-linked).
bool add_triangle(TriMesh& mesh, TriMesh::VertexHandle a, TriMesh::VertexHandle b,
                  TriMesh::VertexHandle c, std::vector<Vec2>& texture_uv) {
  quiet_openmesh();
  const TriMesh::VertexHandle corners[3] = {a, b, c};
  bool manifold = true;
  for (int i = 0; i < 3 && manifold; ++i) {
    const auto from = corners[i];
    const auto to = corners[(i + 1) % 3];
    if (!mesh.is_boundary(from)) manifold = false;
    const auto he = mesh.find_halfedge(from, to);
    if (he.is_valid() && !mesh.is_boundary(he)) manifold = false;
  }
  if (manifold && mesh.add_face(a, b, c).is_valid()) return true;

  TriMesh::VertexHandle copies[3];
  for (int i = 0; i < 3; ++i) {
    // Copies first: point(), normal() and texcoord2D() return references into the vertex
    // arrays that add_vertex may reallocate.
    const TriMesh::Point point = mesh.point(corners[i]);
    const TriMesh::Normal normal = mesh.normal(corners[i]);
    const TriMesh::TexCoord2D uv = mesh.texcoord2D(corners[i]);
    copies[i] = mesh.add_vertex(point);
    mesh.set_normal(copies[i], normal);
    mesh.set_texcoord2D(copies[i], uv);
    if (!texture_uv.empty()) texture_uv.push_back(texture_uv[std::size_t(corners[i].idx())]);
  }
  mesh.add_face(copies[0], copies[1], copies[2]);
  return false;
}

namespace {

// For every vertex (all instances concatenated, in order), the index of the first vertex that
// has the same world position and normal and the same UVs in every channel, bit for bit: the
// welded vertex it becomes. Bitwise, because "identical" is what a weld may merge without
// changing any attribute; +0 and -0 stay apart, which only keeps a seam.
std::vector<std::size_t> weld_vertices(const std::vector<ImportedVertex>& vertices,
                                       const RawMeshFile& file,
                                       const std::vector<PartInstance>& instances) {
  // World position and normal (6 doubles), up to 3 * kMaxUvChannels floats, which are present.
  struct Key {
    std::uint32_t present = 0;
    std::uint64_t world[6] = {};
    std::uint32_t bits[3 * kMaxUvChannels] = {};
    bool operator==(const Key& o) const {
      return present == o.present && std::memcmp(world, o.world, sizeof world) == 0 &&
             std::memcmp(bits, o.bits, sizeof bits) == 0;
    }
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      std::uint64_t h = 1469598103934665603ull ^ k.present;  // FNV-1a over the words
      for (std::uint64_t w : k.world) h = (h ^ w) * 1099511628211ull;
      for (std::uint32_t w : k.bits) h = (h ^ w) * 1099511628211ull;
      return std::size_t(h);
    }
  };
  std::vector<std::size_t> representative(vertices.size());
  std::unordered_map<Key, std::size_t, KeyHash> first;
  first.reserve(vertices.size());
  std::size_t index = 0;
  for (const PartInstance& instance : instances) {
    const RawMeshPart& part = file.parts[instance.part];
    for (std::size_t i = 0; i < part.vertex_count(); ++i, ++index) {
      Key key;
      std::memcpy(key.world, vertices[index].position.data(), 24);
      std::memcpy(key.world + 3, vertices[index].normal.data(), 24);
      for (int c = 0; c < kMaxUvChannels; ++c) {
        if (part.uvs[std::size_t(c)].empty()) continue;
        key.present |= 1u << c;
        std::memcpy(key.bits + 3 * c, &part.uvs[std::size_t(c)][3 * i], 12);
      }
      representative[index] = first.try_emplace(key, index).first->second;
    }
  }
  return representative;
}

// The steps of build_mesh, sharing the object, its parts' instances and the vertices read.
struct MeshBuild {
  const RawMeshFile& file;
  const std::vector<PartInstance>& instances;
  const ObjectDesc& obj;
  const std::string& path;
  const ErrorPrefix& error;
  Mesh& result;
  std::vector<ImportedVertex> vertices;   // in world space, all instances concatenated
  std::vector<std::size_t> first_vertex;  // per instance, the index of its first vertex
  bool keep_texture_uv = false;

  const RawMeshPart* choose_uv_channel();
  void choose_texture_uv();
  Status read_vertices();
  Status read_vertex(const RawMeshPart& part, std::size_t i, const Affine3& transform,
                     const Mat3& normal_matrix, bool& uvs_finite);
  Status check_receiver_uv(const RawMeshPart* part_without_uv) const;
  double degenerate_area() const;
  TriMesh::VertexHandle vertex(std::size_t index, std::vector<TriMesh::VertexHandle>& handle);
  void add_triangles(double min_area);
};

// UV channel: every part must carry it for the object to have lightmap UVs. Generated ones
// (uv = "auto") are made after import (texels/auto_uv.h): none are read. Returns the first part
// without it, if any.
const RawMeshPart* MeshBuild::choose_uv_channel() {
  const bool channel_in_range =
      !obj.auto_uv && obj.uv_channel >= 0 && obj.uv_channel < kMaxUvChannels;
  result.has_uv = channel_in_range;
  const RawMeshPart* part_without_uv = nullptr;
  for (const PartInstance& instance : instances) {
    const RawMeshPart& part = file.parts[instance.part];
    if (!channel_in_range || part.uvs[std::size_t(obj.uv_channel)].empty()) {
      result.has_uv = false;
      if (!part_without_uv) part_without_uv = &part;
    }
  }
  return part_without_uv;
}

// A receiver's texture UVs (channel 0), when its lightmap UVs are another channel and every
// part has them: a glTF of the bake carries them as TEXCOORD_0.
void MeshBuild::choose_texture_uv() {
  keep_texture_uv = obj.receiver && (obj.auto_uv || obj.uv_channel != 0);
  for (const PartInstance& instance : instances)
    keep_texture_uv = keep_texture_uv && !file.parts[instance.part].uvs[0].empty();
}

// Vertices in world space, all instances concatenated. UVs are copied only when every part has
// the channel, so has_uv says what the texcoords hold.
Status MeshBuild::read_vertices() {
  first_vertex.resize(instances.size());
  bool uvs_finite = true;
  for (std::size_t m = 0; m < instances.size(); ++m) {
    const RawMeshPart& part = file.parts[instances[m].part];
    const Affine3& transform = instances[m].transform;
    const Mat3 normal_matrix = transform.linear().inverse().transpose();
    first_vertex[m] = vertices.size();
    for (std::size_t i = 0; i < part.vertex_count(); ++i)
      if (Status read = read_vertex(part, i, transform, normal_matrix, uvs_finite); !read)
        return read.error();
  }
  if (!uvs_finite) {  // a blocker's unusable UVs are dropped: it needs none
    result.has_uv = false;
    for (ImportedVertex& v : vertices) v.uv = Vec2::Zero();
  }
  return Ok{};
}

// Vertex i of `part`, placed by `transform`, appended to the vertices; an error where its
// position is unusable, or a receiver's UV is. A blocker's non-finite UV clears `uvs_finite`.
Status MeshBuild::read_vertex(const RawMeshPart& part, std::size_t i, const Affine3& transform,
                              const Mat3& normal_matrix, bool& uvs_finite) {
  ImportedVertex v;
  const float* p = &part.positions[3 * i];
  const Vec3 file_position(p[0], p[1], p[2]);
  if (!file_position.allFinite()) {
    return error("'" + path + "': vertex " + std::to_string(vertices.size()) +
                 " (as Assimp numbers them) has a non-finite position " +
                 format_vec(file_position) + "; fix the mesh file");
  }
  v.position = transform * file_position;
  // Finite but beyond any level (1e30 in a file, or a scale of 1e25): the ray tracer's
  // float arithmetic overflows on such coordinates, and a float there is coarser than a
  // texel anyway.
  if (!(v.position.cwiseAbs().maxCoeff() <= kMaxCoordinate)) {
    return error(fmt::format(
        "'{}': vertex {} (as Assimp numbers them) at {} lies beyond {:g} m of the origin{}; "
        "fix the mesh file or the object's transform",
        path, vertices.size(), format_vec(v.position), kMaxCoordinate,
        file_position.cwiseAbs().maxCoeff() <= kMaxCoordinate ? " after its transform" : ""));
  }
  v.normal = Vec3::Zero();
  if (!part.normals.empty()) {
    const float* n = &part.normals[3 * i];
    const Vec3 world_normal = normal_matrix * Vec3(n[0], n[1], n[2]);
    const double length = world_normal.norm();
    if (std::isfinite(length) && length > 0) v.normal = world_normal / length;
  }
  if (result.has_uv) {
    const float* t = &part.uvs[std::size_t(obj.uv_channel)][3 * i];
    v.uv = Vec2(t[0], t[1]);
    if (!v.uv.allFinite()) {
      if (obj.receiver) {
        return error("'" + path + "': vertex " + std::to_string(vertices.size()) +
                     " (as Assimp numbers them) has a non-finite UV in channel " +
                     std::to_string(obj.uv_channel) + "; fix the mesh file");
      }
      uvs_finite = false;
    }
  }
  if (keep_texture_uv) {
    const float* t = &part.uvs[0][3 * i];
    v.texture_uv = Vec2(t[0], t[1]);
    keep_texture_uv = v.texture_uv.allFinite();
  }
  vertices.push_back(v);
  return Ok{};
}

// A receiver without lightmap UVs, read or made, is an error naming the channel it asked for.
Status MeshBuild::check_receiver_uv(const RawMeshPart* part_without_uv) const {
  if (obj.receiver && !result.has_uv && !obj.auto_uv) {
    const int channels = part_without_uv ? part_without_uv->uv_channel_count() : 0;
    const std::string channel = std::to_string(obj.uv_channel);
    return error("a receiver needs lightmap UVs in channel " + channel + " (uv = " + channel +
                 ") but '" + path + "' has " +
                 (channels == 0 ? std::string("no UVs")
                                : "only " + std::to_string(channels) + " UV channel(s)") +
                 "; add a lightmap UV set or set 'uv' to an existing channel");
  }
  return Ok{};
}

// Degenerate threshold relative to the object's size, from the vertices faces use.
double MeshBuild::degenerate_area() const {
  Bounds3 bounds;
  for (std::size_t m = 0; m < instances.size(); ++m)
    for (const std::uint32_t index : file.parts[instances[m].part].triangles)
      bounds.extend(vertices[first_vertex[m] + index].position);
  const double diagonal = bounds.diagonal();
  return kDegenerateAreaFraction * diagonal * diagonal;
}

// The mesh vertex of vertex `index`, added on first use (`handle` holds those made so far).
TriMesh::VertexHandle MeshBuild::vertex(std::size_t index,
                                        std::vector<TriMesh::VertexHandle>& handle) {
  TriMesh& mesh = result.mesh;
  if (!handle[index].is_valid()) {
    const ImportedVertex& v = vertices[index];
    handle[index] = mesh.add_vertex(TriMesh::Point(v.position.x(), v.position.y(), v.position.z()));
    mesh.set_normal(handle[index], TriMesh::Normal(v.normal.x(), v.normal.y(), v.normal.z()));
    mesh.set_texcoord2D(handle[index], TriMesh::TexCoord2D(v.uv.x(), v.uv.y()));
    if (keep_texture_uv) result.texture_uv.push_back(v.texture_uv);
  }
  return handle[index];
}

// The triangles of every instance on the welded vertices, wound as their vertex normals say;
// those of no more than `min_area` are skipped and counted, as are non-manifold ones split off.
void MeshBuild::add_triangles(double min_area) {
  TriMesh& mesh = result.mesh;
  const std::vector<std::size_t> welded = weld_vertices(vertices, file, instances);
  std::vector<TriMesh::VertexHandle> handle(vertices.size());  // made on first use
  for (std::size_t m = 0; m < instances.size(); ++m) {
    const std::vector<std::uint32_t>& triangles = file.parts[instances[m].part].triangles;
    const bool mirrors = instances[m].transform.linear().determinant() < 0;
    for (std::size_t f = 0; f + 2 < triangles.size(); f += 3) {
      std::size_t index[3];
      for (int k = 0; k < 3; ++k)
        index[k] = welded[first_vertex[m] + triangles[f + std::size_t(k)]];
      if (mirrors) std::swap(index[1], index[2]);
      const Vec3& a = vertices[index[0]].position;
      const Vec3& b = vertices[index[1]].position;
      const Vec3& c = vertices[index[2]].position;
      const Vec3 winding_normal = (b - a).cross(c - a);
      const double area = 0.5 * winding_normal.norm();
      const Vec3 normal_sum =
          vertices[index[0]].normal + vertices[index[1]].normal + vertices[index[2]].normal;
      if (winding_normal.dot(normal_sum) < 0) std::swap(index[1], index[2]);
      if (!(area > min_area) || area == 0 || index[0] == index[1] || index[1] == index[2] ||
          index[0] == index[2]) {
        ++result.skipped_degenerate;
        continue;
      }
      if (!add_triangle(mesh, vertex(index[0], handle), vertex(index[1], handle),
                        vertex(index[2], handle), result.texture_uv))
        ++result.split_nonmanifold;
    }
  }
}

// A vertex whose file normal was missing or unusable takes the area-weighted mean of its faces'.
void fill_missing_normals(TriMesh& mesh) {
  for (auto v : mesh.vertices()) {
    if (mesh.normal(v).sqrnorm() > 0) continue;
    TriMesh::Normal sum(0, 0, 0);
    for (auto f : mesh.vf_range(v)) sum += mesh.calc_face_normal(f) * mesh.calc_face_area(f);
    const double length = sum.norm();
    mesh.set_normal(v, length > 0 ? sum / length : TriMesh::Normal(0, 0, 1));
  }
}

Expected<Mesh> build_mesh(const RawMeshFile& file, const std::vector<PartInstance>& instances,
                          const ObjectDesc& obj, const std::string& path,
                          const ErrorPrefix& error) {
  Mesh result;
  result.name = obj.name;

  std::size_t triangle_count = 0;
  for (const PartInstance& instance : instances)
    triangle_count += file.parts[instance.part].triangles.size() / 3;
  if (triangle_count == 0) {
    return error("'" + path + "' has no triangles (an object needs a surface)");
  }

  MeshBuild build{file, instances, obj, path, error, result, {}, {}, false};
  const RawMeshPart* part_without_uv = build.choose_uv_channel();
  build.choose_texture_uv();
  if (Status read = build.read_vertices(); !read) return read.error();
  if (Status checked = build.check_receiver_uv(part_without_uv); !checked) return checked.error();
  build.add_triangles(build.degenerate_area());
  TriMesh& mesh = result.mesh;
  if (mesh.n_faces() == 0) {
    return error("every one of the " + std::to_string(triangle_count) + " triangles of '" + path +
                 "' has zero area; fix the mesh file or its scale");
  }
  mesh.update_face_normals();
  fill_missing_normals(mesh);
  return result;
}

}  // namespace

Expected<RawMeshFile> read_checked_mesh_file(const std::filesystem::path& file,
                                             const ImportLimits& import_limits) {
  const std::string path = file.string();
  try {
    if (Status checked = check_mesh_file(file, import_limits.max_file_bytes); !checked) {
      return scene_error("cannot read mesh '" + path + "': " + checked.error().message);
    }
    MeshReadLimits limits;
    limits.max_memory = import_limits.max_memory;
    std::error_code ec;
    limits.max_seconds = import_limits.max_seconds > 0
                             ? import_limits.max_seconds
                             : 60 + 10 * double(std::filesystem::file_size(file, ec)) / 1e6;
    auto raw = read_mesh_file(file, limits);
    if (!raw) return scene_error("cannot read mesh '" + path + "': " + raw.error().message);
    if (const std::string dropped = dropped_data_message(raw->warnings); !dropped.empty()) {
      return scene_error("'" + path + "' is broken: Assimp says \"" + assimp_message(dropped) +
                         "\"; fix or re-export the mesh file");
    }
    return raw;
  } catch (const std::exception& e) {
    return scene_error("cannot import mesh '" + path + "': " + one_line(e.what()));
  }
}

Expected<std::shared_ptr<const RawMeshFile>> read_object_file(
    const ObjectDesc& obj, const std::filesystem::path& scene_file,
    const ImportLimits& import_limits) {
  auto raw = read_checked_mesh_file(mesh_path(obj, scene_file), import_limits);
  if (!raw) return ErrorPrefix(obj, scene_file)(raw.error().message);
  return std::shared_ptr<const RawMeshFile>(std::make_shared<RawMeshFile>(std::move(*raw)));
}

Expected<Mesh> build_object_mesh(const ObjectDesc& obj, const RawMeshFile& file,
                                 const std::filesystem::path& scene_file) {
  const ErrorPrefix error(obj, scene_file);
  const std::string path = mesh_path(obj, scene_file).string();
  try {
    const std::vector<PartInstance> instances =
        part_instances(file, node_world_transforms(file), obj.node, obj.parts, obj.transform);
    return build_mesh(file, instances, obj, path, error);
  } catch (const std::exception& e) {
    return error("cannot import mesh '" + path + "': " + one_line(e.what()));
  }
}

Expected<Mesh> import_mesh(const ObjectDesc& obj, const std::filesystem::path& scene_file,
                           const ImportLimits& import_limits) {
  auto file = read_object_file(obj, scene_file, import_limits);
  if (!file) return file.error();
  return build_object_mesh(obj, **file, scene_file);
}

}  // namespace sb
