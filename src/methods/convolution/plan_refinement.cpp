// The refinement of a convolution plan's roots (docs/design.md §5;
// docs/design.md [S1], "Subdivision"): while the worst leaf's ε exceeds the
// target and the budget allows, the leaf is split where ε falls most per unit of estimated work,
// by blocker depth, blocker space or receiver depth.
#include "methods/convolution/plan_refinement.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <map>
#include <queue>
#include <tuple>
#include <utility>

#include "occluders/clusters.h"

namespace sb {

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
      best.front().split = TripleSplit::none;
      best.back().split = TripleSplit::none;
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
      Triple a = child_triple(t, TripleSplit::blocker_depth),
             b = child_triple(t, TripleSplit::blocker_depth);
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
        Triple a = child_triple(t, TripleSplit::blocker_space),
               b = child_triple(t, TripleSplit::blocker_space);
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
      Triple a = child_triple(t, TripleSplit::receiver_depth),
             b = child_triple(t, TripleSplit::receiver_depth);
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

void refine_triples(ConvolutionPlan& plan, const PlanInputs& in, std::size_t frame_begin,
                    std::size_t frame_end, int budget) {
  Planner(plan, in).refine(frame_begin, frame_end, budget);
}

}  // namespace sb
