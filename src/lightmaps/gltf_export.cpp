// The glTF 2.0 binary writer (gltf_export.h), after the glTF 2.0 specification: a 12-byte
// header, a JSON chunk padded with spaces, a BIN chunk padded with zeros, every buffer view
// 4-byte aligned.
#include "lightmaps/gltf_export.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

namespace sb {

namespace {

using Json = nlohmann::ordered_json;

// glTF's numeric constants.
constexpr int kFloat = 5126, kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;
constexpr int kLinear = 9729, kClampToEdge = 33071;
constexpr int kTriangles = 4;
constexpr std::uint32_t kMagic = 0x46546C67;      // "glTF"
constexpr std::uint32_t kJsonChunk = 0x4E4F534A;  // "JSON"
constexpr std::uint32_t kBinChunk = 0x004E4942;   // "BIN\0"

// The binary chunk and the buffer views and accessors that index it.
class BinaryChunk {
 public:
  // A buffer view of `bytes`; `target` 0 for none (images).
  int view(const void* bytes, std::size_t size, int target) {
    align();
    Json v = {{"buffer", 0}, {"byteOffset", data_.size()}, {"byteLength", size}};
    if (target != 0) v["target"] = target;
    const auto* p = static_cast<const std::uint8_t*>(bytes);
    data_.insert(data_.end(), p, p + size);
    views_.push_back(std::move(v));
    return int(views_.size()) - 1;
  }

  // An accessor of `count` elements of `components` floats (type "VEC2", "VEC3"), with the
  // min and max glTF requires for positions (and the validator checks for all).
  int floats(const std::vector<float>& values, int components, const char* type) {
    const std::size_t count = values.size() / std::size_t(components);
    const int v = view(values.data(), values.size() * sizeof(float), kArrayBuffer);
    Json lo = Json::array(), hi = Json::array();
    for (int c = 0; c < components; ++c) {
      float a = std::numeric_limits<float>::infinity(), b = -a;
      for (std::size_t i = 0; i < count; ++i) {
        a = std::min(a, values[i * std::size_t(components) + std::size_t(c)]);
        b = std::max(b, values[i * std::size_t(components) + std::size_t(c)]);
      }
      lo.push_back(a);
      hi.push_back(b);
    }
    accessors_.push_back({{"bufferView", v},
                          {"componentType", kFloat},
                          {"count", count},
                          {"type", type},
                          {"min", lo},
                          {"max", hi}});
    return int(accessors_.size()) - 1;
  }

  int indices(const std::vector<std::uint32_t>& values) {
    const int v = view(values.data(), values.size() * sizeof(std::uint32_t), kElementArrayBuffer);
    const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
    accessors_.push_back({{"bufferView", v},
                          {"componentType", kUnsignedInt},
                          {"count", values.size()},
                          {"type", "SCALAR"},
                          {"min", Json::array({values.empty() ? 0u : *lo})},
                          {"max", Json::array({values.empty() ? 0u : *hi})}});
    return int(accessors_.size()) - 1;
  }

  void align() {
    while (data_.size() % 4 != 0) data_.push_back(0);
  }
  const std::vector<std::uint8_t>& data() const { return data_; }
  Json& views() { return views_; }
  Json& accessors() { return accessors_; }

 private:
  std::vector<std::uint8_t> data_;
  Json views_ = Json::array(), accessors_ = Json::array();
};

void append_u32(std::vector<std::uint8_t>& out, std::uint32_t value) {
  for (int i = 0; i < 4; ++i) out.push_back(std::uint8_t(value >> (8 * i)));
}

// glTF's frame from the scene's: from Z up, a rotation about X by −90°; a Y-up world as it is.
std::array<double, 3> to_gltf_frame(double x, double y, double z, bool world_y_up) {
  return world_y_up ? std::array<double, 3>{x, y, z} : std::array<double, 3>{x, z, -y};
}

}  // namespace

GltfMesh gltf_mesh(const Mesh& mesh, bool with_uvs, bool world_y_up) {
  GltfMesh out;
  const TriMesh& m = mesh.mesh;
  const bool own_texture_uv = mesh.texture_uv.size() == m.n_vertices();
  for (auto v : m.vertices()) {
    const auto& p = m.point(v);
    const std::array<double, 3> position = to_gltf_frame(p[0], p[1], p[2], world_y_up);
    for (const double c : position) out.positions.push_back(float(c));
    TriMesh::Normal n = m.normal(v);
    const double length = n.norm();
    n = length > 0 ? n / length : TriMesh::Normal(0, 0, 1);
    const std::array<double, 3> normal = to_gltf_frame(n[0], n[1], n[2], world_y_up);
    // Unit in single precision, as the validator checks it.
    const float nx = float(normal[0]), ny = float(normal[1]), nz = float(normal[2]);
    const float norm = std::sqrt(nx * nx + ny * ny + nz * nz);
    out.normals.insert(out.normals.end(), {nx / norm, ny / norm, nz / norm});
    if (!mesh.has_uv || !with_uvs) continue;
    const auto& uv = m.texcoord2D(v);
    out.texcoord1.insert(out.texcoord1.end(), {float(uv[0]), float(1.0 - uv[1])});
    const Vec2 t = own_texture_uv ? mesh.texture_uv[std::size_t(v.idx())] : Vec2(uv[0], uv[1]);
    out.texcoord0.insert(out.texcoord0.end(), {float(t.x()), float(1.0 - t.y())});
  }
  for (auto f : m.faces())
    for (auto v : m.fv_range(f)) out.indices.push_back(std::uint32_t(v.idx()));
  return out;
}

Expected<std::vector<std::uint8_t>> glb_bytes(const std::vector<GltfObject>& objects,
                                              const std::vector<GltfTexture>& textures,
                                              const std::string& quantity,
                                              const std::string& generator) {
  BinaryChunk bin;
  Json nodes = Json::array(), meshes = Json::array(), materials = Json::array();
  Json images = Json::array(), gltf_textures = Json::array();
  bool transformed = false;
  for (const GltfTexture& t : textures) {
    const int view = bin.view(t.png.data(), t.png.size(), 0);
    images.push_back({{"name", t.name}, {"mimeType", "image/png"}, {"bufferView", view}});
    gltf_textures.push_back({{"sampler", 0}, {"source", int(images.size()) - 1}});
  }
  for (std::size_t r = 0; r < objects.size(); ++r) {
    const GltfObject& object = objects[r];
    if (!object.mesh) return output_error("glTF: object '" + object.name + "' has no mesh");
    const GltfMesh& m = *object.mesh;
    const bool uvs = !m.texcoord1.empty();
    if (object.lightmap && (!uvs || object.lightmap->texture < 0 ||
                            std::size_t(object.lightmap->texture) >= textures.size()))
      return output_error("glTF: receiver '" + object.name + "' has no lightmap UVs or texture");
    Json attributes = {{"POSITION", bin.floats(m.positions, 3, "VEC3")},
                       {"NORMAL", bin.floats(m.normals, 3, "VEC3")}};
    if (uvs) {
      attributes["TEXCOORD_0"] = bin.floats(m.texcoord0, 2, "VEC2");
      attributes["TEXCOORD_1"] = bin.floats(m.texcoord1, 2, "VEC2");
    }
    const int indices = bin.indices(m.indices);
    Json material = {{"name", object.name},
                     {"pbrMetallicRoughness",
                      {{"baseColorFactor", {1.0, 1.0, 1.0, 1.0}},
                       {"metallicFactor", 0.0},
                       {"roughnessFactor", 1.0}}}};
    if (object.lightmap) {
      const GltfLightmap& l = *object.lightmap;
      Json lightmap = {{"index", l.texture}, {"texCoord", 1}, {"intensity", l.intensity}};
      if (l.transform) {
        const auto& t = *l.transform;
        lightmap["extensions"]["KHR_texture_transform"] = {{"offset", {t[2], t[3]}},
                                                           {"scale", {t[0], t[1]}}};
        transformed = true;
      }
      material["extensions"] = {{"MOZ_lightmap", lightmap}};
    }
    materials.push_back(std::move(material));
    meshes.push_back({{"name", object.name},
                      {"primitives",
                       {{{"attributes", attributes},
                         {"indices", indices},
                         {"material", int(r)},
                         {"mode", kTriangles}}}}});
    nodes.push_back({{"name", object.name}, {"mesh", int(r)}});
  }
  bin.align();

  Json scene_nodes = Json::array();
  for (std::size_t i = 0; i < objects.size(); ++i) scene_nodes.push_back(int(i));
  Json extensions_used = {"MOZ_lightmap"};
  if (transformed) extensions_used.push_back("KHR_texture_transform");
  Json gltf = {{"asset",
                {{"version", "2.0"},
                 {"generator", generator},
                 {"extras",
                  {{"shadowbake",
                    {{"quantity", quantity},
                     {"lightmap",
                      "MOZ_lightmap on each material: linear 8-bit values times intensity"}}}}}}},
               {"extensionsUsed", extensions_used},
               {"scene", 0},
               {"scenes", {{{"nodes", scene_nodes}}}},
               {"nodes", nodes},
               {"meshes", meshes},
               {"materials", materials},
               {"textures", gltf_textures},
               {"images", images},
               {"samplers",
                {{{"magFilter", kLinear},
                  {"minFilter", kLinear},
                  {"wrapS", kClampToEdge},
                  {"wrapT", kClampToEdge}}}},
               {"buffers", {{{"byteLength", bin.data().size()}}}},
               {"bufferViews", bin.views()},
               {"accessors", bin.accessors()}};

  std::string json = gltf.dump();
  while (json.size() % 4 != 0) json.push_back(' ');
  const std::size_t total = 12 + 8 + json.size() + 8 + bin.data().size();
  if (total > std::numeric_limits<std::uint32_t>::max())
    return output_error("glTF: the scene's meshes and lightmaps take " + std::to_string(total) +
                        " bytes, more than a .glb holds (4 GiB)");
  std::vector<std::uint8_t> out;
  out.reserve(total);
  append_u32(out, kMagic);
  append_u32(out, 2);
  append_u32(out, std::uint32_t(total));
  append_u32(out, std::uint32_t(json.size()));
  append_u32(out, kJsonChunk);
  out.insert(out.end(), json.begin(), json.end());
  append_u32(out, std::uint32_t(bin.data().size()));
  append_u32(out, kBinChunk);
  out.insert(out.end(), bin.data().begin(), bin.data().end());
  return out;
}

}  // namespace sb
