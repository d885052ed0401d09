// A scene baked in-process with a method and its settings overridden, for tests that compare
// methods on one scene (the random scenes' stress tests). Margins off: errors over covered
// texels only.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "pipeline/bake.h"
#include "scene/scene.h"

namespace sb {

inline BakeResult bake_with(Scene scene, const std::string& method, int samples, bool trace,
                            std::uint64_t seed = 0) {
  scene.bake.method = method;
  scene.bake.samples = samples;
  set_setting(scene.bake, "trace", trace);
  scene.bake.seed = seed;
  scene.bake.margin = 0;
  auto result = bake(scene);
  EXPECT_TRUE(result) << result.error().message;
  return result ? std::move(*result) : BakeResult{};
}

}  // namespace sb
