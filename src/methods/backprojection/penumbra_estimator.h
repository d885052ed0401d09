// The back-projection estimator of one light's visibility at one texel, without noise
// (penumbra_estimator.cpp): the blocker polygons in the texel's shaft are projected from the
// texel's ray origin onto the light, rasterised row by row over the light, and the light's
// irradiance weight is integrated in closed form along each row over what they hide.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/geometry.h"
#include "methods/backprojection/light_rows.h"
#include "methods/backprojection/shaft_blockers.h"
#include "scene/lights.h"

namespace sb {

class RayScene;

class PenumbraEstimator {
 public:
  // `rows`: rows across the light (at most LightRows::kMaxRows). `light_offset`: how far short of
  // the light's surface a shadow ray stops (RayScene::surface_offset): geometry closer to the
  // light's plane than this (a ceiling around a flush panel) does not block it, as it does not
  // block the reference's rays.
  PenumbraEstimator(const Light& light, int rows, double light_offset);

  // The light's visibility at the texel whose surface point is `position` (shading normal
  // `normal`; the irradiance weight cosθ_light·cosθ_texel/r² is taken there) and whose shadow rays
  // leave from `origin`, given blocker polygons and convex solids that hold every blocker of
  // its shaft (the shaft's own polygons, ShaftCuller::shaft_polygons, or a tile's candidate
  // triangles, with those of convex solids given as the solids: the parts beyond the light's
  // plane or behind the origin are cut off here, and what projects outside the light or below
  // the texel's horizon hides nothing). `form_factor`: the light's F at the
  // texel (Light::form_factor) when the caller has it, else <= 0 and it is computed here.
  // `blocking`, when given, receives the triangles of the polygons and the keys of the solids
  // that reach the part of the light above the texel's horizon, sorted: those that may hide
  // some of it.
  // V = 1 exactly where nothing is blocked, 0 where every row is blocked from end to end.
  PenumbraSample visibility(const Vec3& position, const Vec3& normal, const Vec3& origin,
                            const Blockers& blockers, double form_factor = 0,
                            std::vector<std::uint32_t>* blocking = nullptr) const;
  // The same for polygons alone.
  PenumbraSample visibility(const Vec3& position, const Vec3& normal, const Vec3& origin,
                            const std::vector<BlockerPolygon>& polygons,
                            double form_factor = 0) const {
    return visibility(position, normal, origin, Blockers{&polygons, nullptr, nullptr}, form_factor);
  }

  // The same estimate with each pair of cells' blocking found by one shadow ray (32 per row:
  // 1024 at 32 rows) instead of from listed polygons: for shafts that hold too many polygons to
  // list (a dense mesh), where tracing costs less than rasterising. Deterministic like the rest:
  // the rays go to fixed points of the light's rows.
  PenumbraSample visibility_traced(const Vec3& position, const Vec3& normal, const Vec3& origin,
                                   const RayScene& scene, double form_factor = 0) const;

  // For the tests that show a wrong weight would be seen: the weight of the half of the light
  // with s > 0 (its turned frame) is multiplied by this. 1 in every bake.
  double weight_bias = 1.0;

 private:
  bool frame(const Vec3& position, LightFrame& f) const;
  // The rows for a texel: the light's own where all of it is above the texel's horizon, else
  // rows spread over the part above (so a sliver of light near the horizon has all of them).
  const LightRows& rows_for(const LightFrame& f, const Vec3& position, const Vec3& normal,
                            LightRows& scratch) const;
  double chord_half(double t, double radius) const;  // a disk's half chord
  void integrate(const LightFrame& f, const LightRows& rows, const Vec3& position,
                 const Vec3& normal, const BlockedRows& blocked, double form_factor,
                 PenumbraSample& out) const;

  const Light* light_;
  int row_count_;
  LightRows rows_;  // all of the light (a sphere's: of the unit disk)
  double light_offset_;
  Vec3 row_axis_s_, row_axis_t_;  // a rectangle's, disk's or polygon's frame (world)
  std::array<Vec2, 4> corners_;   // a rectangle's or polygon's corners in (s, t)
  double ball_radius_ = 0;        // of a ball about the light's centre that holds it
};

// The angle between a light's own axes and its rows, radians: far from 0°, 45° and 90°, the
// directions furniture and panels share most.
constexpr double kRowAngle = 0.4;

}  // namespace sb
