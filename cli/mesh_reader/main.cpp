// shadowbake_mesh_reader: the process in which Assimp reads one mesh file
// (src/scene/mesh_reader.h). Started by read_mesh_file with posix_spawn (never a bare fork of a
// process whose other threads may hold locks), it reads the file named by argv[1] under a data
// limit of argv[2] bytes, packs what the project uses (mesh_reader.h gives the layout) and writes
// it to file descriptor 3. Exit status 0 with the answer written; anything else (a crash, the
// limit, the parent's kill at its deadline) is read by the parent as Assimp's failure.
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <unistd.h>
#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <assimp/LogStream.hpp>

#include <array>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <string>
#include <vector>

#include "scene/mesh_reader.h"

namespace {

// Assimp's log: one global logger, whose stream collects what the reader warns about.
class CapturedLog : public Assimp::LogStream {
 public:
  void write(const char* message) override {
    std::string m = message ? message : "";
    while (!m.empty() && (m.back() == '\n' || m.back() == '\r')) m.pop_back();
    messages.push_back(std::move(m));
  }
  std::vector<std::string> messages;
};

class Writer {
 public:
  template <class T>
  void put(const T& v) {
    bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void put_string(const std::string& s) {
    put(std::uint64_t(s.size()));
    bytes.append(s);
  }
  template <class T, std::size_t N>
  void put_floats(const std::array<T, N>& v) {
    for (const T& x : v) put(x);
  }
  template <class T>
  void put_array(const std::vector<T>& v) {
    put(std::uint64_t(v.size()));
    if (!v.empty()) bytes.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  std::string bytes;
};

std::string one_line(std::string text) {
  for (char& c : text) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

std::array<float, 3> floats(const aiVector3D& v) { return {v.x, v.y, v.z}; }
std::array<float, 3> floats(const aiColor3D& c) { return {c.r, c.g, c.b}; }

// The nodes below `node`, depth first, each after its parent; a hierarchy deeper than any level
// (or a cycle Assimp let through) is an error rather than a stack overflow.
constexpr int kMaxNodeDepth = 256;
bool collect_nodes(const aiNode* node, std::int32_t parent, int depth,
                   std::vector<sb::RawNode>& nodes, unsigned mesh_count, std::string& error) {
  if (depth > kMaxNodeDepth) {
    error = fmt::format("node '{}' is nested more than {} levels deep", node->mName.C_Str(),
                        kMaxNodeDepth);
    return false;
  }
  sb::RawNode raw;
  raw.name = node->mName.C_Str();
  raw.parent = parent;
  const aiMatrix4x4& m = node->mTransformation;
  raw.transform = {m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4,
                   m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4};
  for (unsigned i = 0; i < node->mNumMeshes; ++i) {
    if (node->mMeshes[i] >= mesh_count) {
      error = fmt::format("node '{}' names mesh {} of {}", raw.name, node->mMeshes[i], mesh_count);
      return false;
    }
    raw.parts.push_back(node->mMeshes[i]);
  }
  const auto index = std::int32_t(nodes.size());
  nodes.push_back(std::move(raw));
  for (unsigned c = 0; c < node->mNumChildren; ++c)
    if (!collect_nodes(node->mChildren[c], index, depth + 1, nodes, mesh_count, error))
      return false;
  return true;
}

// Read, copy out, pack: status 0 and the file, or 1 and the error.
std::string read_and_pack(const std::string& file, CapturedLog& log) {
  Writer out;
  out.put(sb::kMeshReaderMagic);
  std::string error;
  std::vector<sb::RawMeshPart> parts;
  std::vector<sb::RawNode> nodes;
  std::vector<sb::RawMaterial> materials;
  std::vector<sb::RawLight> lights;
  double unit_scale = 0;
  try {
    Assimp::Importer importer;
    // No pre-transformation: the nodes and their transforms come back as they are, so that a
    // level's objects stay apart and the transforms are applied in double precision.
    const unsigned flags =
        aiProcess_Triangulate | aiProcess_GenSmoothNormals | aiProcess_ValidateDataStructure;
    const aiScene* scene = importer.ReadFile(file, flags);
    if (!scene) {
      error = one_line(importer.GetErrorString());
    } else if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !scene->mRootNode) {
      error = "the file holds no complete mesh";
    } else {
      for (unsigned m = 0; m < scene->mNumMeshes && error.empty(); ++m) {
        const aiMesh* am = scene->mMeshes[m];
        sb::RawMeshPart part;
        const auto copy = [&](const aiVector3D* v, std::vector<float>& to) {
          to.resize(std::size_t(am->mNumVertices) * 3);
          for (unsigned i = 0; i < am->mNumVertices; ++i) {
            to[3 * i] = v[i].x;
            to[3 * i + 1] = v[i].y;
            to[3 * i + 2] = v[i].z;
          }
        };
        copy(am->mVertices, part.positions);
        if (am->HasNormals()) copy(am->mNormals, part.normals);
        for (unsigned c = 0; c < unsigned(sb::kMaxUvChannels); ++c) {
          if (!am->HasTextureCoords(c)) break;  // channels are used from 0 on
          copy(am->mTextureCoords[c], part.uvs[c]);
        }
        for (unsigned f = 0; f < am->mNumFaces && error.empty(); ++f) {
          const aiFace& face = am->mFaces[f];
          if (face.mNumIndices != 3) continue;
          for (unsigned k = 0; k < 3; ++k) {
            if (face.mIndices[k] >= am->mNumVertices) {
              error = fmt::format("mesh {} face {} names vertex {} of {}", m, f, face.mIndices[k],
                                  am->mNumVertices);
              break;
            }
            part.triangles.push_back(face.mIndices[k]);
          }
        }
        part.material = am->mMaterialIndex;
        parts.push_back(std::move(part));
      }
      if (error.empty()) collect_nodes(scene->mRootNode, -1, 0, nodes, scene->mNumMeshes, error);
      for (unsigned i = 0; i < scene->mNumMaterials; ++i) {
        const aiMaterial* am = scene->mMaterials[i];
        sb::RawMaterial material;
        material.name = am->GetName().C_Str();
        aiColor3D emissive(0, 0, 0);
        if (am->Get(AI_MATKEY_COLOR_EMISSIVE, emissive) == AI_SUCCESS)
          material.emissive = floats(emissive);
        materials.push_back(std::move(material));
      }
      for (unsigned i = 0; i < scene->mNumLights; ++i) {
        const aiLight* al = scene->mLights[i];
        sb::RawLight light;
        light.name = al->mName.C_Str();
        light.type = std::uint32_t(al->mType);
        light.position = floats(al->mPosition);
        light.direction = floats(al->mDirection);
        light.up = floats(al->mUp);
        light.color = floats(al->mColorDiffuse);
        light.inner_cone = al->mAngleInnerCone;
        light.outer_cone = al->mAngleOuterCone;
        light.size = {al->mSize.x, al->mSize.y};
        lights.push_back(std::move(light));
      }
      // FBX's centimetres per unit (Assimp keeps it as metadata, stored as a float or a double).
      double factor = 0;
      float factor_float = 0;
      if (scene->mMetaData && !scene->mMetaData->Get("UnitScaleFactor", factor) &&
          scene->mMetaData->Get("UnitScaleFactor", factor_float))
        factor = factor_float;
      if (std::isfinite(factor) && factor > 0) unit_scale = 0.01 * factor;
    }
  } catch (const std::exception& e) {
    error = one_line(e.what());
  }
  out.put(std::uint32_t(error.empty() ? 0 : 1));
  out.put_string(error);
  out.put(std::uint64_t(log.messages.size()));
  for (const std::string& m : log.messages) out.put_string(one_line(m));
  if (!error.empty()) return out.bytes;
  out.put(std::uint64_t(parts.size()));
  for (const sb::RawMeshPart& p : parts) {
    out.put_array(p.positions);
    out.put_array(p.normals);
    for (const auto& uv : p.uvs) out.put_array(uv);
    out.put_array(p.triangles);
    out.put(p.material);
  }
  out.put(std::uint64_t(nodes.size()));
  for (const sb::RawNode& n : nodes) {
    out.put_string(n.name);
    out.put(n.parent);
    out.put_floats(n.transform);
    out.put_array(n.parts);
  }
  out.put(std::uint64_t(materials.size()));
  for (const sb::RawMaterial& m : materials) {
    out.put_string(m.name);
    out.put_floats(m.emissive);
  }
  out.put(std::uint64_t(lights.size()));
  for (const sb::RawLight& l : lights) {
    out.put_string(l.name);
    out.put(l.type);
    out.put_floats(l.position);
    out.put_floats(l.direction);
    out.put_floats(l.up);
    out.put_floats(l.color);
    out.put(l.inner_cone);
    out.put(l.outer_cone);
    out.put_floats(l.size);
  }
  out.put(unit_scale);
  return out.bytes;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) return 2;
  // Ends with the process that started it, whatever that process dies of.
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  // Heap and anonymous mappings beyond what this small process holds at its start.
  const std::uint64_t limit = std::strtoull(argv[2], nullptr, 10);
  std::uint64_t held_kib = 0;
  {
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);)
      if (line.rfind("VmData:", 0) == 0) held_kib = std::stoull(line.substr(7));
  }
  struct rlimit data = {};
  data.rlim_cur = data.rlim_max = rlim_t(held_kib * 1024 + limit);
  ::setrlimit(RLIMIT_DATA, &data);

  Assimp::DefaultLogger::create("", Assimp::Logger::NORMAL, 0);
  auto* log = new CapturedLog;  // owned by the logger from here on
  Assimp::DefaultLogger::get()->attachStream(log, Assimp::Logger::Warn | Assimp::Logger::Err);
  const std::string packed = read_and_pack(argv[1], *log);
  std::size_t written = 0;
  while (written < packed.size()) {
    const ssize_t n = ::write(3, packed.data() + written, packed.size() - written);
    if (n <= 0) return 3;
    written += std::size_t(n);
  }
  // No destructors: Assimp's logger and importer are left to the exit.
  std::_Exit(0);
}
