// Which receiver texels a light reaches with nothing in the way, decided exactly (up to a
// conservative margin) instead of estimated: a texel's shaft is the convex hull of its shadow
// origin and the light; when no blocker triangle meets that hull, every shadow ray the texel
// could send reaches the light, and its visibility of that light is 1 without a ray or an image.
// On a scene as artists make them most (light, texel) pairs are such: a floor is in shadow only
// under and beside its furniture. The methods spend their work on the rest (shaft_culling.cpp).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/geometry.h"
#include "scene/lights.h"
#include "scene/mesh.h"
#include "texels/texel_space.h"

namespace sb {

class ShaftCuller {
 public:
  // A bounding volume hierarchy over every triangle of `blockers` (world space).
  explicit ShaftCuller(const std::vector<const Mesh*>& blockers);
  ShaftCuller(ShaftCuller&&) noexcept;
  ShaftCuller& operator=(ShaftCuller&&) noexcept;
  ~ShaftCuller();

  // Per texel of `space`: 1 where some blocker triangle may lie in the shaft between the texel's
  // shadow origin (lifted by `offset` along its face normal, as the reference's rays start) and
  // `light`, 0 where none can (or the light does not reach the texel). Parallel over texels; the
  // same result for any thread count.
  std::vector<std::uint8_t> maybe_blocked(const TexelSpace& space, const Light& light,
                                          double offset) const;

  // The same for one ray origin, above the surface point `surface` whose shading normal is
  // `normal`: true when a blocker may lie in its shaft.
  bool maybe_blocked(const Vec3& origin, const Vec3& surface, const Vec3& normal,
                     const Light& light) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sb
