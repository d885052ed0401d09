// Frames, texel groups and root triples of a convolution plan (docs/design.md §3): which frustum
// from a light part's centre serves which receiver texels, which texels share their blockers,
// and which blocker faces lie in the shaft between the light and each group. convolution_plan.cpp
// refines the roots made here.
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>

#include "methods/convolution/convolution_plan.h"
#include "occluders/clusters.h"
#include "occluders/light_frusta.h"

namespace sb {

namespace {

// Points whose convex hull holds the light: the shaft's light end.
std::vector<Vec3> light_outline(const Light& light) {
  std::vector<Vec3> pts;
  const Vec3 c = light.centre();
  std::array<Vec3, 4> corners;
  if (const int count = light.outline(corners); count > 0) {
    pts.assign(corners.begin(), corners.begin() + count);
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

// The receiver's index among the blockers, or -1.
int own_index(const PlanInputs& in) {
  for (std::size_t i = 0; i < in.blockers.size(); ++i)
    if (in.blockers[i] == in.receiver) return int(i);
  return -1;
}

// Lit texels that share their blockers: all of them, or, for a receiver that is its own blocker,
// those of one convex component, or of one plane of a non-convex one.
struct TexelGroup {
  std::vector<std::size_t> texels;  // indices into TexelSpace::texels
  int convex_component = -1;        // the receiver's own convex component, left out of blockers
  // All texels on one plane, with the light's centre in front of it at `height`: the group gets
  // its own frame along the plane's normal (add_frames).
  bool planar = false;
  Vec3 normal = Vec3::Zero();
  double height = 0;
};

std::vector<TexelGroup> group_texels(const TexelSpace& space, const PlanInputs& in,
                                     const std::vector<std::size_t>& lit, const Light& light) {
  const int own = own_index(in);
  std::map<std::pair<int, long long>, std::vector<std::size_t>> groups;
  // Neighbouring texels mostly share their group: the last one found saves a map search.
  std::pair<int, long long> last_key{-2, 0};
  std::vector<std::size_t>* last = nullptr;
  for (std::size_t t : lit) {
    std::pair<int, long long> key{-1, 0};
    if (own >= 0 && in.clusters) {
      const TriMesh& mesh = in.receiver->mesh;
      const int face = space.texels[t].face;
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
    if (!last || key != last_key) {
      last_key = key;
      last = &groups[key];
    }
    last->push_back(t);
  }
  // A curved non-convex component has a plane per face: then fall back to one group per
  // component (its nearby faces may then shadow it a little: docs/methods.md).
  std::map<int, int> planes_per_component;
  for (const auto& [key, members] : groups)
    if (key.first >= 0 && key.second != 0) ++planes_per_component[key.first];
  std::map<std::pair<int, long long>, std::vector<std::size_t>> merged;
  for (auto& [key, members] : groups) {
    auto k = key;
    if (k.first >= 0 && planes_per_component[k.first] > 64) k.second = 1;
    auto& dst = merged[k];
    dst.insert(dst.end(), members.begin(), members.end());
  }
  std::vector<TexelGroup> out;
  for (auto& [key, members] : merged) {
    TexelGroup g;
    g.convex_component = key.first >= 0 && key.second == 0 ? key.first : -1;
    // Planar: every texel's face normal within ~0.1° of the first's and every texel within
    // 0.1 mm of its plane.
    const Texel& first = space.texels[members.front()];
    const Vec3 n = space.geometric_normal(members.front()).cast<double>().normalized();
    const double offset = n.dot(first.position.cast<double>());
    g.planar = std::all_of(members.begin(), members.end(), [&](std::size_t t) {
      const Texel& x = space.texels[t];
      return space.geometric_normal(t).cast<double>().dot(n) > 1 - 2e-6 &&
             std::abs(n.dot(x.position.cast<double>()) - offset) < 1e-4;
    });
    g.height = n.dot(light.centre()) - offset;
    g.planar = g.planar && g.height > 0;
    g.normal = n;
    g.texels = std::move(members);
    out.push_back(std::move(g));
  }
  return out;
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
  for (int i : group) bounds.extend(fr.position[std::size_t(i)]);
  const Shaft shaft(light_outline(light), bounds);
  for (int node : clusters_in_shaft(*in.clusters, shaft)) {
    const Cluster& c = in.clusters->nodes[node];
    for (int f : c.faces)
      if (keep(c.mesh, f)) faces.push_back({in.blockers[c.mesh], f});
  }
  return faces;
}

}  // namespace

// The positions of the texels of groups `rest`, one group after another, as a range read in
// place (a receiver's texels can be millions). Written out rather than std::views::join, which
// clang 14, the fuzzing build's compiler, cannot compile against libstdc++ 12.
class GroupPositions {
 public:
  GroupPositions(const TexelSpace& space, const std::vector<TexelGroup>& groups,
                 const std::vector<int>& rest)
      : space_(space), groups_(groups), rest_(rest) {}

  class Iterator {
   public:
    Iterator(const GroupPositions& of, std::size_t group, std::size_t texel)
        : of_(&of), group_(group), texel_(texel) {
      skip_empty();
    }
    Vec3 operator*() const {
      const std::size_t t = of_->texels(group_)[texel_];
      return of_->space_.texels[t].position.cast<double>();
    }
    Iterator& operator++() {
      ++texel_;
      skip_empty();
      return *this;
    }
    bool operator!=(const Iterator& other) const {
      return group_ != other.group_ || texel_ != other.texel_;
    }

   private:
    // Onto the next texel there is, from the current place: past the ends of groups.
    void skip_empty() {
      while (group_ < of_->rest_.size() && texel_ == of_->texels(group_).size())
        ++group_, texel_ = 0;
    }
    const GroupPositions* of_;
    std::size_t group_, texel_;
  };

  Iterator begin() const { return Iterator(*this, 0, 0); }
  Iterator end() const { return Iterator(*this, rest_.size(), 0); }

 private:
  const std::vector<std::size_t>& texels(std::size_t r) const {
    return groups_[std::size_t(rest_[r])].texels;
  }
  const TexelSpace& space_;
  const std::vector<TexelGroup>& groups_;
  const std::vector<int>& rest_;
};

namespace {

// Each frame with the groups it serves: (index into `groups`, texels of that group in it).
struct FrameGroups {
  PlanFrame frame;
  std::vector<std::pair<int, std::vector<std::size_t>>> members;
};

// Texel t's position, in double precision.
Vec3 texel_position(const TexelSpace& space, std::size_t t) {
  return Vec3(space.texels[t].position.cast<double>());
}

// The texels the light part reaches, less those the shaft test finds nothing in front of.
std::vector<std::size_t> lit_texels(const TexelSpace& space, const PlanInputs& in,
                                    const LightPart& lp) {
  const Light& light = lp.part;
  std::vector<std::size_t> lit;
  const std::vector<std::uint8_t>* maybe =
      in.maybe_blocked ? &(*in.maybe_blocked)[std::size_t(lp.light)] : nullptr;
  for (std::size_t t = 0; t < space.texels.size(); ++t) {
    if (maybe && !(*maybe)[t]) continue;  // nothing between it and the light
    if (light.reaches(space.texels[t].position.cast<double>(),
                      space.texels[t].normal.cast<double>()))
      lit.push_back(t);
  }
  return lit;
}

// The frames that serve `groups` (add_frames says which), each with the texels it serves of
// each group.
std::vector<FrameGroups> choose_frames(const TexelSpace& space,
                                       const std::vector<TexelGroup>& groups, const Light& light) {
  std::vector<FrameGroups> frames;
  std::vector<int> rest;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (groups[g].planar) {
      FrameGroups f;
      f.frame.frame = frame_towards(light.centre(), light.centre() - groups[g].normal);
      f.frame.face = FrameFace::plane;
      f.members.emplace_back(int(g), groups[g].texels);
      frames.push_back(std::move(f));
    } else {
      rest.push_back(int(g));
    }
  }
  if (rest.empty()) return frames;
  const GroupPositions rest_positions(space, groups, rest);
  // Each leaf sizes its own pixels, so the tangent plane's stretch towards the widest angle
  // costs image size, not accuracy.
  if (const std::optional<ProjectionFrame> central =
          central_frustum(light.centre(), rest_positions)) {
    FrameGroups f;
    f.frame.frame = *central;
    for (int g : rest) f.members.emplace_back(g, groups[std::size_t(g)].texels);
    frames.push_back(std::move(f));
  } else {
    const std::size_t first = frames.size();
    for (int face = 0; face < kCubeFaces; ++face) {
      FrameGroups f;
      f.frame.frame = cube_face_frame(light.centre(), face);
      f.frame.face = cube_frame_face(face);
      for (int g : rest) f.members.emplace_back(g, std::vector<std::size_t>{});
      frames.push_back(std::move(f));
    }
    for (std::size_t r = 0; r < rest.size(); ++r) {
      for (std::size_t t : groups[std::size_t(rest[r])].texels) {
        const int face = cube_face(light.centre(), texel_position(space, t));
        frames[first + std::size_t(face)].members[r].second.push_back(t);
      }
    }
  }
  return frames;
}

// Fills the frame's texels, depths and groups from its members, and sets its near depth from
// the deepest texel; returns each group's convex component.
std::vector<int> gather_frame_texels(const TexelSpace& space, const std::vector<TexelGroup>& groups,
                                     FrameGroups& fg) {
  PlanFrame& f = fg.frame;
  std::vector<int> convex_component;
  double deepest = 0;
  std::size_t members = 0;
  for (const auto& m : fg.members) members += m.second.size();
  f.texels.reserve(members);
  f.depth.reserve(members);
  f.position.reserve(members);
  f.tangent.reserve(members);
  for (auto& [g, texels] : fg.members) {
    if (texels.empty()) continue;
    std::vector<int> members;
    for (std::size_t t : texels) {
      members.push_back(int(f.texels.size()));
      f.texels.push_back(t);
      f.depth.push_back(f.frame.depth(texel_position(space, t)));
      deepest = std::max(deepest, f.depth.back());
    }
    f.groups.push_back(std::move(members));
    convex_component.push_back(groups[std::size_t(g)].convex_component);
  }
  if (f.texels.empty()) return convex_component;
  // Texels this close to the light's plane across D (or behind it) cannot be projected; they
  // keep V = 1 and are counted. The choice of frusta keeps them rare.
  f.near = std::max(1e-4, 1e-3 * deepest);
  return convex_component;
}

// The frame's texels projected onto its tangent plane, those too near the light's plane left
// out of its groups (and groups left empty dropped, with their convex components).
void project_frame_texels(const TexelSpace& space, PlanFrame& f,
                          std::vector<int>& convex_component) {
  for (std::size_t i = 0; i < f.texels.size(); ++i) {
    f.position.push_back(texel_position(space, f.texels[i]));
    f.tangent.push_back(f.depth[i] > f.near ? f.frame.tangent(f.position.back()) : Vec2::Zero());
    if (f.depth[i] <= f.near) ++f.outside_texels;
  }
  std::vector<std::vector<int>> kept;
  std::vector<int> kept_component;
  for (std::size_t k = 0; k < f.groups.size(); ++k) {
    auto& g = f.groups[k];
    std::erase_if(g, [&](int i) { return f.depth[std::size_t(i)] <= f.near; });
    if (g.empty()) continue;
    // The deepest texel last (evaluate_triple reads the group's depth there); a full sort by
    // depth cost a tenth of the planning of a 2048² floor.
    std::iter_swap(
        std::max_element(g.begin(), g.end(), [&](int a, int b) { return f.depth[a] < f.depth[b]; }),
        g.end() - 1);
    kept.push_back(std::move(g));
    kept_component.push_back(convex_component[k]);
  }
  f.groups = std::move(kept);
  convex_component = std::move(kept_component);
}

// Appends a root triple per group of the frame plan.frames[index], each evaluated over the
// blocker faces in its shaft.
void add_roots(ConvolutionPlan& plan, const PlanInputs& in, const Light& light, int index,
               const std::vector<int>& convex_component) {
  PlanFrame& added = plan.frames[std::size_t(index)];
  for (std::size_t g = 0; g < added.groups.size(); ++g) {
    Triple root;
    root.frame = index;
    root.group = int(g);
    root.slab_lo = 0;
    root.slab_hi = std::numeric_limits<double>::infinity();
    root.faces = group_faces(plan, in, added, added.groups[g], light, convex_component[g]);
    for (int i : added.groups[g]) root.receiver_box.extend(added.position[std::size_t(i)]);
    evaluate_triple(plan, in, root);
    added.roots.push_back(int(plan.triples.size()));
    plan.triples.push_back(std::move(root));
  }
}

}  // namespace

// Frames, groups and root triples for one light part, appended to `plan`. A planar group (a
// floor, one face plane of a bracket) is seen along its plane's normal: every texel then lies at
// the same depth, the receiver plane of docs/design.md §2 is the group's own plane, and blockers
// clipped to depth <= that plane are exactly those on the light's side of it. The other groups
// share one frustum from the light's centre towards the middle of their texels (docs/design.md §3)
// when it holds them all within kMaxFrustumHalfAngleDeg; otherwise (a light beside or among its
// receiver) the six faces of a cube around the light, each its own frustum.
void add_frames(ConvolutionPlan& plan, const PlanInputs& in, int light_part) {
  const TexelSpace& space = *plan.space;
  const LightPart& lp = plan.light_parts[light_part];
  const Light& light = lp.part;
  const std::vector<std::size_t> lit = lit_texels(space, in, lp);
  if (lit.empty()) return;
  const std::vector<TexelGroup> groups = group_texels(space, in, lit, light);
  std::vector<FrameGroups> frames = choose_frames(space, groups, light);
  for (FrameGroups& fg : frames) {
    PlanFrame& f = fg.frame;
    f.light = lp.light;
    f.light_part = light_part;
    std::vector<int> convex_component = gather_frame_texels(space, groups, fg);
    if (f.texels.empty()) continue;
    project_frame_texels(space, f, convex_component);
    for (const auto& g : f.groups) {
      f.index.emplace_back();
      f.index.back().build(g, f.tangent, f.depth, f.position);
    }
    const int index = int(plan.frames.size());
    plan.frames.push_back(std::move(f));
    add_roots(plan, in, light, index, convex_component);
  }
}

}  // namespace sb
