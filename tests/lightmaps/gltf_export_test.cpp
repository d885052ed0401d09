// Tests of the glTF binary writer (src/lightmaps/gltf_export.h), read back byte by byte: the
// header and chunks, positions turned Y up from a Z-up world and kept in a Y-up one, lightmap UVs
// as TEXCOORD_1 with v flipped (which a render cannot tell from the expected values, since both
// read the same UVs), texture UVs as TEXCOORD_0, MOZ_lightmap with its atlas transform, and a
// blocker without UVs or lightmap. tests/web/ checks the same files with the Khronos validator and
// in three.js.
#include "lightmaps/gltf_export.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstring>

namespace sb {
namespace {

using json = nlohmann::json;

std::uint32_t u32(const std::vector<std::uint8_t>& b, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, &b[at], 4);
  return v;
}

// A triangle at z = 1 with distinct lightmap and texture UVs.
Mesh triangle_mesh() {
  Mesh mesh;
  mesh.has_uv = true;
  const double p[3][3] = {{0, 0, 1}, {2, 0, 1}, {0, 3, 1}};
  const double uv[3][2] = {{0.1, 0.2}, {0.7, 0.2}, {0.1, 0.9}};
  TriMesh::VertexHandle v[3];
  for (int i = 0; i < 3; ++i) {
    v[i] = mesh.mesh.add_vertex(TriMesh::Point(p[i][0], p[i][1], p[i][2]));
    mesh.mesh.set_normal(v[i], TriMesh::Normal(0, 0, 1));
    mesh.mesh.set_texcoord2D(v[i], TriMesh::TexCoord2D(uv[i][0], uv[i][1]));
    mesh.texture_uv.push_back(Vec2(uv[i][1], uv[i][0]));  // swapped: not the lightmap's
  }
  mesh.mesh.add_face(v[0], v[1], v[2]);
  return mesh;
}

struct Glb {
  json gltf;
  std::vector<std::uint8_t> bin;

  // Accessor `index`'s floats.
  std::vector<float> floats(int index) const {
    const json& a = gltf["accessors"][std::size_t(index)];
    const json& v = gltf["bufferViews"][a["bufferView"].get<std::size_t>()];
    const std::size_t n = a["count"].get<std::size_t>() * (a["type"] == "VEC3" ? 3 : 2);
    std::vector<float> out(n);
    std::memcpy(out.data(), &bin[v["byteOffset"].get<std::size_t>()], n * 4);
    return out;
  }
};

Glb parse(const std::vector<std::uint8_t>& bytes) {
  Glb glb;
  EXPECT_EQ(u32(bytes, 0), 0x46546C67u);  // "glTF"
  EXPECT_EQ(u32(bytes, 4), 2u);
  EXPECT_EQ(u32(bytes, 8), bytes.size());
  const std::uint32_t json_length = u32(bytes, 12);
  EXPECT_EQ(u32(bytes, 16), 0x4E4F534Au);  // "JSON"
  EXPECT_EQ(json_length % 4, 0u);
  glb.gltf = json::parse(bytes.begin() + 20, bytes.begin() + 20 + json_length);
  const std::size_t bin_at = 20 + json_length;
  const std::uint32_t bin_length = u32(bytes, bin_at);
  EXPECT_EQ(u32(bytes, bin_at + 4), 0x004E4942u);  // "BIN\0"
  EXPECT_EQ(bin_length % 4, 0u);
  EXPECT_EQ(bin_at + 8 + bin_length, bytes.size());
  glb.bin.assign(bytes.begin() + std::ptrdiff_t(bin_at + 8), bytes.end());
  return glb;
}

TEST(GltfExport, ReceiverWithAtlasAndBlocker) {
  const Mesh mesh = triangle_mesh();
  const GltfMesh receiver = gltf_mesh(mesh), blocker = gltf_mesh(mesh, false);
  GltfLightmap lightmap;
  lightmap.texture = 0;
  lightmap.intensity = 2.5;
  lightmap.transform = std::array<double, 4>{0.25, 0.25, 0.5, 0.125};
  const std::vector<GltfObject> objects = {{"floor", &receiver, lightmap},
                                           {"torus", &blocker, std::nullopt}};
  const std::vector<GltfTexture> textures = {{"lightmap_0", {0x89, 'P', 'N', 'G', 1, 2, 3}}};
  auto bytes = glb_bytes(objects, textures, "visibility", "shadowbake test");
  ASSERT_TRUE(bytes) << bytes.error().message;
  const Glb glb = parse(*bytes);
  const json& g = glb.gltf;

  EXPECT_EQ(g["asset"]["version"], "2.0");
  EXPECT_EQ(g["extensionsUsed"], json({"MOZ_lightmap", "KHR_texture_transform"}));
  for (const json& view : g["bufferViews"]) EXPECT_EQ(view["byteOffset"].get<int>() % 4, 0);

  // The receiver: Y up, UVs with v down, the lightmap bound to TEXCOORD_1 with its rectangle.
  const json& floor = g["meshes"][0]["primitives"][0];
  const std::vector<float> positions = glb.floats(floor["attributes"]["POSITION"]);
  EXPECT_EQ(positions, (std::vector<float>{0, 1, 0, 2, 1, 0, 0, 1, -3}));
  const std::vector<float> lightmap_uv = glb.floats(floor["attributes"]["TEXCOORD_1"]);
  const std::vector<float> texture_uv = glb.floats(floor["attributes"]["TEXCOORD_0"]);
  const float expected_lightmap[6] = {0.1f, 0.8f, 0.7f, 0.8f, 0.1f, 0.1f};
  const float expected_texture[6] = {0.2f, 0.9f, 0.2f, 0.3f, 0.9f, 0.9f};
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(lightmap_uv[std::size_t(i)], expected_lightmap[i], 1e-6) << i;
    EXPECT_NEAR(texture_uv[std::size_t(i)], expected_texture[i], 1e-6) << i;
  }
  const json& material = g["materials"][floor["material"].get<std::size_t>()];
  const json& moz = material["extensions"]["MOZ_lightmap"];
  EXPECT_EQ(moz["index"], 0);
  EXPECT_EQ(moz["texCoord"], 1);
  EXPECT_EQ(moz["intensity"], 2.5);
  EXPECT_EQ(moz["extensions"]["KHR_texture_transform"]["offset"], json({0.5, 0.125}));
  EXPECT_EQ(moz["extensions"]["KHR_texture_transform"]["scale"], json({0.25, 0.25}));
  EXPECT_EQ(g["images"][0]["mimeType"], "image/png");
  EXPECT_EQ(g["samplers"][0]["minFilter"], 9729);  // LINEAR: no mip-maps across an atlas

  // The blocker: positions and normals, no UVs, no lightmap.
  const json& torus = g["meshes"][1]["primitives"][0];
  EXPECT_FALSE(torus["attributes"].contains("TEXCOORD_0"));
  EXPECT_FALSE(torus["attributes"].contains("TEXCOORD_1"));
  EXPECT_FALSE(g["materials"][torus["material"].get<std::size_t>()].contains("extensions"));
  EXPECT_EQ(g["nodes"][1]["name"], "torus");
}

// A scene file's world is Z up and turned; a level's is glTF's own Y up and kept as it is.
TEST(GltfExport, AZUpWorldIsTurnedAndAYUpWorldKept) {
  const GltfMesh turned = gltf_mesh(triangle_mesh());
  const GltfMesh kept = gltf_mesh(triangle_mesh(), true, true);
  EXPECT_EQ(turned.positions, (std::vector<float>{0, 1, 0, 2, 1, 0, 0, 1, -3}));
  EXPECT_EQ(turned.normals, (std::vector<float>{0, 1, 0, 0, 1, 0, 0, 1, 0}));
  EXPECT_EQ(kept.positions, (std::vector<float>{0, 0, 1, 2, 0, 1, 0, 3, 1}));
  EXPECT_EQ(kept.normals, (std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1}));
}

TEST(GltfExport, RefusesAReceiverWithoutLightmapUvs) {
  const GltfMesh no_uvs = gltf_mesh(triangle_mesh(), false);
  const std::vector<GltfObject> objects = {{"floor", &no_uvs, GltfLightmap{}}};
  auto bytes = glb_bytes(objects, {{"t", {1, 2, 3, 4}}}, "visibility", "test");
  ASSERT_FALSE(bytes);
  EXPECT_NE(bytes.error().message.find("'floor' has no lightmap UVs"), std::string::npos);
}

}  // namespace
}  // namespace sb
