// A sphere light inside its fixture (piercing_blockers.h): OpenArena's flames are two crossed
// quads through the light's centre. The reference's rays end on the sphere's near side, which the
// quads hide only in part; the default method must agree with it, where taking the quads whole
// hid the silhouette's disk behind them (a floor 0.6 darker than the reference).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "pipeline/bake.h"
#include "support/image_errors.h"

namespace sb {
namespace {

namespace fs = std::filesystem;

TEST(PiercingBlockers, ALightInsideCrossedQuadsBakesAsTheReference) {
  const fs::path dir = fs::temp_directory_path() / ("sb_piercing_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  // A 6 × 6 m floor with UVs over it; a flame of two 1 m quads crossed through (0.3, 0, 1.2),
  // the light's centre, tilted a little so that nothing is axis-aligned.
  std::ofstream(dir / "floor.obj") << "v -3 -3 0\nv 3 -3 0\nv 3 3 0\nv -3 3 0\n"
                                      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                      "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
  std::ofstream(dir / "flame.obj") << "v -0.2 -0.05 0.7\nv 0.8 0.05 0.7\nv 0.8 0.05 1.7\n"
                                      "v -0.2 -0.05 1.7\n"
                                      "v 0.35 -0.5 0.7\nv 0.25 0.5 0.7\nv 0.25 0.5 1.7\n"
                                      "v 0.35 -0.5 1.7\n"
                                      "f 1 2 3\nf 1 3 4\nf 5 6 7\nf 5 7 8\n";
  std::ofstream(dir / "scene.toml")
      << "[bake]\nresolution = 48\nmargin = 0\n"
         "[[object]]\nname = \"floor\"\nmesh = \"floor.obj\"\nblocker = false\n"
         "[[object]]\nname = \"flame\"\nmesh = \"flame.obj\"\nreceiver = false\n"
         "[[light]]\nname = \"torch\"\nshape = \"sphere\"\nposition = [0.3, 0, 1.2]\n"
         "radius = 0.25\npower = 100\n";
  auto scene = load_scene(dir / "scene.toml");
  ASSERT_TRUE(scene) << scene.error().message;
  Scene truth = *scene;
  truth.bake.method = "reference";
  truth.bake.samples = 4096;
  auto ours = bake(*scene), reference = bake(truth);
  fs::remove_all(dir);
  ASSERT_TRUE(ours && reference);
  const image_errors::Errors e = image_errors::errors(*ours, *reference);
  std::printf("a light inside crossed quads: RMSE %.4f, max %.4f against the reference at 4096\n",
              e.rmse, e.max);
  EXPECT_LT(e.rmse, 0.01);
  EXPECT_LT(e.max, 0.06);
}

}  // namespace
}  // namespace sb
