// Tiles of a receiver's rows (tiles.h).
#include "pipeline/tiles.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

#include "core/stopwatch.h"
#include "methods/light_mix.h"
#include "pipeline/receiver_stages.h"
#include "texels/lightmap_sizes.h"
#include "texels/uv_checks.h"

namespace sb {

namespace {

// Rows [begin, end) of `from` into rows [at, at + end − begin) of `to` (same width, channels).
void copy_rows(const Image& from, int begin, int end, Image& to, int at) {
  const std::size_t row = std::size_t(from.width) * std::size_t(from.channels);
  std::copy(from.pixels.begin() + std::ptrdiff_t(std::size_t(begin) * row),
            from.pixels.begin() + std::ptrdiff_t(std::size_t(end) * row),
            to.pixels.begin() + std::ptrdiff_t(std::size_t(at) * row));
}

}  // namespace

std::vector<double> row_block_costs(const Mesh& mesh, int side, const std::vector<Light>& lights) {
  const int blocks = std::max(1, (side + kTileRows - 1) / kTileRows);
  std::vector<double> cost(std::size_t(blocks), 0.0);
  for (auto f : mesh.mesh.faces()) {
    const Triangle t = triangle(mesh.mesh, f);
    const Vec2 a = t.uv[1] - t.uv[0], b = t.uv[2] - t.uv[0];
    const double uv_area = 0.5 * std::abs(a.x() * b.y() - a.y() * b.x());
    const Vec3 centroid = (t.p[0] + t.p[1] + t.p[2]) / 3.0;
    const Vec3 normal = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).normalized();
    double reached = 0.1;
    for (const Light& light : lights) reached += light.reaches(centroid, normal) ? 1.0 : 0.0;
    const double pairs = double(side) * double(side) * uv_area * reached;
    if (!std::isfinite(pairs)) continue;
    // Its rows, Y = (1 − v) · side: the cost spread evenly over them (the part outside the
    // lightmap is not baked).
    const double v_lo = std::min({t.uv[0].y(), t.uv[1].y(), t.uv[2].y()});
    const double v_hi = std::max({t.uv[0].y(), t.uv[1].y(), t.uv[2].y()});
    const double lo = (1 - v_hi) * side, hi = (1 - v_lo) * side;
    if (!(hi > lo)) {
      const int block = std::clamp(int(std::floor(lo / kTileRows)), 0, blocks - 1);
      cost[std::size_t(block)] += pairs;
      continue;
    }
    const int first = std::clamp(int(std::floor(lo / kTileRows)), 0, blocks - 1);
    const int last = std::clamp(int(std::ceil(hi / kTileRows)) - 1, 0, blocks - 1);
    for (int block = first; block <= last; ++block) {
      const double overlap =
          std::min(hi, double(block + 1) * kTileRows) - std::max(lo, double(block) * kTileRows);
      if (overlap > 0) cost[std::size_t(block)] += pairs * overlap / (hi - lo);
    }
  }
  return cost;
}

std::vector<ShardUnit> shard_units(const std::vector<std::vector<double>>& block_costs,
                                   const std::vector<int>& sides, bool split,
                                   const ShardSpec& spec) {
  double total = 0;
  for (const auto& blocks : block_costs)
    for (double c : blocks) total += c;
  const int count = std::max(spec.count, 1);
  const double share = total / count;
  std::vector<ShardUnit> units;
  std::vector<double> costs;
  for (std::size_t r = 0; r < block_costs.size(); ++r) {
    const std::vector<double>& blocks = block_costs[r];
    std::vector<double> prefix(blocks.size() + 1, 0.0);
    for (std::size_t b = 0; b < blocks.size(); ++b) prefix[b + 1] = prefix[b] + blocks[b];
    const double cost = prefix.back();
    int parts = 1;
    if (split && count > 1 && share > 0 && cost > share && blocks.size() > 1)
      parts = std::min({count, int(blocks.size()), int(std::ceil(cost / share))});
    if (parts <= 1) {
      units.push_back({r, std::nullopt});
      costs.push_back(cost);
      continue;
    }
    // Cut j at the block border nearest to j/parts of the cost, leaving each tile a block.
    std::size_t begin = 0;
    for (int j = 1; j <= parts; ++j) {
      std::size_t end = blocks.size();
      if (j < parts) {
        const double target = cost * j / parts;
        const std::size_t latest = blocks.size() - std::size_t(parts - j);
        end = begin + 1;
        for (std::size_t b = begin + 1; b <= latest; ++b)
          if (std::abs(prefix[b] - target) < std::abs(prefix[end] - target)) end = b;
      }
      const int side = sides[r];
      units.push_back({r, RowRange{int(begin) * kTileRows, std::min(int(end) * kTileRows, side)}});
      costs.push_back(prefix[end] - prefix[begin]);
      begin = end;
    }
  }
  std::vector<ShardUnit> mine;
  for (std::size_t u : shard_receivers(costs, spec)) mine.push_back(units[u]);
  return mine;
}

RowRange tile_window(RowRange rows, int halo, int side) {
  return {std::max(0, rows.begin - halo), std::min(side, rows.end + halo)};
}

void crop_to_tile(ReceiverBake& r, const TexelSpace& space, RowRange rows) {
  const auto crop = [&](Image& image) {
    Image out(image.width, rows.end - rows.begin, image.channels);
    copy_rows(image, rows.begin, rows.end, out, 0);
    image = std::move(out);
  };
  crop(r.image);
  const auto crop_each = [&](TiledImages& images) {
    TiledImages cropped = images.like(images.size(), images.width(), rows.end - rows.begin);
    for (std::size_t l = 0; l < images.size(); ++l) {
      Image image = images.dense(l);
      crop(image);
      cropped.assign(l, image);
    }
    images = std::move(cropped);
  };
  crop_each(r.per_light);
  crop_each(r.per_light_visibility);
  const std::size_t width = std::size_t(space.width);
  r.covered.assign(space.covered.begin() + std::ptrdiff_t(std::size_t(rows.begin) * width),
                   space.covered.begin() + std::ptrdiff_t(std::size_t(rows.end) * width));
  const auto [first, last] = kept_texels(space);
  r.covered_texels = std::int64_t(last - first);
  r.tile = rows;
}

Expected<std::vector<ReceiverBake>> join_tiles(const Scene& scene,
                                               std::vector<std::vector<ReceiverBake>> tiled,
                                               const std::string& where) {
  std::vector<ReceiverBake> joined;
  if (tiled.empty()) return joined;
  auto meshes = load_meshes(scene, nullptr);
  if (!meshes) return meshes.error();
  auto lights = make_lights(placed_lights(scene, *meshes), scene.file);
  if (!lights) return lights.error();
  const std::vector<int> sides = lightmap_sides(scene, *meshes, nullptr);
  std::map<std::size_t, int> side_of;  // by object
  for (std::size_t i = 0, r = 0; i < scene.objects.size(); ++i)
    if (scene.objects[i].receiver) side_of[i] = sides[r++];
  const MethodEntry* entry = find_method(scene.bake.method);

  for (std::vector<ReceiverBake>& tiles : tiled) {
    const auto start = std::chrono::steady_clock::now();
    std::sort(tiles.begin(), tiles.end(), [](const ReceiverBake& a, const ReceiverBake& b) {
      return a.tile->begin < b.tile->begin;
    });
    const ReceiverBake& first = tiles.front();
    const std::size_t object = first.object;
    const auto fail = [&](const std::string& why) {
      return input_error(fmt::format("{}: receiver '{}': its tiles {}", where, first.name, why));
    };
    if (!side_of.count(object)) return fail("are of an object that is not a receiver");
    const int side = side_of[object];
    int next = 0;
    for (const ReceiverBake& t : tiles) {
      if (t.image.width != side || t.image.height != t.tile->end - t.tile->begin)
        return fail(fmt::format("are not of its {}² lightmap", side));
      if (t.per_light.size() != first.per_light.size() ||
          t.per_light_visibility.size() != first.per_light_visibility.size())
        return fail("hold different per-light images");
      if (t.tile->begin != next)
        return fail(t.tile->begin > next
                        ? fmt::format("leave rows {} to {} out (a shard is missing)", next,
                                      t.tile->begin - 1)
                        : fmt::format("overlap at row {}", t.tile->begin));
      next = t.tile->end;
    }
    if (next != side) return fail(fmt::format("end at row {} of {}", next, side));

    ReceiverBake out;
    out.object = object;
    out.name = first.name;
    out.uv_channel = first.uv_channel;
    out.image = Image(side, side, first.image.channels);
    // Each light's images from its tiles' rows, one light at a time.
    const auto join_each = [&](TiledImages ReceiverBake::*member, TiledImages made) {
      for (std::size_t l = 0; l < made.size(); ++l) {
        Image whole(side, side, made.channels());
        for (const ReceiverBake& t : tiles)
          copy_rows((t.*member).dense(l), 0, t.tile->end - t.tile->begin, whole, t.tile->begin);
        made.assign(l, whole);
      }
      out.*member = std::move(made);
    };
    join_each(&ReceiverBake::per_light, per_light_values(first.per_light.size(), side, side));
    join_each(&ReceiverBake::per_light_visibility,
              per_light_visibilities(first.per_light_visibility.size(), side, side));
    std::vector<std::uint8_t> covered(std::size_t(side) * std::size_t(side), 0);
    for (const ReceiverBake& t : tiles) {
      const int rows = t.tile->end - t.tile->begin;
      copy_rows(t.image, 0, rows, out.image, t.tile->begin);
      out.most_lights_per_texel = std::max(out.most_lights_per_texel, t.most_lights_per_texel);
      std::copy(t.covered.begin(), t.covered.end(),
                covered.begin() + std::ptrdiff_t(std::size_t(t.tile->begin) * std::size_t(side)));
      // The method's counts and rays add up; its warnings once each.
      // (A pair, not a structured binding: clang 14, the fuzzing build's, cannot capture one.)
      for (const auto& added : t.report.tallies) {
        auto at = std::find_if(out.report.tallies.begin(), out.report.tallies.end(),
                               [&](const auto& tally) { return tally.first == added.first; });
        if (at == out.report.tallies.end())
          out.report.tallies.push_back(added);
        else
          at->second += added.second;
      }
      for (const std::string& w : t.report.warnings)
        if (std::find(out.report.warnings.begin(), out.report.warnings.end(), w) ==
            out.report.warnings.end())
          out.report.warnings.push_back(w);
      out.rays += t.rays;
      out.seconds += t.seconds;
      out.seconds_texels += t.seconds_texels;
      out.seconds_method += t.seconds_method;
    }
    out.report.manifest = first.report.manifest;
    if (entry && entry->summarise) entry->summarise(out.report);

    // The receiver's texel space as a bake of it whole has it: its tiles' coverage must be it.
    const Mesh& mesh = (*meshes)[object];
    const auto texels_start = std::chrono::steady_clock::now();
    const TexelSpace space = rasterise_texels(mesh, side, side);
    out.seconds_texels += seconds_since(texels_start);
    if (space.covered != covered)
      return fail("cover other texels than its UVs do (a shard baked another mesh or build)");
    const ObjectDesc& obj = scene.objects[object];
    out.uv_layout = check_uv_layout(mesh, space, scene.bake.margin);
    auto warnings =
        layout_warnings(scene, obj, out.uv_layout, std::int64_t(space.texels.size()), side);
    if (!warnings) return warnings.error();
    out.uv_warnings = std::move(*warnings);
    const LightLists lists(space, *lights);
    out.lights_reached = lights_reaching(scene, space, *lights, lists);
    finish_receiver(scene, mesh, space, *lights, lists, out);
    out.seconds += seconds_since(start);
    joined.push_back(std::move(out));
  }
  return joined;
}

std::vector<std::size_t> shard_receivers(const std::vector<double>& costs, const ShardSpec& spec) {
  const std::size_t n = costs.size(), shards = std::size_t(std::max(spec.count, 1));
  std::vector<std::size_t> shard_of(n, 0);
  if (spec.balance == ShardBalance::count) {
    for (std::size_t r = 0; r < n; ++r) shard_of[r] = r % shards;
  } else {
    // Longest processing time first: dearest receiver first (ties in scene order), each onto the
    // shard with the least cost so far (ties: the lowest shard). Within 4/3 of the best makespan.
    std::vector<std::size_t> order(n);
    for (std::size_t r = 0; r < n; ++r) order[r] = r;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return costs[a] > costs[b]; });
    std::vector<double> load(shards, 0.0);
    for (const std::size_t r : order) {
      const std::size_t least =
          std::size_t(std::min_element(load.begin(), load.end()) - load.begin());
      shard_of[r] = least;
      load[least] += costs[r];
    }
  }
  std::vector<std::size_t> mine;
  for (std::size_t r = 0; r < n; ++r)
    if (shard_of[r] == std::size_t(spec.index)) mine.push_back(r);
  return mine;
}

}  // namespace sb
