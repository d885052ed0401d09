// The bundled scenes as the bake tests use them: loaded from scenes/, with the resolution and
// method a test asks for and no margin (so every texel compared is a covered one), and lookup of
// an object by name to move it.
#pragma once

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "scene/scene.h"

namespace sb::test_scenes {

inline Scene load(const std::string& name, int resolution, const std::string& method) {
  auto scene = load_scene(std::string(SB_SOURCE_DIR) + "/scenes/" + name + "/scene.toml");
  EXPECT_TRUE(scene) << scene.error().message;
  if (!scene) throw std::runtime_error(scene.error().message);
  scene->bake.resolution = resolution;
  scene->bake.method = method;
  scene->bake.margin = 0;
  // The convolution itself: without the rays that take over where it cannot vouch for its
  // values (traced_convolution.h), which its own tests are not about.
  set_setting(scene->bake, "trace", false);
  return *scene;
}

// A sphere light as the tests add one by hand.
inline LightDesc sphere_light(const std::string& name, const Vec3& position, double radius,
                              double power) {
  LightDesc light;
  light.name = name;
  light.shape = LightShape::sphere;
  light.position = position;
  light.radius = radius;
  light.power = power;
  return light;
}

inline ObjectDesc& object(Scene& scene, const std::string& name) {
  for (auto& o : scene.objects)
    if (o.name == name) return o;
  throw std::runtime_error("no object " + name);
}

}  // namespace sb::test_scenes
