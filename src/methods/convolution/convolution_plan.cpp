// The error-driven hierarchy of (light part, blocker cluster, receiver part) triples
// (design-notes §4–5; ../shared/seeds/001_414ff95054935c53.txt, "Measuring the Error" and
// "Subdivision"). One virtual configuration per triple gets every penumbra width wrong by at
// most ε = L·(ρ_hi − ρ_lo)/2, ρ = r/d over the triple's blocker depths d and receiver depths r.
// Splitting the blockers by depth narrows d, splitting the receiver by depth narrows r,
// splitting the light halves L; the planner applies whichever split lowers the worst leaf's ε
// most per unit of estimated FFT work, until every leaf is within `error_texels` receiver
// texels or the budget is spent.
//
// What the paper leaves open and is chosen here:
// - A planar group of texels (a floor; one face plane of a bracket) is seen along its plane's
//   normal (add_frames): every texel then lies at one depth, so the receiver's own depth range is
//   exact and only the blockers' depths and the light's tilt need subdividing; blockers clipped
//   to depths before the plane are exactly those on the light's side of it. Other receivers are
//   seen through one frustum from the light's centre (or cube faces) and split by depth.
// - ρ is taken over the receiver texels of the blocker cluster's footprint only (its projection
//   from the light's centre, grown by the widest penumbra), not the whole receiver: a post's
//   shadow needs the depths of the floor around the post, not of the whole floor. This is what
//   makes clusters pay: separate clusters have separate, small footprints.
// - A light tilted against the axis has points off its centre's plane; its kernel is exact for
//   receiver points seen along the triple's view (source_image.cpp) and sheared elsewhere, an
//   error counted with ε (Triple::view_error) that blocker-space and light splits reduce.
// - ε counts in receiver texels up to penumbrae kRelativeSpan texels wide and relative to the
//   penumbra beyond (design-notes §4 allows either): contact shadows get thin slabs, wide soft
//   penumbrae do not spend the budget on invisible width errors.
// - The blockers of a triple are clipped to a slab of depth; a texel takes a slab's shadow in
//   proportion to how much of the slab's geometry lies in front of it (bake_convolution), so
//   geometry behind a texel never shadows it and contact shadows converge as slabs thin.
// - Self-shadowing: the receiver's own faces are blockers too, except for texels on a convex
//   component of the receiver, which cannot shadow itself (H0 already counts its horizon).
//   Texels of a non-convex component are grouped by the plane of their face, so that the
//   plane-side test of project_faces drops the faces they lie on.
#include "methods/convolution/convolution_plan.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <queue>
#include <tuple>

#include "methods/convolution/source_image.h"
#include "occluders/clusters.h"

namespace sb {

double texel_size(const Mesh& mesh, int width, int height) {
  double world = 0, uv = 0;
  for (auto f : mesh.mesh.faces()) {
    const Triangle t = triangle(mesh.mesh, f);
    world += 0.5 * (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).norm();
    const Vec2 a = t.uv[1] - t.uv[0], b = t.uv[2] - t.uv[0];
    uv += 0.5 * std::abs(a.x() * b.y() - a.y() * b.x());
  }
  if (uv <= 0) return 0;
  return std::sqrt(world / (uv * double(width) * height));
}

std::vector<int> ConvolutionPlan::leaves() const {
  std::vector<int> out;
  for (std::size_t i = 0; i < triples.size(); ++i)
    if (triples[i].children.empty() && !triples[i].empty) out.push_back(int(i));
  return out;
}

double ConvolutionPlan::worst_error_texels() const {
  double worst = 0;
  for (int i : leaves())
    if (!triples[i].traced) worst = std::max(worst, triples[i].penumbra_error_texels);
  return worst;
}

double ConvolutionPlan::estimated_cost() const {
  double cost = 0;
  for (int i : leaves())
    if (!triples[i].traced) cost += triples[i].cost;
  return cost;
}

void TexelIndex::build(const std::vector<int>& texels, const std::vector<Vec2>& tangent,
                       const std::vector<double>& depth, const std::vector<Vec3>& position) {
  if (texels.empty()) return;
  TangentBounds bounds;
  for (int i : texels) bounds.extend(tangent[std::size_t(i)]);
  lo = bounds.lo;
  // About 16 texels per cell.
  const Vec2 span = (bounds.hi - lo).cwiseMax(1e-12);
  cell = std::sqrt(span.x() * span.y() * 16.0 / double(texels.size()));
  cell = std::max({cell, span.maxCoeff() / 4096.0, 1e-12});
  nx = std::max(1, int(span.x() / cell) + 1);
  ny = std::max(1, int(span.y() / cell) + 1);
  auto cell_of = [&](int i) {
    const Vec2& t = tangent[std::size_t(i)];
    const int x = std::min(nx - 1, int((t.x() - lo.x()) / cell));
    const int y = std::min(ny - 1, int((t.y() - lo.y()) / cell));
    return std::size_t(y) * nx + x;
  };
  start.assign(std::size_t(nx) * ny + 1, 0);
  for (int i : texels) ++start[cell_of(i) + 1];
  for (std::size_t c = 1; c < start.size(); ++c) start[c] += start[c - 1];
  items.resize(texels.size());
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (int i : texels) items[std::size_t(fill[cell_of(i)]++)] = i;
  cells.assign(std::size_t(nx) * ny, Cell{});
  for (int i : texels) {
    Cell& c = cells[cell_of(i)];
    c.tangents.extend(tangent[std::size_t(i)]);
    c.depth.extend(depth[std::size_t(i)]);
    c.box.extend(position[std::size_t(i)]);
    ++c.count;
  }
  bx = (nx + kBlock - 1) / kBlock;
  by = (ny + kBlock - 1) / kBlock;
  blocks.assign(std::size_t(bx) * by, Cell{});
  for (int y = 0; y < ny; ++y) {
    for (int x = 0; x < nx; ++x) {
      const Cell& c = cells[std::size_t(y) * nx + x];
      if (c.count == 0) continue;
      Cell& b = blocks[std::size_t(y / kBlock) * bx + x / kBlock];
      b.tangents.extend(c.tangents);
      b.depth.extend(c.depth.lo);
      b.depth.extend(c.depth.hi);
      b.box.extend(c.box.lo);
      b.box.extend(c.box.hi);
      b.count += c.count;
    }
  }
}

namespace {

// Penumbra errors count in texels up to penumbrae this many texels wide, and relative to the
// penumbra beyond: a width error of one texel is visible at a contact shadow, while a penumbra
// 100 texels wide may be off by a few texels unseen. (design-notes §4: "compare it with the texel
// size, or with the penumbra width, for a relative error".)
constexpr double kRelativeSpan = 16.0;
// Image pixels across a leaf's narrowest penumbra, where that is wider than one texel per pixel.
// Fewer cost accuracy where it is checked exactly: with 32 (or 16), bilinear reads of the
// convolved image and the coarser kernel put the parallel square light's maximum error at 0.02
// (0.05) against its closed form, above the 0.02 its test allows (convolution_bake_test.cpp).
constexpr double kPenumbraPixels = 64.0;
// Light splits: at most this many halvings (2^2 = 4 parts).
constexpr int kMaxLightSplits = 2;

double light_radius(const Light& light) {
  return light.shape() == LightShape::rectangle
             ? 0.5 * std::hypot(light.desc().width, light.desc().height)
             : light.desc().radius;
}

}  // namespace

std::pair<double, double> part_interval(const std::vector<ReceiverCut>& cuts) {
  double lo = -std::numeric_limits<double>::infinity(), hi = -lo;
  for (const ReceiverCut& c : cuts) {
    if (c.below) {
      hi = std::min(hi, c.depth + c.band);
    } else {
      lo = std::max(lo, c.depth - c.band);
    }
  }
  return {lo, hi};
}

void evaluate_triple(const ConvolutionPlan& plan, const PlanInputs& in, Triple& t) {
  const PlanFrame& fr = plan.frames[t.frame];
  const Light& light = plan.light_parts[fr.light_part].part;
  const std::vector<int>& group = fr.groups[std::size_t(t.group)];
  t.empty = true;
  t.footprint_texels = 0;
  t.polygons = 0;
  t.blockers = ProjectedBlockers{};
  // Plain variables, not a structured binding: clang 14 (the fuzz build) cannot capture one.
  const std::pair<double, double> part = part_interval(t.cuts);
  const double part_lo = part.first, part_hi = part.second;
  if (t.faces.empty() || group.empty()) return;
  const double part_depth_hi = std::min(part_hi, fr.depth[group.back()]);

  ShadowCaster caster;
  caster.light_radius = light_radius(light);
  caster.receiver = t.receiver_box;
  // The slab grown by a hair, so that a face lying exactly on a slab boundary (a flat top seen
  // along its normal) keeps its polygon in both slabs: nearest_layer_coverage gives its samples
  // to one of them, and that one's footprint must hold them.
  const double hair = 1e-7 * std::max(1.0, part_depth_hi);
  t.blockers = project_faces(t.faces, fr.frame, std::max(t.slab_lo - hair, fr.near),
                             std::min(t.slab_hi + hair, part_depth_hi), caster);
  t.polygons = int(t.blockers.polygons.size());
  if (t.blockers.polygons.empty()) return;
  if (!t.layer) t.layer = std::make_shared<const ProjectedBlockers>(t.blockers);
  DepthRange blocker_depths;
  TangentBounds projection;
  for (const auto& pg : t.blockers.polygons) {
    blocker_depths.extend(pg.depth_lo);
    blocker_depths.extend(pg.depth_hi);
    projection.extend(TangentBounds{pg.lo, pg.hi});
  }
  // The footprint: the blockers' projection grown by the widest penumbra they can cast on the
  // part, k_max times the light's half extents (tangent units).
  t.view = projection.centre();
  const Vec2 half = projected_half_extents(light, fr.frame, t.view, part_depth_hi);
  const double k_max = std::max(0.0, 1.0 / blocker_depths.lo - 1.0 / part_depth_hi);
  const Vec2 lo = projection.lo - half * k_max, hi = projection.hi + half * k_max;
  DepthRange receiver_depths;
  TangentBounds footprint;
  Bounds3 box;
  const double d_floor = blocker_depths.lo;
  fr.index[std::size_t(t.group)].for_each_cell(
      lo, hi,
      [&](const TexelIndex::Cell& c) {
        return c.depth.lo > d_floor && c.depth.lo >= part_lo && c.depth.hi <= part_hi;
      },
      [&](const TexelIndex::Cell& c) {
        receiver_depths.extend(c.depth.lo);
        receiver_depths.extend(c.depth.hi);
        footprint.extend(c.tangents);
        box.extend(c.box.lo);
        box.extend(c.box.hi);
        t.footprint_texels += c.count;
      },
      [&](int i) {
        const double d = fr.depth[i];
        if (d <= d_floor || d < part_lo || d > part_hi) return;
        const Vec2& tc = fr.tangent[i];
        if ((tc.array() < lo.array()).any() || (tc.array() > hi.array()).any()) return;
        receiver_depths.extend(d);
        footprint.extend(tc);
        box.extend(fr.position[std::size_t(i)]);
        ++t.footprint_texels;
      });
  if (receiver_depths.empty()) return;
  t.empty = false;
  t.receiver_box = box;
  t.blocker_depths = blocker_depths;
  t.receiver_depths = receiver_depths;
  t.footprint_lo = footprint.lo;
  t.footprint_hi = footprint.hi;
  const double extent = light.extent_across(fr.frame.axis);
  t.config = choose_configuration(fr.frame, blocker_depths, receiver_depths, extent);
  t.smallest_penumbra = extent * (t.config.rho_lo - 1.0);
  const Vec2 reach =
      (footprint.lo - t.view).cwiseAbs().cwiseMax((footprint.hi - t.view).cwiseAbs());
  t.view_error = depth_half_spread(light, fr.frame) * reach.norm() * (t.config.rho_hi - 1.0);
  const double scale = std::max(plan.texel, t.smallest_penumbra / kRelativeSpan);
  t.penumbra_error_texels = scale > 0 ? (t.config.penumbra_error + t.view_error) / scale : 0;

  // Image resolution: one pixel per receiver texel at the receiver plane, coarser only where the
  // narrowest penumbra spans kPenumbraPixels pixels anyway (design-notes §5, "texture
  // resolution"); then within max_image, flagging any loss of detail.
  const double r_star = t.config.receiver_plane;
  const double detail = std::max(plan.texel, t.smallest_penumbra / kPenumbraPixels);
  double pixel =
      (plan.texel > 0 ? detail : (footprint.hi - footprint.lo).maxCoeff() / 512) / r_star;
  const double k = std::max(0.0, 1.0 / t.config.blocker_plane - 1.0 / r_star);
  const Vec2 kernel_extent = 2 * k * projected_half_extents(light, fr.frame, t.view, r_star);
  const Vec2 span = footprint.hi - footprint.lo;
  const double needed = (span + kernel_extent).maxCoeff();
  if (needed / pixel + 8 > in.max_image) {
    pixel = needed / (in.max_image - 8);
    t.blurred = pixel * r_star > 1.01 * std::max(plan.texel, t.smallest_penumbra / 2.0);
  } else {
    t.blurred = false;
  }
  // The grid and its cost at a pixel size: the transform, the kernel's splatting (about 9
  // samples of the light per kernel pixel, source_image.cpp), the footprint's lookups and the
  // faces' rasterisation.
  const auto size_images = [&](double at) {
    const int kernel_w = 2 * int(std::ceil(kernel_extent.x() / (2 * at))) + 1;
    const int kernel_h = 2 * int(std::ceil(kernel_extent.y() / (2 * at))) + 1;
    const int margin_x = kernel_w / 2 + 1, margin_y = kernel_h / 2 + 1;
    t.grid.pixel = at;
    t.grid.origin = footprint.lo - Vec2(margin_x, margin_y) * at;
    t.grid.width = int(std::ceil(span.x() / at)) + 2 * margin_x + 1;
    t.grid.height = int(std::ceil(span.y() / at)) + 2 * margin_y + 1;
    t.fft_width = in.backend->transform_size(t.grid.width);
    t.fft_height = in.backend->transform_size(t.grid.height);
    const double n = double(t.fft_width) * t.fft_height;
    // The blocker images: 4 × 4 coverage samples per pixel, for the share and the whole image
    // (blocker_image.cpp); on the showcase they took three times the transforms' time.
    const double blocker_pixels = 2.0 * 16.0 * double(t.grid.width) * t.grid.height;
    t.cost = (n * std::log2(std::max(2.0, n)) + 9.0 * double(kernel_w) * kernel_h) *
                 (light.textured() ? 3 : 1) +
             blocker_pixels + 30.0 * double(t.footprint_texels) + 20.0 * double(t.faces.size());
  };
  size_images(pixel);
  // Within the work budget (PlanInputs::cost_budget_per_texel): a leaf whose images would cost
  // more than its footprint may takes coarser pixels. Its ε, which decides where it is traced,
  // does not change; only the blur it adds, which ε's scale already allows for where the
  // penumbra is wide (the case that makes images this large: blockers near the light's depth).
  if (in.cost_budget_per_texel > 0) {
    const double cap = in.cost_budget_per_texel * std::max(4096.0, double(t.footprint_texels));
    for (int step = 0; step < 40 && t.cost > cap && t.grid.width * t.grid.height > 256; ++step) {
      pixel *= 1.5;
      size_images(pixel);
      t.blurred = true;
    }
  }
  t.traced =
      in.ray_cost_per_texel > 0 && t.cost > in.ray_cost_per_texel * double(t.footprint_texels);
}

Triple child_triple(const Triple& parent, const char* split) {
  Triple c;
  c.frame = parent.frame;
  c.group = parent.group;
  c.split = split;
  c.slab_lo = parent.slab_lo;
  c.slab_hi = parent.slab_hi;
  c.cuts = parent.cuts;
  c.layer = parent.layer;
  c.receiver_box = parent.receiver_box;
  return c;
}

namespace {

class Planner {
 public:
  Planner(ConvolutionPlan& plan, const PlanInputs& in) : plan_(plan), in_(in) {}

  // Refines every root of the frames [frame_begin, frame_end) within `budget` leaves.
  void refine(std::size_t frame_begin, std::size_t frame_end, int budget) {
    auto worse = [&](int a, int b) {
      return plan_.triples[a].penumbra_error_texels < plan_.triples[b].penumbra_error_texels;
    };
    std::priority_queue<int, std::vector<int>, decltype(worse)> queue(worse);
    int leaves = 0;
    for (std::size_t f = frame_begin; f < frame_end; ++f) {
      for (int root : plan_.frames[f].roots) {
        if (plan_.triples[root].empty) continue;
        ++leaves;
        if (over(root)) queue.push(root);
      }
    }
    // The work budget: the leaves' estimated cost within cost_budget_per_texel per texel.
    double cost = 0, cost_budget = std::numeric_limits<double>::infinity();
    if (in_.cost_budget_per_texel > 0) {
      double texels = 0;
      for (std::size_t f = frame_begin; f < frame_end; ++f)
        texels += double(plan_.frames[f].texels.size());
      cost_budget = in_.cost_budget_per_texel * std::max(texels, 4096.0);
      for (std::size_t f = frame_begin; f < frame_end; ++f)
        for (int root : plan_.frames[f].roots)
          if (!plan_.triples[root].empty && !plan_.triples[root].traced)
            cost += plan_.triples[root].cost;
    }
    while (!queue.empty() && leaves < budget && cost < cost_budget) {
      const int worst = queue.top();
      queue.pop();
      std::vector<Triple> best;
      double best_score = 0;
      for (auto& children : candidates(plan_.triples[worst])) {
        double eps = 0, cost = 0;
        for (const Triple& c : children) {
          eps = std::max(eps, c.empty ? 0.0 : c.penumbra_error_texels);
          cost += c.empty ? 0.0 : c.cost;
        }
        const double score =
            (plan_.triples[worst].penumbra_error_texels - eps) / std::max(1.0, cost);
        if (score > best_score) {
          best_score = score;
          best = std::move(children);
        }
      }
      if (best.empty()) continue;  // no split helps: it stays a leaf above the target
      cost -= plan_.triples[worst].traced ? 0.0 : plan_.triples[worst].cost;
      for (const Triple& c : best) cost += c.empty || c.traced ? 0.0 : c.cost;
      plan_.triples[worst].split = best.front().split;
      best.front().split.clear();
      best.back().split.clear();
      plan_.triples[worst].blockers = ProjectedBlockers{};
      --leaves;
      for (Triple& c : best) {
        c.parent = worst;
        const int index = int(plan_.triples.size());
        plan_.triples[worst].children.push_back(index);
        const bool counts = !c.empty;
        plan_.triples.push_back(std::move(c));
        if (!counts) continue;
        ++leaves;
        if (over(index)) queue.push(index);
      }
    }
  }

 private:
  // Above the target and worth refining: a leaf that will be traced is not.
  bool over(int t) const {
    return !plan_.triples[t].empty && !plan_.triples[t].traced &&
           plan_.triples[t].penumbra_error_texels > in_.error_texels * (1 + 1e-9);
  }

  // The faces of the parent that kept a polygon (the others were culled or clipped away).
  std::vector<FaceRef> surviving(const Triple& t, const std::vector<int>& polygons) const {
    std::vector<FaceRef> faces;
    for (int p : polygons) faces.push_back(t.faces[t.blockers.polygons[p].source]);
    std::sort(faces.begin(), faces.end(), [](const FaceRef& a, const FaceRef& b) {
      return std::tie(a.mesh, a.face) < std::tie(b.mesh, b.face);
    });
    faces.erase(std::unique(faces.begin(), faces.end(),
                            [](const FaceRef& a, const FaceRef& b) {
                              return a.mesh == b.mesh && a.face == b.face;
                            }),
                faces.end());
    return faces;
  }

  std::vector<std::vector<Triple>> candidates(const Triple& t) {
    std::vector<std::vector<Triple>> out;
    const double texel = plan_.texel;
    const auto& polys = t.blockers.polygons;
    std::vector<int> all(polys.size());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = int(i);
    // Blocker depth: two slabs at the middle of the geometry's depth range.
    if (t.blocker_depths.hi - t.blocker_depths.lo > 0.25 * texel) {
      const double mid = t.blocker_depths.mid();
      Triple a = child_triple(t, "blocker depth"), b = child_triple(t, "blocker depth");
      a.slab_hi = b.slab_lo = mid;
      std::vector<int> near_polys, far_polys;
      for (int p : all) {
        if (polys[p].depth_lo <= mid) near_polys.push_back(p);
        if (polys[p].depth_hi >= mid) far_polys.push_back(p);
      }
      a.faces = surviving(t, near_polys);
      b.faces = surviving(t, far_polys);
      out.push_back(pair(std::move(a), std::move(b)));
    }
    // Blocker space: two clusters either side of the median centroid along the wider axis of
    // their tangent bounding box: of the polygons, and, when they belong to several connected
    // components, also of whole components (at the median of the components' centroids), which
    // keeps each side's solids whole for add_sections.
    if (polys.size() >= 2) {
      std::vector<Vec2> centroid(polys.size());
      for (std::size_t i = 0; i < polys.size(); ++i)
        centroid[i] = 0.5 * (polys[i].lo + polys[i].hi);
      const TangentBounds centroids = tangent_bounds(centroid);
      const Vec2 span = centroids.hi - centroids.lo;
      const int axis = span.x() >= span.y() ? 0 : 1;
      // Per polygon, its component's index among those present.
      std::vector<int> part(polys.size(), 0);
      std::vector<Vec2> part_centroid;
      if (in_.clusters) {
        std::map<std::pair<const Mesh*, int>, int> index;
        std::vector<int> count;
        for (std::size_t i = 0; i < polys.size(); ++i) {
          const FaceRef& f = t.faces[std::size_t(polys[i].source)];
          const auto m = std::find(in_.blockers.begin(), in_.blockers.end(), f.mesh);
          if (m == in_.blockers.end()) continue;
          const int c =
              in_.clusters
                  ->face_component[std::size_t(m - in_.blockers.begin())][std::size_t(f.face)];
          const auto [it, added] = index.emplace(std::pair(f.mesh, c), int(count.size()));
          if (added) {
            count.push_back(0);
            part_centroid.push_back(Vec2::Zero());
          }
          part[i] = it->second;
          ++count[std::size_t(it->second)];
          part_centroid[std::size_t(it->second)] += centroid[i];
        }
        for (std::size_t k = 0; k < count.size(); ++k) part_centroid[k] /= double(count[k]);
      }
      auto add = [&](const std::vector<int>& near_side, const std::vector<int>& far_side) {
        if (near_side.empty() || far_side.empty()) return;
        Triple a = child_triple(t, "blocker space"), b = child_triple(t, "blocker space");
        a.faces = surviving(t, near_side);
        b.faces = surviving(t, far_side);
        out.push_back(pair(std::move(a), std::move(b)));
      };
      if (part_centroid.size() >= 2) {
        std::vector<int> parts(part_centroid.size());
        for (std::size_t k = 0; k < parts.size(); ++k) parts[k] = int(k);
        const auto middle = parts.begin() + std::ptrdiff_t(parts.size() / 2);
        std::nth_element(parts.begin(), middle, parts.end(), [&](int a, int b) {
          return part_centroid[std::size_t(a)][axis] < part_centroid[std::size_t(b)][axis];
        });
        std::vector<std::uint8_t> first(parts.size(), 0);
        for (auto it = parts.begin(); it != middle; ++it) first[std::size_t(*it)] = 1;
        std::vector<int> near_side, far_side;
        for (int p : all)
          (first[std::size_t(part[std::size_t(p)])] ? near_side : far_side).push_back(p);
        add(near_side, far_side);
      }
      if (centroids.hi[axis] > centroids.lo[axis]) {
        std::vector<int> order = all;
        const auto middle = order.begin() + std::ptrdiff_t(order.size() / 2);
        std::nth_element(order.begin(), middle, order.end(),
                         [&](int a, int b) { return centroid[a][axis] < centroid[b][axis]; });
        add(std::vector<int>(order.begin(), middle), std::vector<int>(middle, order.end()));
      }
    }
    // Receiver depth: two parts either side of the middle of the footprint's depths, blended over
    // a band of a tenth of the range (at least a texel) each way.
    if (t.receiver_depths.hi - t.receiver_depths.lo > 2 * texel) {
      const double mid = t.receiver_depths.mid();
      const double band = std::max(texel, 0.1 * (t.receiver_depths.hi - t.receiver_depths.lo));
      Triple a = child_triple(t, "receiver depth"), b = child_triple(t, "receiver depth");
      a.cuts.push_back({mid, band, true});
      b.cuts.push_back({mid, band, false});
      a.faces = b.faces = surviving(t, all);
      out.push_back(pair(std::move(a), std::move(b)));
    }
    // The candidates' children are independent of one another: evaluated on all threads.
    tbb::parallel_for(std::size_t(0), 2 * out.size(),
                      [&](std::size_t k) { evaluate_triple(plan_, in_, out[k / 2][k % 2]); });
    return out;
  }

  static std::vector<Triple> pair(Triple a, Triple b) {
    std::vector<Triple> both;
    both.push_back(std::move(a));
    both.push_back(std::move(b));
    return both;
  }

  ConvolutionPlan& plan_;
  const PlanInputs& in_;
};

}  // namespace

namespace {

// Appends `from` (planned for the same receiver) to `to`, renumbering its indices.
void merge_plan(ConvolutionPlan& to, ConvolutionPlan&& from) {
  const int parts = int(to.light_parts.size()), frames = int(to.frames.size()),
            triples = int(to.triples.size());
  for (auto& lp : from.light_parts) to.light_parts.push_back(std::move(lp));
  for (auto& f : from.frames) {
    f.light_part += parts;
    for (int& r : f.roots) r += triples;
    to.frames.push_back(std::move(f));
  }
  for (auto& t : from.triples) {
    t.frame += frames;
    if (t.parent >= 0) t.parent += triples;
    if (t.euler >= 0) t.euler += triples;
    for (int& c : t.children) c += triples;
    to.triples.push_back(std::move(t));
  }
  for (auto& w : from.warnings) to.warnings.push_back(std::move(w));
}

ConvolutionPlan empty_like(const ConvolutionPlan& plan) {
  ConvolutionPlan p;
  p.receiver = plan.receiver;
  p.space = plan.space;
  p.texel = plan.texel;
  p.target = plan.target;
  return p;
}

bool has_slabs(const ConvolutionPlan& plan) {
  return std::any_of(plan.triples.begin(), plan.triples.end(),
                     [](const Triple& t) { return t.split == "blocker depth"; });
}

ConvolutionPlan plan_whole_part(const ConvolutionPlan& base, const PlanInputs& in, LightPart part,
                                int budget) {
  ConvolutionPlan whole = empty_like(base);
  whole.light_parts.push_back(std::move(part));
  add_frames(whole, in, 0);
  Planner(whole, in).refine(0, whole.frames.size(), budget);
  add_sections(whole, in);
  return whole;
}

ConvolutionPlan plan_light_part(const ConvolutionPlan& base, const PlanInputs& in, LightPart part,
                                int budget, int level);

// The part's two halves along its longer side, planned at once on their own threads with half
// the budget each, merged into one plan.
ConvolutionPlan plan_halves(const ConvolutionPlan& base, const PlanInputs& in,
                            const LightPart& part, int budget, int level) {
  const LightDesc& d = part.part.desc();
  std::array<ConvolutionPlan, 2> half_plans;
  tbb::parallel_for(0, 2, [&](int side) {
    LightDesc h = d;
    const double sign = side == 0 ? -0.5 : 0.5;
    if (d.width >= d.height) {
      h.width = 0.5 * d.width;
      h.position = d.position + sign * h.width * part.part.right();
    } else {
      h.height = 0.5 * d.height;
      h.position = d.position + sign * h.height * part.part.up();
    }
    h.power = 0.5 * d.power;
    LightPart half{part.light, part.name + "." + std::to_string(side), Light(h),
                   0.5 * part.fraction};
    half_plans[std::size_t(side)] =
        plan_light_part(base, in, std::move(half), std::max(1, budget / 2), level + 1);
  });
  ConvolutionPlan halves = empty_like(base);
  for (ConvolutionPlan& h : half_plans) merge_plan(halves, std::move(h));
  return halves;
}

// Plans one light part within `budget` leaves; when the target is missed, tries the part's two
// halves (a source subdivision, design-notes §5) and keeps the plan with the smaller worst ε.
// Where blockers are cut into depth slabs, the part is split into at least `light_parts` pieces
// whatever ε says (the slabs' plane error, which ε does not measure, scales with the light's
// size; one plane per blocker has none). Below that count the halves are planned first: if they
// cut blockers into slabs, the whole part (whose ε is larger) would too, and its plan, which
// would be thrown away, is never made.
ConvolutionPlan plan_light_part(const ConvolutionPlan& base, const PlanInputs& in, LightPart part,
                                int budget, int level) {
  const LightDesc& d = part.part.desc();
  const bool splittable =
      d.shape == LightShape::rectangle && !part.part.textured() && level < kMaxLightSplits;
  if (splittable && (1 << level) < in.light_parts) {
    ConvolutionPlan halves = plan_halves(base, in, part, budget, level);
    if (has_slabs(halves)) return halves;
    ConvolutionPlan whole = plan_whole_part(base, in, part, budget);
    const double worst = whole.worst_error_texels();
    const bool better = worst > in.error_texels && halves.worst_error_texels() < worst;
    return has_slabs(whole) || better ? std::move(halves) : std::move(whole);
  }
  ConvolutionPlan whole = plan_whole_part(base, in, part, budget);
  const double worst = whole.worst_error_texels();
  if (worst <= in.error_texels || !splittable) return whole;
  ConvolutionPlan halves = plan_halves(base, in, part, budget, level);
  return halves.worst_error_texels() < worst ? std::move(halves) : std::move(whole);
}

}  // namespace

ConvolutionPlan plan_convolution(const TexelSpace& space, const PlanInputs& in) {
  ConvolutionPlan plan;
  plan.receiver = in.receiver->name;
  plan.space = &space;
  plan.texel = texel_size(*in.receiver, space.width, space.height);
  plan.target = in.error_texels * plan.texel;
  for (std::size_t l = 0; l < in.lights->size(); ++l) {
    const Light& light = (*in.lights)[l];
    LightPart whole{int(l), light.desc().name, light, 1.0};
    merge_plan(plan, plan_light_part(plan, in, std::move(whole), in.max_triples, 0));
  }
  // Leaves the budget left above the tracing threshold are traced rather than convolved: their
  // values would be replaced anyway.
  if (in.ray_cost_per_texel > 0 && in.trace_error_texels >= 0) {
    for (Triple& t : plan.triples)
      if (t.children.empty() && !t.empty && t.penumbra_error_texels > in.trace_error_texels)
        t.traced = true;
  }
  for (const Triple& t : plan.triples) {
    if (t.children.empty() && t.blurred && !t.traced) {
      plan.warnings.push_back("receiver '" + plan.receiver +
                              "': a convolution image reached max_image and is coarser than "
                              "its sharpest penumbra; raise max_image to keep it sharp");
      break;
    }
  }
  const double worst = plan.worst_error_texels();
  if (worst > in.error_texels) {
    plan.warnings.push_back(
        "receiver '" + plan.receiver + "': penumbra error " + std::to_string(worst).substr(0, 5) +
        " texels after " + std::to_string(in.max_triples) +
        " triples per light, above error_texels = " + std::to_string(in.error_texels).substr(0, 5));
  }
  return plan;
}

}  // namespace sb
