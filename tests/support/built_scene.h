// A scene's meshes, lights, blocker meshes, ray scene and shaft culler, built as the bake builds
// them (pipeline/receiver_stages.h: load_meshes, placed_lights, blocker_meshes), for tests that
// call one stage of a method on one receiver's texel space.
#pragma once

#include <optional>
#include <stdexcept>
#include <vector>

#include "occluders/ray_scene.h"
#include "occluders/shaft_culling.h"
#include "pipeline/receiver_stages.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "scene/scene.h"

namespace sb::test_scenes {

struct Built {
  std::vector<Mesh> meshes;  // every object's, in scene order
  std::vector<Light> lights;
  std::vector<const Mesh*> blockers;
  std::optional<RayScene> rays;
  std::optional<ShaftCuller> culler;
  explicit Built(const Scene& scene) {
    auto loaded = load_meshes(scene, nullptr);
    if (!loaded) throw std::runtime_error(loaded.error().message);
    meshes = std::move(*loaded);
    auto made = make_lights(placed_lights(scene, meshes), scene.file);
    if (!made) throw std::runtime_error(made.error().message);
    lights = std::move(*made);
    blockers = blocker_meshes(scene, meshes);
    auto built = RayScene::build(blockers);
    if (!built) throw std::runtime_error(built.error().message);
    rays.emplace(std::move(*built));
    culler.emplace(blockers);
  }
};

}  // namespace sb::test_scenes
