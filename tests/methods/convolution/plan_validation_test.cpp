// validate (plan_validation.cpp): the plans of every bundled scene hold the plan's invariants, as
// `shadowbake plan` makes them, and a plan corrupted in one place is refused with a message that
// names what broke.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "methods/convolution/convolution_plan.h"
#include "methods/convolution/fft_convolution.h"
#include "methods/convolution/traced_convolution.h"
#include "methods/method.h"
#include "occluders/clusters.h"
#include "scene/mesh.h"
#include "scene/scene.h"
#include "support/test_scenes.h"
#include "texels/texel_space.h"

namespace sb {
namespace {

namespace fs = std::filesystem;

// Every receiver's plan of a scene, made with the inputs `shadowbake plan` gives the planner,
// with everything the plans point into kept alive.
struct ScenePlans {
  Scene scene;
  std::vector<Mesh> meshes;
  ClusterTree clusters;
  std::vector<Light> lights;
  std::vector<std::unique_ptr<TexelSpace>> spaces;
  std::vector<ConvolutionPlan> plans;
};

std::unique_ptr<ScenePlans> plan_receivers(const Scene& scene) {
  auto p = std::make_unique<ScenePlans>();
  p->scene = scene;
  for (const auto& obj : scene.objects) {
    auto mesh = import_mesh(obj, scene.file);
    EXPECT_TRUE(mesh) << mesh.error().message;
    if (!mesh) return p;
    p->meshes.push_back(std::move(*mesh));
  }
  BakeContext context;
  context.scene = &p->scene;
  for (std::size_t i = 0; i < p->meshes.size(); ++i)
    if (scene.objects[i].blocker) context.blockers.push_back(&p->meshes[i]);
  p->clusters = build_clusters(context.blockers);
  context.clusters = &p->clusters;
  p->lights = *make_lights(scene.lights, scene.file);
  context.lights = &p->lights;
  const FftConvolver fft;
  for (std::size_t i = 0; i < p->meshes.size(); ++i) {
    if (!scene.objects[i].receiver) continue;
    p->spaces.push_back(std::make_unique<TexelSpace>(
        rasterise_texels(p->meshes[i], scene.bake.resolution, scene.bake.resolution)));
    p->plans.push_back(plan_convolution(
        *p->spaces.back(),
        plan_inputs(context, convolution_settings(context.scene->bake), &p->meshes[i], &fft)));
  }
  return p;
}

TEST(PlanValidation, EveryBundledScenesPlansValidate) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(fs::path(SB_SOURCE_DIR) / "scenes"))
    if (fs::exists(entry.path() / "scene.toml")) files.push_back(entry.path() / "scene.toml");
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 10u);
  std::size_t plans = 0;
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.string());
    const auto scene = load_scene(file);
    ASSERT_TRUE(scene) << scene.error().message;
    const auto p = plan_receivers(*scene);
    for (const ConvolutionPlan& plan : p->plans) {
      const Status valid = validate(plan, p->lights.size());
      EXPECT_TRUE(valid) << valid.error().message;
      ++plans;
    }
  }
  EXPECT_GE(plans, files.size());
}

// The posts' plan has depth and space splits, convex solids' sections and Euler heads.
class CorruptedPlan : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    planned_ = plan_receivers(test_scenes::load("posts", 128, "convolution")).release();
  }
  static void TearDownTestSuite() {
    delete planned_;
    planned_ = nullptr;
  }

  const ConvolutionPlan& plan() const { return planned_->plans.front(); }
  std::size_t lights() const { return planned_->lights.size(); }
  // The first triple for which `want` holds.
  template <class F>
  std::size_t first(F&& want) const {
    for (std::size_t i = 0; i < plan().triples.size(); ++i)
      if (want(plan().triples[i])) return i;
    ADD_FAILURE() << "no such triple";
    return 0;
  }
  std::size_t a_split() const {
    return first([](const Triple& t) { return t.split == TripleSplit::blocker_depth; });
  }
  std::size_t a_leaf() const {
    return first([](const Triple& t) { return t.children.empty() && !t.empty && !t.section; });
  }
  void expect_refused(const ConvolutionPlan& corrupted, const std::string& words) const {
    const Status valid = validate(corrupted, lights());
    ASSERT_FALSE(valid) << "accepted a plan with " << words;
    EXPECT_NE(valid.error().message.find(words), std::string::npos) << valid.error().message;
    EXPECT_NE(valid.error().message.find("receiver 'floor'"), std::string::npos)
        << valid.error().message;
  }

  static ScenePlans* planned_;
};

ScenePlans* CorruptedPlan::planned_ = nullptr;

TEST_F(CorruptedPlan, UncorruptedIsAccepted) {
  ASSERT_EQ(plan().receiver, "floor");
  const Status valid = validate(plan(), lights());
  EXPECT_TRUE(valid) << valid.error().message;
  EXPECT_TRUE(std::any_of(plan().triples.begin(), plan().triples.end(),
                          [](const Triple& t) { return t.section; }));
}

TEST_F(CorruptedPlan, RefusesAChildNamingAnotherParent) {
  ConvolutionPlan p = plan();
  const std::size_t split = a_split();
  const std::size_t child = std::size_t(p.triples[split].children[0]);
  p.triples[child].parent = split == 0 ? 1 : 0;
  expect_refused(p, "names another parent");
}

TEST_F(CorruptedPlan, RefusesAChildOutOfRange) {
  ConvolutionPlan p = plan();
  p.triples[a_split()].children[1] += int(p.triples.size());
  expect_refused(p, "does not come after it");
}

TEST_F(CorruptedPlan, RefusesASplitIntoOnePart) {
  ConvolutionPlan p = plan();
  Triple& split = p.triples[a_split()];
  split.children.erase(split.children.begin());
  expect_refused(p, "a split into 1 parts");
}

TEST_F(CorruptedPlan, RefusesATripleOfNoFrame) {
  ConvolutionPlan p = plan();
  p.triples[a_leaf()].frame = int(p.frames.size());
  expect_refused(p, "frame");
}

TEST_F(CorruptedPlan, RefusesAGroupTexelOutOfRange) {
  ConvolutionPlan p = plan();
  p.frames[0].groups[0].front() = int(p.frames[0].texels.size());
  expect_refused(p, "group 0: texel");
}

TEST_F(CorruptedPlan, RefusesATexelIndexMissingTexels) {
  ConvolutionPlan p = plan();
  p.frames[0].index[0].items.pop_back();
  expect_refused(p, "texel index");
}

TEST_F(CorruptedPlan, RefusesAFrameOfAnotherLight) {
  ConvolutionPlan p = plan();
  p.frames[0].light += 1;
  expect_refused(p, "its light is not its light part's");
}

TEST_F(CorruptedPlan, RefusesALightPartOfNoLight) {
  ConvolutionPlan p = plan();
  p.light_parts[0].light = int(lights());
  expect_refused(p, "light part 0");
}

TEST_F(CorruptedPlan, RefusesATransformSmallerThanItsImage) {
  ConvolutionPlan p = plan();
  Triple& leaf = p.triples[a_leaf()];
  leaf.fft_width = leaf.grid.width - 1;
  expect_refused(p, "smaller than its image");
}

TEST_F(CorruptedPlan, RefusesALeafWithoutItsLayer) {
  ConvolutionPlan p = plan();
  p.triples[a_leaf()].layer.reset();
  expect_refused(p, "layer");
}

TEST_F(CorruptedPlan, RefusesAPolygonOfNoFace) {
  ConvolutionPlan p = plan();
  Triple& leaf = p.triples[a_leaf()];
  leaf.blockers.polygons.front().source = int(leaf.faces.size());
  expect_refused(p, "a polygon of face");
}

TEST_F(CorruptedPlan, RefusesASplitWithoutChildren) {
  ConvolutionPlan p = plan();
  p.triples[a_leaf()].split = TripleSplit::blocker_space;
  expect_refused(p, "a split without children");
}

TEST_F(CorruptedPlan, RefusesSlabsThatDoNotDivideTheirSplit) {
  ConvolutionPlan p = plan();
  const Triple& split = p.triples[a_split()];
  p.triples[std::size_t(split.children[0])].slab_hi += 1e-3;
  expect_refused(p, "slabs do not divide");
}

TEST_F(CorruptedPlan, RefusesASectionAwayFromItsSplit) {
  ConvolutionPlan p = plan();
  Triple& section = p.triples[first([](const Triple& t) { return t.section; })];
  section.slab_lo = section.slab_hi = section.slab_hi + 1e-3;
  expect_refused(p, "a section away from its split's depth");
}

TEST_F(CorruptedPlan, RefusesAnEulerHeadAfterItsTriple) {
  ConvolutionPlan p = plan();
  p.triples[first([](const Triple& t) { return t.euler >= 0; })].euler = int(p.triples.size());
  expect_refused(p, "Euler head");
}

}  // namespace
}  // namespace sb
