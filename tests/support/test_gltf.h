// A minimal reader of glTF 2.0 binaries (.glb) for tests: the triangles of every mesh primitive
// with their positions and one TEXCOORD set, read straight from the file's accessors (node
// transforms ignored). Independent of Assimp, so tests can compare what import_mesh makes of a
// file with what the file itself holds (Khronos glTF 2.0 specification, sections 3.6-3.7 and 4.4).
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/geometry.h"

namespace sb::test_gltf {

struct SoupTriangle {
  Vec3 p[3];
  Vec2 uv[3];  // (u, v) with v up: 1 - the file's t
};

inline std::vector<SoupTriangle> read_triangles(const std::string& path, int texcoord) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto u32 = [&](std::size_t at) {
    std::uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  if (bytes.size() < 20 || bytes.compare(0, 4, "glTF") != 0) throw std::runtime_error(path);
  const std::uint32_t json_length = u32(12);
  const nlohmann::json gltf = nlohmann::json::parse(bytes.substr(20, json_length));
  const std::size_t bin = 20 + json_length + 8;  // the BIN chunk's data
  const auto element = [&](int accessor, std::size_t i, int component) -> double {
    const auto& a = gltf["accessors"][accessor];
    const auto& view = gltf["bufferViews"][a["bufferView"].get<int>()];
    const int type = a["componentType"];
    const std::size_t size = type == 5126 || type == 5125 ? 4 : type == 5123 ? 2 : 1;
    const std::size_t components = a["type"] == "SCALAR" ? 1 : a["type"] == "VEC2" ? 2 : 3;
    const std::size_t stride = view.value("byteStride", size * components);
    const std::size_t at = bin + view.value("byteOffset", std::size_t(0)) +
                           a.value("byteOffset", std::size_t(0)) + i * stride + component * size;
    if (type == 5126) {
      float f;
      std::memcpy(&f, bytes.data() + at, 4);
      return f;
    }
    if (type == 5125) return u32(at);
    if (type == 5123) {
      std::uint16_t s;
      std::memcpy(&s, bytes.data() + at, 2);
      return s;
    }
    return static_cast<unsigned char>(bytes[at]);
  };
  std::vector<SoupTriangle> out;
  for (const auto& mesh : gltf["meshes"]) {
    for (const auto& primitive : mesh["primitives"]) {
      const int position = primitive["attributes"]["POSITION"];
      const int uv = primitive["attributes"]["TEXCOORD_" + std::to_string(texcoord)];
      const int indices = primitive["indices"];
      const std::size_t count = gltf["accessors"][indices]["count"];
      for (std::size_t t = 0; t + 2 < count; t += 3) {
        SoupTriangle tri;
        for (int k = 0; k < 3; ++k) {
          const auto v = std::size_t(element(indices, t + k, 0));
          tri.p[k] =
              Vec3(element(position, v, 0), element(position, v, 1), element(position, v, 2));
          tri.uv[k] = Vec2(element(uv, v, 0), 1.0 - element(uv, v, 1));
        }
        out.push_back(tri);
      }
    }
  }
  return out;
}

}  // namespace sb::test_gltf
