// The fixture and helpers of the mesh import tests (mesh_import_test.cpp,
// mesh_import_rejects_test.cpp, example_scene_meshes_test.cpp): a fresh folder per test to write
// mesh files into, an object description for them, and the mesh's points and normals as Vec3.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include <unistd.h>

#include "scene/mesh.h"

namespace sb::mesh_import_test {

namespace fs = std::filesystem;

// Scale, then rotate about X, Y, Z (degrees), then translate: the scene format's object transform,
// built here so these tests do not depend on the scene reader.
inline Affine3 make_transform(const Vec3& translate, const Vec3& rotate_deg, const Vec3& scale) {
  const double to_rad = std::numbers::pi / 180.0;
  Affine3 t = Affine3::Identity();
  t.translate(translate);
  t.rotate(Eigen::AngleAxisd(rotate_deg.z() * to_rad, Vec3::UnitZ()));
  t.rotate(Eigen::AngleAxisd(rotate_deg.y() * to_rad, Vec3::UnitY()));
  t.rotate(Eigen::AngleAxisd(rotate_deg.x() * to_rad, Vec3::UnitX()));
  t.scale(scale);
  return t;
}

inline Vec3 point(const TriMesh& mesh, TriMesh::VertexHandle v) {
  const auto& p = mesh.point(v);
  return Vec3(p[0], p[1], p[2]);
}

inline Vec3 normal(const TriMesh& mesh, TriMesh::VertexHandle v) {
  const auto& n = mesh.normal(v);
  return Vec3(n[0], n[1], n[2]);
}

inline Vec3 face_normal(const TriMesh& mesh, TriMesh::FaceHandle f) {
  const auto& n = mesh.normal(f);
  return Vec3(n[0], n[1], n[2]);
}

// True when mesh has a vertex at p (within tolerance).
inline bool has_point(const TriMesh& mesh, const Vec3& p, double tolerance = 1e-6) {
  for (auto v : mesh.vertices()) {
    if ((point(mesh, v) - p).norm() < tolerance) return true;
  }
  return false;
}

// Each test writes its meshes into a fresh folder of its own.
class MeshImport : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("shadowbake_mesh_import_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::string& name, const std::string& text) {
    const fs::path file = dir_ / name;
    std::ofstream(file, std::ios::binary) << text;
    return file;
  }

  ObjectDesc object(const fs::path& mesh, bool receiver = true) {
    ObjectDesc obj;
    obj.name = "thing";
    obj.mesh = mesh;
    obj.receiver = receiver;
    obj.line = 7;
    return obj;
  }

  fs::path scene_file() const { return dir_ / "scene.toml"; }

  fs::path dir_;
};

// A unit quad in z = 0 (two triangles), normals +z, UVs (x, y).
inline constexpr const char* kQuadObj = R"(v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
f 1/1/1 2/2/1 3/3/1
f 1/1/1 3/3/1 4/4/1
)";

}  // namespace sb::mesh_import_test
