// The convolution's error-driven hierarchy (convolution_plan.cpp): the exact case needs one
// triple, the worst penumbra error falls as the target falls, clusters' nearest-layer images
// partition the hard shadow, and on the subdivision scenes (table, posts, bracket) the bake
// stays close to the reference, shadows itself and hardens at contact.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include "methods/convolution/blocker_image.h"
#include "methods/convolution/convolution_bake.h"
#include "methods/convolution/convolution_plan.h"
#include "methods/convolution/fft_convolution.h"
#include "occluders/clusters.h"
#include "pipeline/bake.h"
#include "scene/mesh.h"
#include "support/image_errors.h"
#include "support/test_scenes.h"
#include "texels/texel_space.h"

namespace sb {
namespace {

using test_scenes::load;

// The plan of the scene's first receiver, with everything it points into kept alive.
struct Planned {
  std::vector<Mesh> meshes;
  std::vector<const Mesh*> blockers;
  ClusterTree clusters;
  std::vector<Light> lights;
  TexelSpace space;
  ConvolutionPlan plan;
};

std::unique_ptr<Planned> plan_scene(const Scene& scene) {
  auto p = std::make_unique<Planned>();
  for (const auto& obj : scene.objects) p->meshes.push_back(*import_mesh(obj, scene.file));
  for (std::size_t i = 0; i < p->meshes.size(); ++i)
    if (scene.objects[i].blocker) p->blockers.push_back(&p->meshes[i]);
  p->clusters = build_clusters(p->blockers);
  p->lights = *make_lights(scene.lights, scene.file);
  std::size_t receiver = 0;
  while (!scene.objects[receiver].receiver) ++receiver;
  p->space = rasterise_texels(p->meshes[receiver], scene.bake.resolution, scene.bake.resolution);
  PlanInputs in;
  in.lights = &p->lights;
  in.receiver = &p->meshes[receiver];
  in.blockers = p->blockers;
  in.clusters = &p->clusters;
  in.error_texels = setting_number(scene.bake, "error_texels");
  in.max_triples = int(setting_whole(scene.bake, "max_triples"));
  const FftConvolver fft;
  in.backend = &fft;
  p->plan = plan_convolution(p->space, in);
  return p;
}

// Over the texels `a` covers, the first channel.
double rmse(const ReceiverBake& a, const ReceiverBake& b) {
  return image_errors::errors(a, b, {.channel = 0}).rmse;
}

TEST(ConvolutionPlan, ExactCaseNeedsOneTriple) {
  const auto p = plan_scene(load("parallel", 256, "convolution"));
  EXPECT_EQ(p->plan.leaves().size(), 1u) << describe_plan(p->plan);
  EXPECT_NEAR(p->plan.worst_error_texels(), 0.0, 1e-9);
  EXPECT_TRUE(p->plan.warnings.empty());
}

TEST(ConvolutionPlan, WorstErrorFallsAsTheTargetFalls) {
  Scene scene = load("posts", 128, "convolution");
  double previous = std::numeric_limits<double>::infinity();
  std::size_t previous_leaves = 0;
  for (const double target : {32.0, 8.0, 2.0}) {
    set_setting(scene.bake, "error_texels", target);
    const auto p = plan_scene(scene);
    const double worst = p->plan.worst_error_texels();
    std::printf("posts 128^2, error_texels %.0f: %zu leaves, worst eps %.2f texels\n", target,
                p->plan.leaves().size(), worst);
    EXPECT_LT(worst, previous);
    EXPECT_GT(p->plan.leaves().size(), previous_leaves);
    if (p->plan.warnings.empty()) {
      EXPECT_LE(worst, target);
    }
    previous = worst;
    previous_leaves = p->plan.leaves().size();
  }
  // The text a user reads names every split kind it used and the leaves' image sizes.
  const std::string text = describe_plan(plan_scene(scene)->plan);
  EXPECT_NE(text.find("blocker depth"), std::string::npos);
  EXPECT_NE(text.find("image "), std::string::npos);
}

// Two clusters of one layer (near and far slabs of the same geometry) cover disjoint parts of the
// tangent plane that add up to the whole layer's hard shadow.
TEST(ConvolutionPlan, NearestLayersPartitionTheHardShadow) {
  const auto p = plan_scene(load("table", 128, "convolution"));
  const Triple* root = nullptr;
  for (int r : p->plan.frames[0].roots)
    if (!p->plan.triples[std::size_t(r)].empty) root = &p->plan.triples[std::size_t(r)];
  ASSERT_NE(root, nullptr);
  const ProjectedBlockers& layer = *root->layer;
  const double mid = root->blocker_depths.mid();
  std::vector<std::uint8_t> all(layer.polygons.size(), 1);
  TangentGrid grid = root->grid;
  const auto whole = nearest_layer_coverage(layer, all, 0, 1e9, grid);
  const auto near = nearest_layer_coverage(layer, all, 0, mid, grid);
  const auto far = nearest_layer_coverage(layer, all, mid, 1e9, grid);
  const auto union_cov = blocker_coverage(layer, grid);
  double worst = 0, covered = 0;
  for (std::size_t i = 0; i < whole.size(); ++i) {
    worst = std::max(worst, double(std::abs(near[i] + far[i] - whole[i])));
    worst = std::max(worst, double(std::abs(whole[i] - union_cov[i])));
    covered += whole[i];
  }
  EXPECT_GT(covered, 100.0);
  EXPECT_LE(worst, 1e-6);
}

// The posts are convex closed solids: their slabs are capped and every depth split between two
// of a post's slabs has its section leaf, at the split's depth, whose image is the post's
// 8 × 8 cm cross-section seen from the light's centre (by the parity of the surface's crossings,
// so the triangles' shared edges and the far faces must cancel exactly).
TEST(ConvolutionPlan, ConvexSolidsGetTheirSections) {
  const auto p = plan_scene(load("posts", 128, "convolution"));
  const ConvolutionPlan& plan = p->plan;
  int sections = 0;
  for (const Triple& t : plan.triples) {
    if (!t.section) continue;
    ++sections;
    ASSERT_GE(t.parent, 0);
    const Triple& split = plan.triples[std::size_t(t.parent)];
    EXPECT_EQ(split.split, TripleSplit::blocker_depth);
    EXPECT_EQ(t.slab_lo, t.slab_hi);
    EXPECT_EQ(t.slab_lo, plan.triples[std::size_t(split.children[0])].slab_hi);
    ASSERT_TRUE(t.solid_faces);
    ASSERT_GE(t.euler, 0);
    // Every leaf under the solid's top is one of its slabs.
    std::vector<int> below = {t.euler};
    for (std::size_t k = 0; k < below.size(); ++k) {
      const Triple& b = plan.triples[std::size_t(below[k])];
      EXPECT_EQ(b.euler, t.euler);
      if (!b.empty) {
        EXPECT_TRUE(b.solid_faces);
      }
      for (int c : b.children) below.push_back(c);
    }
    const PlanFrame& fr = plan.frames[std::size_t(t.frame)];
    const ProjectedBlockers before =
        project_faces(*t.solid_faces, fr.frame, fr.near, t.slab_lo, ShadowCaster{});
    // On a grid of its own around the crossings (the plan's grid need only reach the footprint's
    // texels, which at 128² may not span the whole section).
    Vec2 lo = Vec2::Constant(1e30), hi = -lo;
    for (const auto& pg : before.polygons) {
      lo = lo.cwiseMin(pg.lo);
      hi = hi.cwiseMax(pg.hi);
    }
    ASSERT_LT(lo.x(), hi.x());
    TangentGrid grid;
    grid.pixel = 1e-3;
    grid.origin = lo - Vec2::Constant(2 * grid.pixel);
    grid.width = int((hi.x() - lo.x()) / grid.pixel) + 4;
    grid.height = int((hi.y() - lo.y()) / grid.pixel) + 4;
    const std::vector<float> image = blocker_coverage(ProjectedBlockers{}, grid, &before);
    double area = 0;
    for (float c : image) area += double(c);
    area *= grid.pixel * grid.pixel;
    // Seen along D = -z from the light's centre, a horizontal 8 cm square at depth d covers
    // (0.08 / d)² of the tangent plane, once per post that reaches the height of depth d.
    ASSERT_NEAR(fr.frame.axis.z(), -1.0, 1e-9);
    const double height = fr.frame.origin.z() - t.slab_lo;
    std::map<std::pair<const Mesh*, int>, double> top;  // per post, its highest vertex
    for (const FaceRef& f : *t.solid_faces) {
      const std::size_t m = std::size_t(std::find(p->blockers.begin(), p->blockers.end(), f.mesh) -
                                        p->blockers.begin());
      const int component = p->clusters.face_component[m][std::size_t(f.face)];
      double& z = top.try_emplace({f.mesh, component}, 0.0).first->second;
      for (auto v : f.mesh->mesh.fv_range(f.mesh->mesh.face_handle(f.face)))
        z = std::max(z, double(f.mesh->mesh.point(v)[2]));
    }
    int posts = 0;
    for (const auto& [post, z] : top) posts += height > 0 && height < z;
    const double expected = posts * std::pow(0.08 / t.slab_lo, 2);
    EXPECT_NEAR(area, expected, 0.03 * expected) << "section at depth " << t.slab_lo;
  }
  EXPECT_GT(sections, 0);
}

// The acceptance figures of docs/methods.md, at 128² to stay fast: RMSE against a 256-sample
// reference on the three subdivision scenes, with the tolerance set from the measured values
// (table 0.0061, posts 0.0236, bracket floor 0.0263 and bracket 0.0140 at 128², with convex
// solids counted by Euler's formula, light parts weighted by irradiance and texels buried under
// the legs and posts dark) plus a margin.
TEST(ConvolutionPlan, SubdivisionScenesAgainstReference) {
  struct Case {
    const char* scene;
    double tolerance;
  };
  for (const Case c : {Case{"table", 0.010}, Case{"posts", 0.030}, Case{"bracket", 0.034}}) {
    Scene conv = load(c.scene, 128, "convolution");
    Scene ref = load(c.scene, 128, "reference");
    ref.bake.samples = 256;
    auto a = bake(conv), b = bake(ref);
    ASSERT_TRUE(a && b);
    for (std::size_t r = 0; r < a->receivers.size(); ++r) {
      const double e = rmse(a->receivers[r], b->receivers[r]);
      std::printf("%s/%s 128^2: convolution vs reference RMSE %.4f\n", c.scene,
                  a->receivers[r].name.c_str(), e);
      EXPECT_LE(e, c.tolerance) << c.scene << "/" << a->receivers[r].name;
    }
  }
}

// The bracket's wall shades its own base: texels of the base's top face far from the wall are
// lit, those beside it darker, in the convolution as in the reference.
TEST(ConvolutionPlan, ObjectShadowsItself) {
  Scene conv = load("bracket", 128, "convolution");
  Scene ref = load("bracket", 128, "reference");
  ref.bake.samples = 128;
  auto a = bake(conv), b = bake(ref);
  ASSERT_TRUE(a && b);
  const ReceiverBake& ca = a->receivers[1];
  const ReceiverBake& rb = b->receivers[1];
  ASSERT_EQ(ca.name, "bracket");
  // Mean visibility over covered texels that the reference puts in shadow (< 0.3).
  double conv_sum = 0, n = 0;
  for (std::size_t i = 0; i < ca.covered.size(); ++i) {
    if (!ca.covered[i] || rb.image.pixels[3 * i] >= 0.3 || rb.image.pixels[3 * i] <= 0) continue;
    conv_sum += ca.image.pixels[3 * i];
    ++n;
  }
  ASSERT_GT(n, 200);
  EXPECT_LT(conv_sum / n, 0.35) << "the bracket's self-shadow is missing";
}

// Contact hardening: a post standing on the floor casts a shadow whose penumbra is sharp at the
// post's foot and widens towards the tip of its shadow, as in the reference, to within two
// texels from 0.2 m past the foot (the acceptance test; nearer the foot see below).
// 10–90 % widths across the shadow, at 512², with a 512-triple budget.
TEST(ConvolutionPlan, PostShadowHardensAtContact) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("sb_contact_hardening_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  {
    // An 8 cm square post 1 m tall standing at x = 0.2 on the 2 x 2 m floor of scenes/parallel.
    std::ofstream obj(dir / "post.obj");
    const double a = 0.04, x0 = 0.2, h = 1.0;
    for (int i = 0; i < 8; ++i)
      obj << "v " << x0 + (i & 1 ? a : -a) << " " << (i & 2 ? a : -a) << " " << (i & 4 ? h : 0)
          << "\n";
    const int quads[6][4] = {{1, 3, 4, 2}, {5, 6, 8, 7}, {1, 2, 6, 5},
                             {3, 7, 8, 4}, {1, 5, 7, 3}, {2, 4, 8, 6}};
    for (const auto& q : quads)
      obj << "f " << q[0] << " " << q[1] << " " << q[2] << "\nf " << q[0] << " " << q[2] << " "
          << q[3] << "\n";
    std::ofstream toml(dir / "scene.toml");
    toml << "[bake]\nresolution = 512\nmargin = 0\nmax_triples = 512\n"
         << "[[object]]\nname = \"floor\"\nmesh = \"" << SB_SOURCE_DIR
         << "/scenes/parallel/floor.obj\"\nblocker = true\n"
         << "[[object]]\nname = \"post\"\nmesh = \"post.obj\"\nreceiver = false\n"
         << "[[light]]\nname = \"panel\"\nshape = \"rectangle\"\nposition = [-0.3, 0, 2]\n"
         << "normal = [0, 0, -1]\nsize = [0.4, 0.4]\npower = 100\n";
  }
  auto scene = load_scene(dir / "scene.toml");
  ASSERT_TRUE(scene) << scene.error().message;
  Scene ref = *scene;
  ref.bake.method = "reference";
  ref.bake.samples = 256;
  // The default, light_parts = 2, and the light whole.
  Scene whole = *scene;
  set_setting(whole.bake, "light_parts", 1);
  auto a = bake(whole), b = bake(ref), h = bake(*scene);
  ASSERT_TRUE(a && b && h);
  const Image& ci = a->receivers[0].image;
  const Image& ri = b->receivers[0].image;
  const Image& hi = h->receivers[0].image;
  const int n = ci.width;
  // Width of the penumbra across the shadow (along y) at floor x: the distance between the
  // 10 % and 90 % crossings on the +y side, linearly interpolated, in texels.
  auto width_at = [&](const Image& img, double x) {
    const int i = int((x + 1) / 2 * n);
    auto v = [&](int j) { return double(img.at(i, j)[0]); };
    auto crossing = [&](double level) {
      for (int j = n / 2; j > 0; --j)  // row 0 is v = 1, i.e. y = +1: walk towards +y
        if (v(j) < level && v(j - 1) >= level) return j - (level - v(j)) / (v(j - 1) - v(j));
      return double(n / 2);
    };
    return std::abs(crossing(0.9) - crossing(0.1));
  };
  // The shadow of the post runs in +x from its foot at x = 0.24 to its tip's image at
  // x = 0.2 + 0.5 · 1/1 ≈ 0.7.
  double previous = 0, previous_halves = 0;
  for (const double x : {0.3, 0.45, 0.6}) {
    const double wc = width_at(ci, x), wr = width_at(ri, x), wh = width_at(hi, x);
    std::printf(
        "post shadow at x = %.2f m: penumbra %.1f texels (convolution), %.1f with "
        "light_parts = 1, %.1f (reference)\n",
        x, wh, wc, wr);
    // Measured (docs/methods.md): 21.2 against 20.0 texels at x = 0.30, 45.2 against 44.7 at
    // 0.45, 55.3 against 54.9 at 0.60 at the default: within the two texels the issue asks for.
    // The slab planes' error, summed over the post's slabs, scales with the light's size: whole,
    // the light gives 22.2, 47.2 and 55.0.
    EXPECT_NEAR(wh, wr, 2.0) << "at x = " << x;
    EXPECT_NEAR(wc, wr, 3.0) << "at x = " << x << " with light_parts = 1";
    EXPECT_GT(wc, previous) << "the penumbra must widen away from the post's foot";
    EXPECT_GT(wh, previous_halves) << "the penumbra must widen away from the post's foot";
    previous = wc;
    previous_halves = wh;
  }
}

// A leaf holding the table's four legs spans the table's whole footprint, though each leg's
// shadow reaches only a few texels from it: its islands are convolved on windows of their own
// (leaf_windows). Linearity makes that exact: the same texture as one grid per leaf, to float
// rounding, for more but much smaller transforms.
TEST(ConvolutionPlan, IslandWindowsChangeNothingButTheWork) {
  const Scene scene = load("table", 256, "convolution");
  const auto p = plan_scene(scene);
  FftConvolver fft;
  ConvolutionInputs in;
  in.plan.lights = &p->lights;
  std::size_t receiver = 0;
  while (!scene.objects[receiver].receiver) ++receiver;
  in.plan.receiver = &p->meshes[receiver];
  in.plan.blockers = p->blockers;
  in.plan.clusters = &p->clusters;
  in.plan.max_triples = int(setting_whole(scene.bake, "max_triples"));
  in.plan.backend = &fft;
  in.fft = &fft;
  std::vector<PairReport> with_reports, without_reports;
  const ConvolutionVisibility with = *bake_convolution(p->space, in, &with_reports);
  in.island_windows = false;
  const ConvolutionVisibility without = *bake_convolution(p->space, in, &without_reports);
  ASSERT_EQ(with.visible.size(), without.visible.size());
  double worst = 0;
  for (std::size_t l = 0; l < with.visible.size(); ++l) {
    ASSERT_EQ(with.visible[l].size(), without.visible[l].size());
    for (std::size_t t = 0; t < with.visible[l].size(); ++t)
      worst = std::max(worst,
                       double((with.visible[l][t] - without.visible[l][t]).cwiseAbs().maxCoeff()));
  }
  EXPECT_LT(worst, 1e-4);
  int with_count = 0, without_count = 0;
  for (const PairReport& r : with_reports) with_count += r.convolutions;
  for (const PairReport& r : without_reports) without_count += r.convolutions;
  EXPECT_GT(with_count, without_count) << "no leaf was cut into windows";
}

}  // namespace
}  // namespace sb
