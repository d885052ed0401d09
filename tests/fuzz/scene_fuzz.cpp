// libFuzzer target for what reads untrusted files: the scene reader (scene_file.cpp), the mesh
// checks and import (mesh_file_checks.cpp, mesh_import.cpp, Assimp behind them), lights, the UV
// rasteriser and the UV layout checks. Built by tests/fuzz/run_fuzz.sh with clang's
// -fsanitize=fuzzer,address,undefined; docs/testing.md says how to run it.
//
// An input is a scene and one mesh file: the first byte chooses the mesh's format (its file
// extension), the bytes up to the first NUL are scene.toml and the rest is the mesh, written as
// mesh.<ext> beside it (a scene naming "mesh.obj" with the OBJ format loads it). Inputs that are
// errors are the point: every one must come back as an Error, never as a crash, a leak or
// undefined behaviour. Assimp itself runs in a child process (mesh_reader.h): what it does wrong
// there comes back as an Error too, so the fuzzer checks that it does, and everything the
// project does with what comes back.
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "scene/lights.h"
#include "scene/mesh.h"
#include "scene/mesh_file_checks.h"
#include "scene/scene.h"
#include "texels/texel_space.h"
#include "texels/uv_checks.h"

namespace {

namespace fs = std::filesystem;

const char* const kExtensions[] = {"obj", "ply", "gltf", "glb", "stl", "fbx", "off", "dae"};

const fs::path& folder() {
  static const fs::path dir = [] {
    const fs::path d =
        fs::temp_directory_path() / ("shadowbake_fuzz_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

void write(const fs::path& path, std::string_view bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(bytes.data(), std::streamsize(bytes.size()));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::string extension = kExtensions[data[0] % std::size(kExtensions)];
  const std::string_view rest(reinterpret_cast<const char*>(data + 1), size - 1);
  const std::size_t split = rest.find('\0');
  const std::string_view scene_text = rest.substr(0, split);
  const std::string_view mesh_bytes =
      split == std::string_view::npos ? std::string_view() : rest.substr(split + 1);

  const fs::path scene_file = folder() / "scene.toml";
  const fs::path mesh_file = folder() / ("mesh." + extension);
  for (const char* ext : kExtensions) fs::remove(folder() / (std::string("mesh.") + ext));
  write(scene_file, scene_text);
  write(mesh_file, mesh_bytes);

  // The mesh on its own, as a receiver reading UV channel 0: the import path whatever the scene.
  sb::ObjectDesc alone;
  alone.name = "mesh";
  alone.mesh = mesh_file;
  sb::ImportLimits limits;
  limits.max_file_bytes = 1 << 20;
  limits.max_memory = std::uint64_t(1) << 30;
  limits.max_seconds = 10;  // under libFuzzer's -timeout
  auto mesh = sb::import_mesh(alone, scene_file, limits);
  if (mesh) {
    const sb::TexelSpace space = sb::rasterise_texels(*mesh, 32, 32);
    (void)sb::uv_layout_warnings(sb::check_uv_layout(*mesh, space, 2));
  }

  // The scene, and what it names.
  auto scene = sb::load_scene(scene_file);
  if (!scene) return 0;
  for (const sb::ObjectDesc& obj : scene->objects) {
    auto m = sb::import_mesh(obj, scene_file, limits);
    if (!m) continue;
    const int resolution = std::min(scene->bake.resolution, 32);
    const sb::TexelSpace space = sb::rasterise_texels(*m, resolution, resolution);
    (void)sb::check_uv_layout(*m, space, std::min(scene->bake.margin, 4));
  }
  (void)sb::make_lights(scene->lights, scene_file);
  return 0;
}
