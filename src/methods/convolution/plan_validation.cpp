// validate (convolution_plan.h): the cross-references of a convolution plan checked before the
// bake indexes arrays by them. The planner builds plans of light parts and halves apart and
// renumbers them as it merges them (convolution_plan.cpp); a wrong index there would read or
// write past a frame's texels or an image in release builds, so plans are checked where they are
// built and merged, in every build (core/error.h).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "methods/convolution/convolution_plan.h"

namespace sb {

namespace {

Status broken(const ConvolutionPlan& plan, const std::string& what) {
  return Error{ErrorKind::internal,
               fmt::format("convolution plan of receiver '{}': {}", plan.receiver, what)};
}

bool in_range(long long i, std::size_t size) { return i >= 0 && std::size_t(i) < size; }

// The face exists in its mesh.
bool valid_face(const FaceRef& f) { return f.mesh && in_range(f.face, f.mesh->mesh.n_faces()); }

// The grid of `group` (indices into a frame's arrays of `texels` entries) holds exactly its
// texels, in cells whose offsets are ordered.
std::string texel_index_problem(const TexelIndex& index, const std::vector<int>& group,
                                std::size_t texels) {
  if (index.nx <= 0 || index.ny <= 0) return "its grid has no cells";
  const std::size_t cells = std::size_t(index.nx) * std::size_t(index.ny);
  if (index.start.size() != cells + 1 || index.cells.size() != cells)
    return "its cell arrays do not match its grid";
  if (index.bx != (index.nx + TexelIndex::kBlock - 1) / TexelIndex::kBlock ||
      index.by != (index.ny + TexelIndex::kBlock - 1) / TexelIndex::kBlock ||
      index.blocks.size() != std::size_t(index.bx) * std::size_t(index.by))
    return "its blocks do not match its grid";
  if (index.start.front() != 0) return "its first cell does not start at 0";
  for (std::size_t c = 0; c < cells; ++c)
    if (index.start[c] > index.start[c + 1]) return "its cell offsets decrease";
  if (std::size_t(index.start.back()) != index.items.size() || index.items.size() != group.size())
    return "it does not hold its group's texels";
  for (int i : index.items)
    if (!in_range(i, texels)) return fmt::format("it holds texel {} of {}", i, texels);
  return "";
}

Status validate_frame(const ConvolutionPlan& plan, std::size_t f) {
  const PlanFrame& fr = plan.frames[f];
  const std::string name = fmt::format("frame {}", f);
  if (!in_range(fr.light_part, plan.light_parts.size()))
    return broken(
        plan, fmt::format("{}: light part {} of {}", name, fr.light_part, plan.light_parts.size()));
  if (fr.light != plan.light_parts[std::size_t(fr.light_part)].light)
    return broken(plan, name + ": its light is not its light part's");
  if (int(fr.face) < int(FrameFace::central) || int(fr.face) > int(FrameFace::cube_neg_z))
    return broken(plan, name + ": no such frustum");
  const std::size_t n = fr.texels.size();
  if (fr.depth.size() != n || fr.tangent.size() != n || fr.position.size() != n)
    return broken(plan, name + ": its per-texel arrays differ in length from its texels");
  const std::size_t space_texels = plan.space ? plan.space->texels.size() : 0;
  for (std::size_t t : fr.texels)
    if (t >= space_texels)
      return broken(plan, fmt::format("{}: receiver texel {} of {}", name, t, space_texels));
  if (fr.index.size() != fr.groups.size() || fr.roots.size() != fr.groups.size())
    return broken(plan, name + ": not one texel index and one root per group");
  for (std::size_t g = 0; g < fr.groups.size(); ++g) {
    const std::vector<int>& group = fr.groups[g];
    const std::string group_name = fmt::format("{}, group {}", name, g);
    if (group.empty()) return broken(plan, group_name + ": no texels");
    for (int i : group) {
      if (!in_range(i, n))
        return broken(plan, fmt::format("{}: texel {} of the frame's {}", group_name, i, n));
      // evaluate_triple reads the group's deepest depth at its last texel.
      if (fr.depth[std::size_t(i)] > fr.depth[std::size_t(group.back())])
        return broken(plan, group_name + ": its deepest texel is not its last");
      if (!(fr.depth[std::size_t(i)] > fr.near))
        return broken(plan, group_name + ": a texel at or before the frame's near depth");
    }
    if (const std::string problem = texel_index_problem(fr.index[g], group, n); !problem.empty())
      return broken(plan, fmt::format("{}: texel index: {}", group_name, problem));
    const int root = fr.roots[g];
    if (!in_range(root, plan.triples.size()))
      return broken(plan,
                    fmt::format("{}: root triple {} of {}", group_name, root, plan.triples.size()));
    const Triple& r = plan.triples[std::size_t(root)];
    if (r.parent != -1 || r.frame != int(f) || r.group != int(g))
      return broken(
          plan, fmt::format("{}: root triple {} is not a root of this group", group_name, root));
  }
  return Ok{};
}

// The fields bake_convolution reads of a leaf it convolves.
Status validate_leaf(const ConvolutionPlan& plan, std::size_t i, const std::string& name) {
  const Triple& t = plan.triples[i];
  if (t.blocker_depths.empty() || t.receiver_depths.empty() || t.footprint_texels <= 0 ||
      t.blockers.polygons.empty())
    return broken(plan, name + ": a leaf to convolve without blockers or receiver texels");
  if ((t.footprint_lo.array() > t.footprint_hi.array()).any())
    return broken(plan, name + ": its footprint's bounds are reversed");
  if (t.grid.width <= 0 || t.grid.height <= 0 || !(t.grid.pixel > 0) ||
      !std::isfinite(t.grid.pixel))
    return broken(plan, name + ": an empty image grid");
  // The transforms hold the images they convolve.
  if (t.fft_width < t.grid.width || t.fft_height < t.grid.height)
    return broken(plan, fmt::format("{}: transform {}x{} smaller than its image {}x{}", name,
                                    t.fft_width, t.fft_height, t.grid.width, t.grid.height));
  if (!(t.penumbra_error_texels >= 0) || !std::isfinite(t.penumbra_error_texels) ||
      !(t.cost >= 0) || !std::isfinite(t.cost))
    return broken(plan, name + ": its penumbra error or cost is negative or not finite");
  if (t.section) return Ok{};
  // Its share of the root layer's hard shadow: the layer's polygons come from the root's faces.
  if (!t.layer) return broken(plan, name + ": a leaf without its root's layer");
  const Triple* root = &t;
  while (root->parent >= 0) root = &plan.triples[std::size_t(root->parent)];
  for (const auto& pg : t.layer->polygons)
    if (!in_range(pg.source, root->faces.size()))
      return broken(plan, fmt::format("{}: a layer polygon of face {} of its root's {}", name,
                                      pg.source, root->faces.size()));
  return Ok{};
}

Status validate_triple(const ConvolutionPlan& plan, std::size_t i,
                       std::set<const std::vector<FaceRef>*>& solids_checked) {
  const Triple& t = plan.triples[i];
  const std::string name = fmt::format("triple {}", i);
  if (!in_range(t.frame, plan.frames.size()))
    return broken(plan, fmt::format("{}: frame {} of {}", name, t.frame, plan.frames.size()));
  const PlanFrame& fr = plan.frames[std::size_t(t.frame)];
  if (!in_range(t.group, fr.groups.size()))
    return broken(plan, fmt::format("{}: group {} of {}", name, t.group, fr.groups.size()));
  if (t.parent == -1) {
    if (fr.roots[std::size_t(t.group)] != int(i))
      return broken(plan, name + ": a root that is not its group's root");
  } else {
    // Parents before children: add_sections and the bake walk the triples in order.
    if (!in_range(t.parent, i))
      return broken(plan, fmt::format("{}: parent {} does not come before it", name, t.parent));
    const Triple& p = plan.triples[std::size_t(t.parent)];
    if (std::find(p.children.begin(), p.children.end(), int(i)) == p.children.end())
      return broken(plan, fmt::format("{}: its parent {} does not list it", name, t.parent));
    if (p.frame != t.frame || p.group != t.group)
      return broken(plan, name + ": not of its parent's frame and group");
  }
  if (!(t.slab_lo <= t.slab_hi)) return broken(plan, name + ": its slab's bounds are reversed");
  for (const ReceiverCut& c : t.cuts)
    if (!(c.band >= 0) || !std::isfinite(c.depth))
      return broken(plan, name + ": a receiver cut with a negative band or no depth");
  for (const FaceRef& f : t.faces)
    if (!valid_face(f))
      return broken(plan, fmt::format("{}: face {} not in its mesh", name, f.face));
  for (const auto& pg : t.blockers.polygons)
    if (!in_range(pg.source, t.faces.size()))
      return broken(
          plan, fmt::format("{}: a polygon of face {} of its {}", name, pg.source, t.faces.size()));

  // Children: each after it and naming it as parent; a split's two halves, and under a depth
  // split at most one section, at the depth where the halves meet.
  int halves = 0, sections = 0;
  for (int c : t.children) {
    if (!in_range(c, plan.triples.size()) || c <= int(i))
      return broken(plan, fmt::format("{}: child {} does not come after it", name, c));
    if (plan.triples[std::size_t(c)].parent != int(i))
      return broken(plan, fmt::format("{}: child {} names another parent", name, c));
    ++(plan.triples[std::size_t(c)].section ? sections : halves);
  }
  if ((t.split == TripleSplit::none) != t.children.empty())
    return broken(plan, name + ": children without a split, or a split without children");
  if (!t.children.empty()) {
    if (halves != 2) return broken(plan, fmt::format("{}: a split into {} parts", name, halves));
    if (sections > 0 && (sections > 1 || t.split != TripleSplit::blocker_depth))
      return broken(plan, name + ": a section under a split other than one by blocker depth");
    if (t.split == TripleSplit::blocker_depth) {
      const Triple& a = plan.triples[std::size_t(t.children[0])];
      const Triple& b = plan.triples[std::size_t(t.children[1])];
      if (a.slab_lo != t.slab_lo || a.slab_hi != b.slab_lo || b.slab_hi != t.slab_hi)
        return broken(plan, name + ": its depth split's slabs do not divide its own");
    }
  }

  // Euler's count: the head of a convex solid's splits comes first and heads itself.
  if (t.euler != -1) {
    if (!in_range(t.euler, i + 1))
      return broken(plan, fmt::format("{}: Euler head {} does not come before it", name, t.euler));
    const Triple& head = plan.triples[std::size_t(t.euler)];
    if (head.euler != t.euler || head.frame != t.frame)
      return broken(plan,
                    fmt::format("{}: Euler head {} is not a head of its frame", name, t.euler));
    if (!t.empty && !t.solid_faces)
      return broken(plan, name + ": counted by Euler's formula without its solid's faces");
  }
  if (t.solid_faces && solids_checked.insert(t.solid_faces.get()).second)
    for (const FaceRef& f : *t.solid_faces)
      if (!valid_face(f))
        return broken(plan, fmt::format("{}: solid face {} not in its mesh", name, f.face));
  if (t.section) {
    const Triple* p = t.parent >= 0 ? &plan.triples[std::size_t(t.parent)] : nullptr;
    if (!p || p->split != TripleSplit::blocker_depth || t.euler < 0 || !t.solid_faces ||
        !t.children.empty() || t.empty)
      return broken(plan, name + ": a section that is not a counted leaf under a depth split");
    if (t.slab_lo != t.slab_hi || t.slab_lo != plan.triples[std::size_t(p->children[0])].slab_hi)
      return broken(plan, name + ": a section away from its split's depth");
  }
  if (t.children.empty() && !t.empty) return validate_leaf(plan, i, name);
  return Ok{};
}

}  // namespace

Status validate(const ConvolutionPlan& plan, std::size_t lights) {
  if (!plan.frames.empty() && !plan.space) return broken(plan, "frames without a texel space");
  for (std::size_t p = 0; p < plan.light_parts.size(); ++p) {
    const LightPart& lp = plan.light_parts[p];
    if (!in_range(lp.light, lights))
      return broken(plan, fmt::format("light part {}: light {} of {}", p, lp.light, lights));
    if (!(lp.fraction > 0 && lp.fraction <= 1))
      return broken(plan, fmt::format("light part {}: a share of its light outside (0, 1]", p));
  }
  for (std::size_t f = 0; f < plan.frames.size(); ++f)
    if (Status s = validate_frame(plan, f); !s) return s;
  std::set<const std::vector<FaceRef>*> solids_checked;
  for (std::size_t i = 0; i < plan.triples.size(); ++i)
    if (Status s = validate_triple(plan, i, solids_checked); !s) return s;
  return Ok{};
}

}  // namespace sb
