// Blocker triangles that pass through a sphere light's ball, as the estimator must take them.
//
// A level's light often sits inside its fixture: OpenArena's flames are two crossed quads
// through the light's centre. The estimator sees a sphere as the disk of its silhouette
// (penumbra_estimator.h) and cuts what lies beyond that disk's plane; a quad through the centre
// lies in front of it in part, and would hide the disk, where the reference's rays, which end on
// the sphere's near side (Light::above_horizon), pass it: no part of a blocker inside the ball
// lies between a point outside it and the near side it sees. So a triangle that meets the ball is
// taken as its parts outside it: the triangle less the regular polygon of kSides corners
// inscribed in the circle the ball cuts from its plane, in triangles. What that keeps of the ball
// (the circle's rim outside the polygon, 0.6 % of the circle's area at 32 sides) still hides, a
// little, what it should not.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/geometry.h"
#include "occluders/shaft_culling.h"
#include "scene/lights.h"

namespace sb {

struct PiercingBlockers {
  static constexpr int kSides = 32;
  // What a part reports as its umbra where it hides all of the light alone (BlockerPolygon::
  // source): this bit and its index in `parts`, apart from every triangle's and blocker key's.
  static constexpr std::uint32_t kPartUmbra = 0x20000000u;
  std::vector<std::uint32_t> triangles;  // the culler's triangles that meet the ball, ascending
  // Their parts outside the ball, in triangles: triangles[k]'s are parts[first[k], first[k+1]).
  std::vector<std::array<Vec3, 3>> parts;
  std::vector<std::uint32_t> first;

  bool empty() const { return triangles.empty(); }
  bool pierces(std::uint32_t triangle) const;
  // The parts of `triangle`, which pierces.
  std::span<const std::array<Vec3, 3>> parts_of(std::uint32_t triangle) const;
};

// The blocker triangles that pass through `light`'s ball, for a sphere light (none for others).
PiercingBlockers piercing_blockers(const ShaftCuller& culler, const Light& light);

}  // namespace sb
