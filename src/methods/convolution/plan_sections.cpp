// Convex closed solids in a plan (add_sections, convolution_plan.h): which triples are slabs
// of such solids, and the section leaves between their slabs, so that the bake can count the
// light each solid hides by Euler's formula (convolution_bake.cpp, docs/methods.md). The planner
// in convolution_plan.cpp makes the trees this walks.
#include <algorithm>
#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include "methods/convolution/convolution_plan.h"
#include "methods/convolution/source_image.h"
#include "occluders/clusters.h"
#include "occluders/tangent_bounds.h"

namespace sb {

namespace {

using Component = std::pair<int, int>;  // (mesh, connected component)

// The blockers' cluster tree by connected component: each component's root node, and the faces
// of each set of solids, one list shared by every triple that holds that set.
struct Components {
  const ClusterTree& tree;
  std::map<const Mesh*, int> mesh_index;
  std::map<Component, int> root_of;  // its cluster tree's root node
  // Every face of a set of solids, by their cluster roots.
  std::map<std::vector<int>, std::shared_ptr<const std::vector<FaceRef>>> solid_faces;

  explicit Components(const PlanInputs& in) : tree(*in.clusters) {
    for (std::size_t m = 0; m < in.blockers.size(); ++m) mesh_index.emplace(in.blockers[m], int(m));
    for (int r : tree.roots)
      root_of.emplace(Component(tree.nodes[r].mesh, tree.nodes[r].component), r);
  }

  // The component a blocker face belongs to.
  Component component_of(const FaceRef& f) const {
    const int m = mesh_index.at(f.mesh);
    return Component(m, tree.face_component[std::size_t(m)][std::size_t(f.face)]);
  }

  // A triple's faces counted by component.
  std::map<Component, std::size_t> count_faces(const Triple& t) const {
    std::map<Component, std::size_t> count;
    for (const FaceRef& f : t.faces) ++count[component_of(f)];
    return count;
  }

  // Every face of the solids whose (sorted) cluster roots are `roots`, listed once per set.
  std::shared_ptr<const std::vector<FaceRef>> faces_of(const PlanInputs& in,
                                                       const std::vector<int>& roots) {
    auto& faces = solid_faces[roots];
    if (!faces) {
      auto all = std::make_shared<std::vector<FaceRef>>();
      for (int root : roots) {
        const Cluster& node = tree.nodes[std::size_t(root)];
        for (int f : node.faces) all->push_back({in.blockers[std::size_t(node.mesh)], f});
      }
      faces = std::move(all);
    }
    return faces;
  }
};

// Whether triple i is complete (add_sections says when), from its faces counted by component and
// the flags of the triples before it, its parent's among them.
bool triple_complete(const ConvolutionPlan& plan, const Components& comps, std::size_t i,
                     const std::map<Component, std::size_t>& count,
                     const std::vector<std::uint8_t>& complete) {
  const Triple& t = plan.triples[i];
  if (t.parent < 0) {
    return std::all_of(count.begin(), count.end(), [&](const auto& c) {
      return c.second == comps.tree.nodes[std::size_t(comps.root_of.at(c.first))].faces.size();
    });
  }
  const Triple& parent = plan.triples[std::size_t(t.parent)];
  bool whole = complete[std::size_t(t.parent)];
  if (whole && parent.split == TripleSplit::blocker_space) {
    for (int sibling : parent.children) {
      if (sibling == int(i)) continue;
      for (const FaceRef& f : plan.triples[std::size_t(sibling)].faces)
        if (count.count(comps.component_of(f))) whole = false;
    }
  }
  return whole;
}

// The cluster roots of the components a complete triple holds, when each is a convex closed
// solid wholly beyond the frame's near depth; empty otherwise.
std::vector<int> convex_solid_roots(const Components& comps, const PlanFrame& fr,
                                    const std::map<Component, std::size_t>& count) {
  const ClusterTree& tree = comps.tree;
  std::vector<int> roots;
  for (const auto& [component, faces] : count) {
    const auto [m, c] = component;
    // Convex only: a non-convex solid's capped slabs cost convolutions and measured no gain
    // (the bracket), and Euler's count needs a line to meet the solid in one interval.
    if (!tree.component_closed[std::size_t(m)][std::size_t(c)] ||
        !tree.component_convex[std::size_t(m)][std::size_t(c)])
      return {};
    const int root = comps.root_of.at(component);
    double lo = 0, hi = 0;
    tree.nodes[std::size_t(root)].depth_range(fr.frame.origin, fr.frame.axis, &lo, &hi);
    // A section counts crossings from the light's side: the solid must lie wholly before it.
    if (!(lo > fr.near)) return {};
    roots.push_back(root);
  }
  return roots;
}

// Several solids count together only when no line from a receiver texel to the light can
// meet two of them within the slab: such a line's projection from the light's centre moves
// by at most the light's projected half extents times (1/d_lo − 1/d_hi) across the slab's
// depths, so solids whose projections lie further apart than that are never both met.
bool solids_apart(const ConvolutionPlan& plan, const ClusterTree& tree, const Triple& t,
                  const PlanFrame& fr, const std::vector<int>& roots) {
  bool solid = true;
  const Light& light = plan.light_parts[std::size_t(fr.light_part)].part;
  const Vec2 reach = projected_half_extents(light, fr.frame, t.view, t.receiver_depths.hi) *
                     (1.0 / t.blocker_depths.lo - 1.0 / t.blocker_depths.hi);
  std::vector<std::pair<Vec2, Vec2>> boxes;
  for (int root : roots) {
    const TangentBounds hull = tangent_bounds(fr.frame, tree.nodes[std::size_t(root)].hull);
    boxes.emplace_back(hull.lo - reach, hull.hi + reach);
  }
  for (std::size_t a = 0; a < boxes.size() && solid; ++a)
    for (std::size_t b = a + 1; b < boxes.size() && solid; ++b)
      solid = (boxes[a].second.array() < boxes[b].first.array()).any() ||
              (boxes[b].second.array() < boxes[a].first.array()).any();
  return solid;
}

// For a solid triple `top` whose parent is not solid: when its whole subtree is solid (or
// empty), marks it as one Euler count and adds a section leaf under each of its depth splits.
void add_section_leaves(ConvolutionPlan& plan, const PlanInputs& in, std::size_t top) {
  const Triple& t = plan.triples[top];
  if (!t.solid_faces || t.children.empty()) return;
  if (t.parent >= 0 && plan.triples[std::size_t(t.parent)].solid_faces) return;
  std::vector<int> subtree = {int(top)};
  bool whole = true;
  for (std::size_t k = 0; k < subtree.size() && whole; ++k) {
    const Triple& s = plan.triples[std::size_t(subtree[k])];
    if (!s.empty && !s.solid_faces) whole = false;
    for (int child : s.children) subtree.push_back(child);
  }
  if (!whole) return;
  for (int s : subtree) plan.triples[std::size_t(s)].euler = int(top);
  for (int s : subtree) {
    if (plan.triples[std::size_t(s)].split != TripleSplit::blocker_depth) continue;
    const Triple& split = plan.triples[std::size_t(s)];
    Triple section = child_triple(split, TripleSplit::none);
    section.parent = s;
    section.slab_lo = section.slab_hi = plan.triples[std::size_t(split.children[0])].slab_hi;
    section.faces = split.faces;
    section.solid_faces = split.solid_faces;
    section.euler = int(top);
    section.section = true;
    evaluate_triple(plan, in, section);
    if (section.empty) continue;
    plan.triples[std::size_t(s)].children.push_back(int(plan.triples.size()));
    plan.triples.push_back(std::move(section));
  }
}

}  // namespace

void add_sections(ConvolutionPlan& plan, const PlanInputs& in) {
  if (!in.clusters) return;
  Components comps(in);

  // A triple is complete when it holds every face of each component it touches that meets its
  // slab: a root holding whole components, and its descendants, except where a blocker-space
  // split shares a component between its two sides. Parents come before children in `triples`.
  const std::size_t n = plan.triples.size();
  std::vector<std::uint8_t> complete(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    Triple& t = plan.triples[i];
    const std::map<Component, std::size_t> count = comps.count_faces(t);
    complete[i] = triple_complete(plan, comps, i, count, complete);
    if (!complete[i] || t.empty) continue;
    const PlanFrame& fr = plan.frames[std::size_t(t.frame)];
    std::vector<int> roots = convex_solid_roots(comps, fr, count);
    if (roots.empty()) continue;
    if (roots.size() > 1 && !solids_apart(plan, comps.tree, t, fr, roots)) continue;
    std::sort(roots.begin(), roots.end());
    t.solid_faces = comps.faces_of(in, roots);
  }

  // Euler's count for a convex solid: a line meets it in one interval, which touches k
  // consecutive slabs and crosses the k − 1 sections between them inside the solid, so
  // Σ slabs − Σ sections is 1 for a line that meets the solid and 0 for one that misses it.
  for (std::size_t top = 0; top < n; ++top) add_section_leaves(plan, in, top);
}

}  // namespace sb
