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
// - ρ is taken over the receiver texels of the blocker cluster's footprint only (its projection
//   from the light's centre, grown by the widest penumbra), not the whole receiver: a post's
//   shadow needs the depths of the floor around the post, not of the whole floor. This is what
//   makes clusters pay: separate clusters have separate, small footprints.
// - The blockers of a triple are clipped to a slab of depth; a texel takes a slab's shadow in
//   proportion to how much of the slab's geometry lies in front of it (bake_convolution), so
//   geometry behind a texel never shadows it and contact shadows converge as slabs thin.
// - Self-shadowing: the receiver's own faces are blockers too, except for texels on a convex
//   component of the receiver, which cannot shadow itself (H0 already counts its horizon).
//   Texels of a non-convex component are grouped by the plane of their face, so that the
//   plane-side test of project_faces drops the faces they lie on.
#include "convolution_plan.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <queue>
#include <tuple>

#include "clusters.h"
#include "fft_convolution.h"

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
  for (int i : leaves()) worst = std::max(worst, triples[i].penumbra_error_texels);
  return worst;
}

double ConvolutionPlan::estimated_cost() const {
  double cost = 0;
  for (int i : leaves()) cost += triples[i].cost;
  return cost;
}

void TexelIndex::build(const std::vector<int>& texels, const std::vector<Vec2>& tangent) {
  if (texels.empty()) return;
  Vec2 hi = tangent[std::size_t(texels[0])];
  lo = hi;
  for (int i : texels) {
    lo = lo.cwiseMin(tangent[std::size_t(i)]);
    hi = hi.cwiseMax(tangent[std::size_t(i)]);
  }
  // About 16 texels per cell.
  const Vec2 span = (hi - lo).cwiseMax(1e-12);
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
}

namespace {

// The widest angle, from the light's centre, between a receiver's texels and its frustum's axis
// that one projection serves; beyond it the tangent plane stretches without bound (tan 60° = 1.7;
// each leaf sizes its own pixels, so the stretch costs image size, not accuracy).
constexpr double kMaxFrustumHalfAngleDeg = 60.0;
// Light splits: at most this many halvings (2^3 = 8 parts).
constexpr int kMaxLightSplits = 3;

double light_radius(const Light& light) {
  return light.shape() == LightShape::rectangle
             ? 0.5 * std::hypot(light.desc().width, light.desc().height)
             : light.desc().radius;
}

// Points whose convex hull holds the light: the shaft's light end.
std::vector<Vec3> light_outline(const Light& light) {
  std::vector<Vec3> pts;
  const Vec3 c = light.centre();
  if (light.shape() == LightShape::rectangle) {
    const Vec3 a = 0.5 * light.desc().width * light.right(), b = 0.5 * light.desc().height * light.up();
    for (const Vec3& p : {Vec3(c + a + b), Vec3(c + a - b), Vec3(c - a + b), Vec3(c - a - b)})
      pts.push_back(p);
  } else if (light.shape() == LightShape::disk) {
    const int n = 16;  // circumscribed 16-gon
    const double r = light.desc().radius / std::cos(std::numbers::pi / n);
    for (int i = 0; i < n; ++i) {
      const double phi = 2 * std::numbers::pi * i / n;
      pts.push_back(c + r * (std::cos(phi) * light.right() + std::sin(phi) * light.up()));
    }
  } else {
    const double r = light.desc().radius;
    for (int i = 0; i < 8; ++i)
      pts.push_back(c + r * Vec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
  }
  return pts;
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
  const auto [part_lo, part_hi] = part_interval(t.cuts);
  if (t.faces.empty() || group.empty()) return;
  const double part_depth_hi = std::min(part_hi, fr.depth[group.back()]);

  ShadowCaster caster;
  caster.light_radius = light_radius(light);
  caster.receiver = t.receiver_box;
  t.blockers = project_faces(t.faces, fr.frame, std::max(t.slab_lo, fr.near),
                             std::min(t.slab_hi, part_depth_hi), caster);
  t.polygons = int(t.blockers.polygons.size());
  if (t.blockers.polygons.empty()) return;
  if (!t.layer) t.layer = std::make_shared<const ProjectedBlockers>(t.blockers);
  DepthRange blocker_depths;
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& pg : t.blockers.polygons) {
    blocker_depths.extend(pg.depth_lo);
    blocker_depths.extend(pg.depth_hi);
    lo = lo.cwiseMin(pg.lo);
    hi = hi.cwiseMax(pg.hi);
  }
  // The footprint: the blockers' projection grown by the widest penumbra they can cast on the
  // part, k_max times the light's half extents (tangent units).
  const Vec2 half = light.half_extents(fr.frame.e1, fr.frame.e2);
  const double k_max = std::max(0.0, 1.0 / blocker_depths.lo - 1.0 / part_depth_hi);
  lo -= half * k_max;
  hi += half * k_max;
  DepthRange receiver_depths;
  Vec2 tlo = Vec2::Constant(std::numeric_limits<double>::infinity()), thi = -tlo;
  Bounds3 box;
  fr.index[std::size_t(t.group)].for_each(lo, hi, [&](int i) {
    const double d = fr.depth[i];
    if (d <= blocker_depths.lo || d < part_lo || d > part_hi) return;
    const Vec2& tc = fr.tangent[i];
    if ((tc.array() < lo.array()).any() || (tc.array() > hi.array()).any()) return;
    receiver_depths.extend(d);
    tlo = tlo.cwiseMin(tc);
    thi = thi.cwiseMax(tc);
    box.extend(Vec3(plan.space->texels[fr.texels[i]].position.cast<double>()));
    ++t.footprint_texels;
  });
  if (receiver_depths.empty()) return;
  t.empty = false;
  t.receiver_box = box;
  t.blocker_depths = blocker_depths;
  t.receiver_depths = receiver_depths;
  t.footprint_lo = tlo;
  t.footprint_hi = thi;
  const double extent = light.extent_across(fr.frame.axis);
  t.config = choose_configuration(fr.frame, blocker_depths, receiver_depths, extent);
  t.penumbra_error_texels = plan.texel > 0 ? t.config.penumbra_error / plan.texel : 0;
  t.smallest_penumbra = extent * (t.config.rho_lo - 1.0);

  // Image resolution: one pixel per receiver texel at the receiver plane, coarser only where the
  // narrowest penumbra spans 64 pixels anyway (design-notes §5, "texture
  // resolution"); then within max_image, flagging any loss of detail.
  const double r_star = t.config.receiver_plane;
  const double detail = std::max(plan.texel, t.smallest_penumbra / 64.0);
  double pixel = (plan.texel > 0 ? detail : (thi - tlo).maxCoeff() / 512) / r_star;
  const double k = std::max(0.0, 1.0 / t.config.blocker_plane - 1.0 / r_star);
  const Vec2 kernel_extent = 2 * k * half;
  const Vec2 span = thi - tlo;
  const double needed = (span + kernel_extent).maxCoeff();
  if (needed / pixel + 8 > in.max_image) {
    pixel = needed / (in.max_image - 8);
    t.blurred = pixel * r_star > 1.01 * std::max(plan.texel, t.smallest_penumbra / 2.0);
  } else {
    t.blurred = false;
  }
  const int kernel_w = 2 * int(std::ceil(kernel_extent.x() / (2 * pixel))) + 1;
  const int kernel_h = 2 * int(std::ceil(kernel_extent.y() / (2 * pixel))) + 1;
  const int margin_x = kernel_w / 2 + 1, margin_y = kernel_h / 2 + 1;
  t.grid.pixel = pixel;
  t.grid.origin = tlo - Vec2(margin_x, margin_y) * pixel;
  t.grid.width = int(std::ceil(span.x() / pixel)) + 2 * margin_x + 1;
  t.grid.height = int(std::ceil(span.y() / pixel)) + 2 * margin_y + 1;
  t.fft_width = FftConvolver::fast_size(t.grid.width);
  t.fft_height = FftConvolver::fast_size(t.grid.height);
  const double n = double(t.fft_width) * t.fft_height;
  t.cost = n * std::log2(std::max(2.0, n)) * (light.textured() ? 3 : 1) +
           30.0 * double(t.footprint_texels) + 20.0 * double(t.faces.size());
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
    while (!queue.empty() && leaves < budget) {
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
  bool over(int t) const {
    return !plan_.triples[t].empty &&
           plan_.triples[t].penumbra_error_texels > in_.error_texels * (1 + 1e-9);
  }

  Triple child_of(const Triple& parent, const char* split) const {
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
      Triple a = child_of(t, "blocker depth"), b = child_of(t, "blocker depth");
      a.slab_hi = b.slab_lo = mid;
      std::vector<int> near_polys, far_polys;
      for (int p : all) {
        if (polys[p].depth_lo <= mid) near_polys.push_back(p);
        if (polys[p].depth_hi >= mid) far_polys.push_back(p);
      }
      a.faces = surviving(t, near_polys);
      b.faces = surviving(t, far_polys);
      out.push_back(evaluate_pair(std::move(a), std::move(b)));
    }
    // Blocker space: two clusters either side of the median polygon centroid along the wider
    // axis of their tangent bounding box.
    if (polys.size() >= 2) {
      std::vector<Vec2> centroid(polys.size());
      Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
      for (std::size_t i = 0; i < polys.size(); ++i) {
        centroid[i] = 0.5 * (polys[i].lo + polys[i].hi);
        lo = lo.cwiseMin(centroid[i]);
        hi = hi.cwiseMax(centroid[i]);
      }
      const int axis = (hi - lo).x() >= (hi - lo).y() ? 0 : 1;
      if (hi[axis] > lo[axis]) {
        std::vector<int> order = all;
        const auto middle = order.begin() + std::ptrdiff_t(order.size() / 2);
        std::nth_element(order.begin(), middle, order.end(),
                         [&](int a, int b) { return centroid[a][axis] < centroid[b][axis]; });
        Triple a = child_of(t, "blocker space"), b = child_of(t, "blocker space");
        a.faces = surviving(t, std::vector<int>(order.begin(), middle));
        b.faces = surviving(t, std::vector<int>(middle, order.end()));
        out.push_back(evaluate_pair(std::move(a), std::move(b)));
      }
    }
    // Receiver depth: two parts either side of the middle of the footprint's depths, blended over
    // a band of a tenth of the range (at least a texel) each way.
    if (t.receiver_depths.hi - t.receiver_depths.lo > 2 * texel) {
      const double mid = t.receiver_depths.mid();
      const double band = std::max(texel, 0.1 * (t.receiver_depths.hi - t.receiver_depths.lo));
      Triple a = child_of(t, "receiver depth"), b = child_of(t, "receiver depth");
      a.cuts.push_back({mid, band, true});
      b.cuts.push_back({mid, band, false});
      a.faces = b.faces = surviving(t, all);
      out.push_back(evaluate_pair(std::move(a), std::move(b)));
    }
    return out;
  }

  std::vector<Triple> evaluate_pair(Triple a, Triple b) {
    evaluate_triple(plan_, in_, a);
    evaluate_triple(plan_, in_, b);
    std::vector<Triple> pair;
    pair.push_back(std::move(a));
    pair.push_back(std::move(b));
    return pair;
  }

  ConvolutionPlan& plan_;
  const PlanInputs& in_;
};

}  // namespace

namespace {

// The receiver's index among the blockers, or -1.
int own_index(const PlanInputs& in) {
  for (std::size_t i = 0; i < in.blockers.size(); ++i)
    if (in.blockers[i] == in.receiver) return int(i);
  return -1;
}

// Splits a frame's texels into groups that share their blockers (PlanFrame::groups), and gives
// each group's key: (component, convex) of the receiver's own geometry, or (-1, ·) for all.
void group_texels(const TexelSpace& space, const PlanInputs& in, PlanFrame& fr,
                  std::vector<int>* group_component) {
  const int own = own_index(in);
  std::map<std::pair<int, long long>, std::vector<int>> groups;
  std::map<std::pair<int, long long>, int> component_of;
  for (std::size_t i = 0; i < fr.texels.size(); ++i) {
    if (fr.depth[i] <= fr.near) continue;
    std::pair<int, long long> key{-1, 0};
    if (own >= 0 && in.clusters) {
      const TriMesh& mesh = in.receiver->mesh;
      const int face = space.texels[fr.texels[i]].face;
      const int comp = in.clusters->face_component[own][face];
      key.first = comp;
      if (!in.clusters->component_convex[own][comp]) {
        // The plane of the texel's face, quantised: normal to ~0.3°, offset to 1 mm.
        const auto fh = mesh.face_handle(face);
        const auto n = mesh.normal(fh);
        const auto p = mesh.point(*mesh.cfv_begin(fh));
        long long h = 0;
        for (int k = 0; k < 3; ++k) h = h * 1001 + std::llround(n[k] * 200) + 500;
        h = h * 1000003 + std::llround((n | p) * 1000);
        key.second = h;
      }
    }
    groups[key].push_back(int(i));
    component_of[key] = key.first;
  }
  // A curved non-convex component has a plane per face: then fall back to one group per
  // component (its nearby faces may then shadow it a little: docs/methods.md).
  std::map<int, int> planes_per_component;
  for (const auto& [key, members] : groups)
    if (key.first >= 0 && key.second != 0) ++planes_per_component[key.first];
  std::map<std::pair<int, long long>, std::vector<int>> merged;
  for (auto& [key, members] : groups) {
    auto k = key;
    if (k.first >= 0 && planes_per_component[k.first] > 64) k.second = 1;
    auto& dst = merged[k];
    dst.insert(dst.end(), members.begin(), members.end());
  }
  for (auto& [key, members] : merged) {
    std::sort(members.begin(), members.end(),
              [&](int a, int b) { return fr.depth[a] < fr.depth[b]; });
    fr.groups.push_back(std::move(members));
    group_component->push_back(key.first >= 0 && key.second == 0 ? key.first : -1);
  }
}

// The candidate blocker faces of a group: those of the clusters in the shaft between the light
// and the group's texels, less the group's own convex component.
std::vector<FaceRef> group_faces(const ConvolutionPlan& plan, const PlanInputs& in,
                                 const PlanFrame& fr, const std::vector<int>& group,
                                 const Light& light, int convex_component) {
  const int own = own_index(in);
  std::vector<FaceRef> faces;
  auto keep = [&](int mesh, int face) {
    return !(mesh == own && convex_component >= 0 &&
             in.clusters->face_component[mesh][face] == convex_component);
  };
  if (!in.clusters) {
    for (std::size_t m = 0; m < in.blockers.size(); ++m)
      for (auto f : in.blockers[m]->mesh.faces())
        if (keep(int(m), f.idx())) faces.push_back({in.blockers[m], f.idx()});
    return faces;
  }
  Bounds3 bounds;
  for (int i : group) bounds.extend(Vec3(plan.space->texels[fr.texels[i]].position.cast<double>()));
  const Shaft shaft(light_outline(light), bounds);
  for (int node : clusters_in_shaft(*in.clusters, shaft)) {
    const Cluster& c = in.clusters->nodes[node];
    for (int f : c.faces)
      if (keep(c.mesh, f)) faces.push_back({in.blockers[c.mesh], f});
  }
  return faces;
}

// Frames, groups and root triples for one light part, appended to `plan`.
void add_frames(ConvolutionPlan& plan, const PlanInputs& in, int light_part) {
  const TexelSpace& space = *plan.space;
  const LightPart& lp = plan.light_parts[light_part];
  const Light& light = lp.part;
  std::vector<std::size_t> lit;
  Bounds3 lit_bounds;
  for (std::size_t t = 0; t < space.texels.size(); ++t) {
    const Vec3 p = space.texels[t].position.cast<double>();
    if (!light.reaches(p, space.texels[t].normal.cast<double>())) continue;
    lit.push_back(t);
    lit_bounds.extend(p);
  }
  if (lit.empty()) return;
  auto position = [&](std::size_t t) { return Vec3(space.texels[t].position.cast<double>()); };
  // One frustum from the light's centre towards the middle of the lit texels (design-notes §3)
  // when it holds them all within kMaxFrustumHalfAngleDeg; otherwise (a light beside or among
  // its receiver) the six faces of a cube around the light, each its own frustum.
  const ProjectionFrame central = frame_towards(light.centre(), lit_bounds.centre());
  double widest = 1.0;
  for (std::size_t t : lit) {
    const Vec3 d = position(t) - light.centre();
    const double len = d.norm();
    widest = std::min(widest, len > 0 ? d.dot(central.axis) / len : 1.0);
  }
  std::vector<PlanFrame> frames;
  if (widest >= std::cos(kMaxFrustumHalfAngleDeg * std::numbers::pi / 180.0)) {
    PlanFrame f;
    f.frame = central;
    f.texels = lit;
    frames.push_back(std::move(f));
  } else {
    static const char* kFaces[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
    frames.resize(6);
    for (int f = 0; f < 6; ++f) {
      Vec3 axis = Vec3::Zero();
      axis[f / 2] = f % 2 ? -1.0 : 1.0;
      frames[f].frame = frame_towards(light.centre(), light.centre() + axis);
      frames[f].face = kFaces[f];
    }
    for (std::size_t t : lit) {
      const Vec3 d = position(t) - light.centre();
      int axis;
      d.cwiseAbs().maxCoeff(&axis);
      frames[2 * axis + (d[axis] < 0 ? 1 : 0)].texels.push_back(t);
    }
  }
  for (PlanFrame& f : frames) {
    if (f.texels.empty()) continue;
    f.light = lp.light;
    f.light_part = light_part;
    double deepest = 0;
    for (std::size_t t : f.texels) {
      f.depth.push_back(f.frame.depth(position(t)));
      deepest = std::max(deepest, f.depth.back());
    }
    // Texels this close to the light's plane across D (or behind it) cannot be projected; they
    // keep V = 1 and are counted. The choice of frusta keeps them rare.
    f.near = std::max(1e-4, 1e-3 * deepest);
    for (std::size_t i = 0; i < f.texels.size(); ++i) {
      f.tangent.push_back(f.depth[i] > f.near ? f.frame.tangent(position(f.texels[i]))
                                              : Vec2::Zero());
      if (f.depth[i] <= f.near) ++f.outside_texels;
    }
    std::vector<int> convex_component;
    group_texels(space, in, f, &convex_component);
    for (const auto& g : f.groups) {
      f.index.emplace_back();
      f.index.back().build(g, f.tangent);
    }
    const int index = int(plan.frames.size());
    plan.frames.push_back(std::move(f));
    PlanFrame& added = plan.frames.back();
    for (std::size_t g = 0; g < added.groups.size(); ++g) {
      Triple root;
      root.frame = index;
      root.group = int(g);
      root.slab_lo = 0;
      root.slab_hi = std::numeric_limits<double>::infinity();
      root.faces = group_faces(plan, in, added, added.groups[g], light, convex_component[g]);
      for (int i : added.groups[g])
        root.receiver_box.extend(Vec3(space.texels[added.texels[i]].position.cast<double>()));
      evaluate_triple(plan, in, root);
      added.roots.push_back(int(plan.triples.size()));
      plan.triples.push_back(std::move(root));
    }
  }
}

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

// Plans one light part within `budget` leaves; when the target is missed, tries the part's two
// halves (a source subdivision, design-notes §5) with half the budget each and keeps the plan
// with the smaller worst ε.
ConvolutionPlan plan_light_part(const ConvolutionPlan& base, const PlanInputs& in, LightPart part,
                                int budget, int level) {
  ConvolutionPlan whole = empty_like(base);
  whole.light_parts.push_back(part);
  add_frames(whole, in, 0);
  Planner(whole, in).refine(0, whole.frames.size(), budget);
  const double worst = whole.worst_error_texels();
  const LightDesc& d = part.part.desc();
  const bool splittable =
      d.shape == LightShape::rectangle && !part.part.textured() && level < kMaxLightSplits;
  if (worst <= in.error_texels || !splittable) return whole;
  ConvolutionPlan halves = empty_like(base);
  for (int side = 0; side < 2; ++side) {
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
    LightPart half{part.light, part.name + "." + std::to_string(side), Light(h), 0.5 * part.fraction};
    merge_plan(halves, plan_light_part(base, in, std::move(half), std::max(1, budget / 2), level + 1));
  }
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
  for (const Triple& t : plan.triples) {
    if (t.children.empty() && t.blurred) {
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
