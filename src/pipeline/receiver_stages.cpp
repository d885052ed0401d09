// The stages of a bake around the method (receiver_stages.h).
#include "pipeline/receiver_stages.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <optional>

#include "core/stopwatch.h"
#include "lightmaps/shadowmask.h"
#include "pipeline/memory_budget.h"
#include "scene/mesh_reader.h"
#include "scene/sky.h"
#include "scene/sun_light.h"
#include "texels/auto_uv.h"
#include "texels/lightmap_sizes.h"
#include "texels/seams.h"

namespace sb {

namespace {

// The covered texels whose value means nothing, for the seams' stitching (texels/seams.h): in a
// visibility, those none of the lights reaches (V = H / H0 with H0 = 0, written 0): every light,
// or those that make up scene light `output`. None for an irradiance, which is 0 there in truth.
std::vector<std::uint8_t> arbitrary_texels(bool visibility, const TexelSpace& space,
                                           const std::vector<Light>& lights,
                                           const LightLists& lists,
                                           std::optional<std::size_t> output = std::nullopt) {
  std::vector<std::uint8_t> arbitrary;
  if (!visibility) return arbitrary;
  const auto decide = [&](const Texel& t) {
    const Vec3 y = t.position.cast<double>(), n = t.normal.cast<double>();
    // Its block's lights: the others reach none of its texels.
    const auto listed = lists.lights_of(lists.block_of(t.x, t.y));
    const bool reached = std::any_of(listed.begin(), listed.end(), [&](std::uint32_t l) {
      return (!output || std::size_t(lights[l].output()) == *output) && lights[l].reaches(y, n);
    });
    arbitrary[std::size_t(t.y) * std::size_t(space.width) + std::size_t(t.x)] = !reached;
  };
  if (!output) {
    arbitrary.assign(space.covered.size(), 0);
    for (const Texel& t : space.texels) decide(t);
    return arbitrary;
  }
  // One scene light's: every covered texel but those of the blocks its parts' lists give it.
  arbitrary = space.covered;
  std::vector<std::uint32_t> blocks;
  for (std::size_t l = 0; l < lights.size(); ++l)
    if (std::size_t(lights[l].output()) == *output) {
      const auto mine = lists.blocks_of(l);
      blocks.insert(blocks.end(), mine.begin(), mine.end());
    }
  std::sort(blocks.begin(), blocks.end());
  blocks.erase(std::unique(blocks.begin(), blocks.end()), blocks.end());
  constexpr int side = LightLists::kSide;
  for (const std::uint32_t b : blocks) {
    const int x0 = int(b % std::uint32_t(lists.blocks_x())) * side;
    const int y0 = int(b / std::uint32_t(lists.blocks_x())) * side;
    for (int y = y0; y < std::min(y0 + side, space.height); ++y) {
      // The row's texels in the block (texels are in row-major order).
      auto t = std::lower_bound(space.texels.begin(), space.texels.end(), std::pair(y, x0),
                                [](const Texel& a, const std::pair<int, int>& key) {
                                  return std::pair<int, int>(a.y, a.x) < key;
                                });
      for (; t != space.texels.end() && t->y == y && t->x < x0 + side; ++t) decide(*t);
    }
  }
  return arbitrary;
}

// What a seam's lookup difference is measured against (SeamReport): 1 for a visibility, the
// image's largest value for an irradiance (1 where it is black).
double seam_scale(const Scene& scene, const Image& image) {
  if (scene.bake.quantity != Quantity::irradiance || image.pixels.empty()) return 1.0;
  const float largest = *std::max_element(image.pixels.begin(), image.pixels.end());
  return largest > 0 ? double(largest) : 1.0;
}

}  // namespace

// Every object's mesh, in scene order; skipped degenerate triangles become warnings. A mesh file
// may be a quarter of the memory budget, and its reader may use half of it: Assimp's scene and
// the working mesh take several times the file's size. A file that several objects share (a
// level's nodes) is read once and kept until its last object is built. A receiver with
// uv = "auto" gets its lightmap UVs here, packed for the side it will have.
Expected<std::vector<Mesh>> load_meshes(const Scene& scene, std::vector<std::string>* warnings) {
  std::vector<Mesh> meshes;
  meshes.reserve(scene.objects.size());
  ImportLimits limits;
  limits.max_file_bytes = memory_budget(scene.bake) / 4;
  limits.max_memory = memory_budget(scene.bake) / 2;
  std::map<std::filesystem::path, std::size_t> users;
  for (const auto& obj : scene.objects) ++users[obj.mesh];
  std::map<std::filesystem::path, std::shared_ptr<const RawMeshFile>> read;
  for (const auto& obj : scene.objects) {
    std::shared_ptr<const RawMeshFile>& file = read[obj.mesh];
    if (!file) {
      auto raw = read_object_file(obj, scene.file, limits);
      if (!raw) return raw.error();
      file = std::move(*raw);
    }
    auto mesh = build_object_mesh(obj, *file, scene.file);
    if (--users[obj.mesh] == 0) read.erase(obj.mesh);
    if (!mesh) return mesh.error();
    if (mesh->skipped_degenerate > 0 && warnings) {
      warnings->push_back(object_location(scene.file, obj) + ": skipped " +
                          std::to_string(mesh->skipped_degenerate) +
                          " degenerate (zero-area) triangles");
    }
    if (mesh->split_nonmanifold > 0 && warnings) {
      warnings->push_back(fmt::format(
          "{}: {} triangle(s) meet others at an edge or vertex no 2-manifold has (three or more "
          "faces on an edge, or a vertex whose faces do not form one fan); each was kept on "
          "copies of its corners, which bakes it as it is but leaves its edges unshared",
          object_location(scene.file, obj), mesh->split_nonmanifold));
    }
    if (obj.auto_uv && obj.receiver) {
      AutoUvTarget target;
      target.margin = scene.bake.margin;
      target.max_side = largest_lightmap_side(scene);
      if (scene.bake.texels_per_metre > 0)
        target.texels_per_metre = scene.bake.texels_per_metre * obj.lightmap_scale;
      else
        target.side = std::min(scene.bake.resolution, target.max_side);
      if (auto made = generate_lightmap_uvs(*mesh, target); !made)
        return scene_error(object_location(scene.file, obj) + ": " + made.error().message);
    }
    meshes.push_back(std::move(*mesh));
  }
  return meshes;
}

bool world_is_y_up(const Scene& scene) {
  return std::any_of(scene.objects.begin(), scene.objects.end(),
                     [](const ObjectDesc& o) { return o.node >= 0; });
}

std::vector<const Mesh*> blocker_meshes(const Scene& scene, const std::vector<Mesh>& meshes) {
  std::vector<const Mesh*> blockers;
  for (std::size_t i = 0; i < meshes.size(); ++i)
    if (scene.objects[i].blocker) blockers.push_back(&meshes[i]);
  return blockers;
}

// The scene's lights with every sun and sky placed for the meshes' bounds (sun_light.h, sky.h),
// and, under an irradiance floor, a range for each light that has none.
std::vector<LightDesc> placed_lights(const Scene& scene, const std::vector<Mesh>& meshes) {
  std::vector<LightDesc> lights = scene.lights;
  for (LightDesc& l : lights) {
    if (std::isfinite(l.range)) continue;
    l.range = range_for_floor(l, scene.bake.irradiance_floor);
    if (!std::isfinite(l.shadowmask_range)) l.shadowmask_range = l.range;
  }
  const auto at_infinity = [](const LightDesc& l) {
    return l.sun_angle_deg > 0 || l.shape == LightShape::sky;
  };
  if (std::none_of(lights.begin(), lights.end(), at_infinity)) return lights;
  Bounds3 bounds;
  for (const Mesh& m : meshes)
    for (const auto& v : m.mesh.vertices()) {
      const auto& p = m.mesh.point(v);
      bounds.extend(Vec3(p[0], p[1], p[2]));
    }
  if (bounds.empty()) return lights;
  for (LightDesc& l : lights) {
    if (l.sun_angle_deg > 0) place_sun(l, bounds);
    if (l.shape == LightShape::sky) place_sky(l, bounds);
  }
  return lights;
}

Status cut_enclosed_lights(const Scene& scene, const std::vector<const Mesh*>& blockers,
                           const RayScene* rays, std::vector<LightDesc>& lights,
                           std::vector<std::string>& warnings) {
  const auto tested = [](const LightDesc& l) {
    return l.sun_angle_deg == 0 &&
           (l.shape == LightShape::sphere || l.shape == LightShape::rectangle ||
            l.shape == LightShape::disk);
  };
  if (blockers.empty() || std::none_of(lights.begin(), lights.end(), tested)) return Ok{};
  std::optional<RayScene> own;
  if (!rays) {
    auto built = RayScene::build(blockers);
    if (!built) return built.error();
    rays = &own.emplace(std::move(*built));
  }
  std::vector<const LightDesc*> enclosed;
  for (LightDesc& l : lights) {
    if (!tested(l) || !rays->inside_solid(l.position)) continue;
    l.range = 0;
    l.shadowmask_range = 0;
    enclosed.push_back(&l);
  }
  warn_lights(scene, enclosed,
              "its centre lies inside solid geometry (every ray from it meets a surface from "
              "behind); it reaches nothing",
              "lights' centres lie inside solid geometry (every ray from each meets a surface "
              "from behind)",
              "they reach nothing", warnings);
  return Ok{};
}

void warn_lights(const Scene& scene, const std::vector<const LightDesc*>& lights,
                 std::string_view each, std::string_view many, std::string_view then,
                 std::vector<std::string>& warnings) {
  constexpr std::size_t kNamed = 5;
  if (lights.size() <= kNamed) {
    for (const LightDesc* l : lights)
      warnings.push_back(
          fmt::format("{}:{}: light '{}': {}", scene.file.string(), l->line, l->name, each));
    return;
  }
  std::string names;
  for (std::size_t k = 0; k < kNamed; ++k) names += (k ? ", '" : "'") + lights[k]->name + "'";
  warnings.push_back(fmt::format("{}: {} {}, {} and {} more; {}", scene.file.string(),
                                 lights.size(), many, names, lights.size() - kNamed, then));
}

std::vector<std::uint8_t> lights_reaching(const Scene& scene, const TexelSpace& space,
                                          const std::vector<Light>& lights,
                                          const LightLists& lists) {
  std::vector<std::uint8_t> reached(scene.lights.size(), 0);
  if (scene.bake.quantity == Quantity::ambient_occlusion) return reached;
  // Texel by texel, the lights of its block not yet found to reach (this light, or another part
  // of its mesh light): a light the lists leave out everywhere costs nothing.
  for (const Texel& t : space.texels) {
    for (const std::uint32_t l : lists.lights_of(lists.block_of(t.x, t.y))) {
      std::uint8_t& reaches = reached[std::size_t(lights[l].output())];
      if (!reaches) reaches = lights[l].reaches(t.position.cast<double>(), t.normal.cast<double>());
    }
  }
  return reached;
}

Expected<std::vector<std::string>> layout_warnings(const Scene& scene, const ObjectDesc& obj,
                                                   const UvLayoutReport& layout,
                                                   std::int64_t covered, int side) {
  std::vector<std::string> warnings;
  // Its warnings say where it is in the scene file as it is now (a reused one's too).
  const std::string where = object_location(scene.file, obj) + ": ";
  if (covered == 0) {
    const std::string problem = fmt::format(
        "its lightmap UVs (channel {}) cover no texel at {}² (UV area {:.3g}, of which {:.3g} "
        "inside [0, 1])",
        obj.uv_channel, side, layout.uv_area, layout.uv_area - layout.uv_area_outside);
    if (!obj.allow_uncovered) {
      return scene_error(where + problem +
                         "; fix the UVs, set 'uv' to the lightmap channel, or set "
                         "allow_uncovered = true");
    }
    warnings.push_back(where + problem + "; its lightmap is black");
  }
  for (const std::string& w : uv_layout_warnings(layout)) warnings.push_back(where + w);
  return warnings;
}

namespace {

// Each of light l's images made whole, given its shadow-mask range, dilated and stitched as a
// bake of that light alone would be, and kept by tiles again: one light's images whole at a
// time (a level's thousand lights would not fit whole together).
void finish_light(const Scene& scene, const TexelSpace& space, const std::vector<Light>& lights,
                  const LightLists& lists, const SeamStitcher* stitcher, std::size_t l,
                  ReceiverBake& out, double& seconds_dilate, double& seconds_seams) {
  const bool visibility = scene.bake.quantity == Quantity::visibility;
  // The light's arbitrary texels, by whether the image is a visibility: found once, as the value
  // image of a visibility bake and the mask's visibility share them.
  std::optional<std::vector<std::uint8_t>> arbitrary[2];
  const auto arbitrary_of = [&](bool of_visibility) -> const std::vector<std::uint8_t>& {
    std::optional<std::vector<std::uint8_t>>& a = arbitrary[of_visibility];
    if (!a) a = arbitrary_texels(of_visibility, space, lights, lists, l);
    return *a;
  };
  const auto finish = [&](TiledImages& images, bool mask) {
    if (l >= images.size()) return;
    Image image = images.dense(l);
    if (mask) apply_shadowmask_range(image, scene.lights[l], space);
    const auto dilate_start = std::chrono::steady_clock::now();
    // Beyond its tiles the image holds its fill: dilation visits the tiles within reach of them
    // where the fill's neighbours may matter.
    const int tx = images.tiles_x(), ty = images.tiles_y();
    const int around = (2 * scene.bake.margin + 2 + TiledImages::kSide - 1) / TiledImages::kSide;
    std::vector<std::uint8_t> visit(std::size_t(tx) * std::size_t(ty), 0);
    for (const std::uint32_t tile : images.tiles(l)) {
      const int x = int(tile % std::uint32_t(tx)), y = int(tile / std::uint32_t(tx));
      for (int v = std::max(0, y - around); v <= std::min(ty - 1, y + around); ++v)
        for (int u = std::max(0, x - around); u <= std::min(tx - 1, x + around); ++u)
          visit[std::size_t(v) * std::size_t(tx) + std::size_t(u)] = 1;
    }
    dilate(image, space.covered, scene.bake.margin, visit, TiledImages::kSide);
    seconds_dilate += seconds_since(dilate_start);
    if (stitcher) {
      const auto seams_start = std::chrono::steady_clock::now();
      stitcher->stitch(image, arbitrary_of(mask || visibility), SeamSolver::automatic);
      seconds_seams += seconds_since(seams_start);
    }
    images.assign(l, image);
  };
  finish(out.per_light, false);
  finish(out.per_light_visibility, true);
}

}  // namespace

void finish_receiver(const Scene& scene, const Mesh& mesh, const TexelSpace& space,
                     const std::vector<Light>& lights, const LightLists& lists, ReceiverBake& out) {
  const auto dilate_start = std::chrono::steady_clock::now();
  dilate(out.image, space.covered, scene.bake.margin);
  out.seconds_dilate = seconds_since(dilate_start);
  const auto seams_start = std::chrono::steady_clock::now();
  // The arbitrary-texel masks cost a reach test per texel and light: only for a mesh with seams.
  const std::vector<SeamEdge> seams = find_seams(mesh);
  std::optional<SeamStitcher> stitcher;
  if (!seams.empty()) {
    stitcher.emplace(seams, out.image.width, out.image.height, space.covered);
    const bool visibility = scene.bake.quantity == Quantity::visibility;
    const std::vector<std::uint8_t> arbitrary = arbitrary_texels(visibility, space, lights, lists);
    const double scale = seam_scale(scene, out.image);
    out.seams.edges = std::int64_t(seams.size());
    out.seams.before = stitcher->difference(out.image, arbitrary, scale);
    out.seams.after = out.seams.before;
    if (scene.bake.seams) {
      out.seams.texels = stitcher->texels();
      stitcher->stitch(out.image, arbitrary, SeamSolver::automatic);
      out.seams.after = stitcher->difference(out.image, arbitrary, scale);
    } else {
      stitcher.reset();
    }
  }
  out.seconds_seams = seconds_since(seams_start);
  // The lights in parallel, each its own images whole (two lights' at a time on two cores).
  const std::size_t per_light = std::max(out.per_light.size(), out.per_light_visibility.size());
  tbb::combinable<std::pair<double, double>> seconds;  // dilation, seams
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, per_light, 1), [&](const auto& range) {
    auto& [dilation, seams_time] = seconds.local();
    for (std::size_t l = range.begin(); l != range.end(); ++l)
      finish_light(scene, space, lights, lists, stitcher ? &*stitcher : nullptr, l, out, dilation,
                   seams_time);
  });
  seconds.combine_each([&](const std::pair<double, double>& s) {
    out.seconds_dilate += s.first;
    out.seconds_seams += s.second;
  });
  out.seams.stitched = scene.bake.seams;
  out.seconds_seams = seconds_since(seams_start);
  out.covered_texels = std::int64_t(space.texels.size());
  out.covered = space.covered;
  if (scene.output.gltf)
    out.gltf_mesh = std::make_shared<const GltfMesh>(gltf_mesh(mesh, true, world_is_y_up(scene)));
}

}  // namespace sb
