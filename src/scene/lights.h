// Area lights as the bake methods see them: emission, closed-form unoccluded irradiance H0
// (docs/design.md §1) and stratified sampling for the ray-traced reference.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/geometry.h"
#include "core/image.h"
#include "scene/scene.h"

namespace sb {

// A point on a light chosen for one shadow ray, with its weight in the ratio estimator
// V = Σ w·v / Σ w (lights.cpp says why that estimator).
struct LightSample {
  Vec3 point;
  double weight = 0;  // 0: the sample cannot contribute (behind the light or below the horizon)
  Vec3 tint = Vec3::Ones();  // the emission texture at the point (ones for an untextured light)
};

class Light;
class Sky;

// The part of a light above the horizon of a point (Light::above_horizon), for the reference's
// samples: where the whole light is above, sample() as it is; where the horizon cuts it, the
// polygon it leaves above (a disk, or a sphere's silhouette disk, as the regular 128-gon of its
// area that its closed form clips too), sampled uniformly by area, so that every sample
// contributes and a light cut by a texel's horizon is estimated from all of them rather than
// from the few that fall above, or left out when none does.
class HorizonPart {
 public:
  // A point of the part for a stratified u ∈ [0,1)², weighted so that Σ w·v / Σ w over such
  // samples converges to V = H / H0.
  LightSample sample(const Vec2& u) const;
  bool empty() const { return !whole_ && area_.empty(); }

 private:
  friend class Light;
  const Light* light_ = nullptr;
  Vec3 y_, n_;
  bool whole_ = true;
  // The clipped polygon as a fan of triangles (3 corners each) and their cumulative areas; for a
  // sphere, the polygon lies in its silhouette's plane, `plane` metres from y.
  std::vector<Vec3> fan_;
  std::vector<double> area_;
  double plane_ = 0;
};

class Light {
 public:
  // `texture`, if given, is the emission image mapped over a rectangle or disk (linear RGB or
  // grey; row 0 is the top, along `up`).
  // `output`: the index, among the scene's lights, of the light this one is or is a part of (a
  // mesh light's parts, make_lights): whose per-light images it adds to (LightMix).
  // `sky`: the sky this light is a part of (make_lights), whose own rays the reference traces.
  explicit Light(const LightDesc& desc, std::shared_ptr<const Image> texture = nullptr,
                 int output = 0, std::shared_ptr<const Sky> sky = nullptr);

  const LightDesc& desc() const { return desc_; }
  // The light's own random streams' key, from its name alone: a light is sampled the same way
  // whatever other lights the scene holds and in whatever order, so its per-light output equals
  // a bake of the scene with that light alone (docs/cli.md, per-light outputs).
  std::uint64_t stream() const { return stream_; }
  LightShape shape() const { return desc_.shape; }
  int output() const { return output_; }
  // The sky this light is a part of, or null.
  const Sky* sky() const { return sky_.get(); }
  Vec3 centre() const { return desc_.position; }
  // A rectangle's four corners or a polygon's three or four (world metres, in order around it;
  // a triangle's last corner repeated in the fourth slot); 0 for the round shapes.
  int outline(std::array<Vec3, 4>& corners) const;
  // A point light: a sphere of kPointLightRadius (scene.h), whose shadows are hard.
  bool is_point() const {
    return desc_.shape == LightShape::sphere && desc_.radius <= kPointLightRadius;
  }
  // Emitting surface area in m² (a sphere's whole surface; a rectangle or disk's one side).
  double area() const;
  // Radiant exitance per channel, W/m², averaged over the light: color · power / area, times the
  // texture's mean for a textured light.
  Vec3 exitance() const { return exitance_; }
  bool textured() const { return texture_ != nullptr; }
  // The texture's value (bilinear) at a point given in metres in the light's (right, up) frame;
  // ones for an untextured light.
  Vec3 tint(const Vec2& local) const;
  // Largest distance across the light seen along `axis`: the length that the penumbra error
  // metric multiplies (docs/design.md §4), metres.
  double extent_across(const Vec3& axis) const;
  // Half the light's extent along each of two unit directions e1, e2 across the axis of
  // projection (the bounding box of its outline seen along that axis), metres.
  Vec2 half_extents(const Vec3& e1, const Vec3& e2) const;
  // What the source image of docs/design.md §2 holds at a point of the plane through the centre
  // perpendicular to `axis` (given as an offset from the centre): the light's relative emission
  // (per channel, tint times 1) where the line through the point along `axis` meets the light,
  // 0 where it misses. A sphere is a uniform disk of its radius.
  Vec3 source_image(const Vec3& offset, const Vec3& axis) const;
  // Unit axes of a rectangle, disk or polygon: right = up × normal; the normal is the emitting
  // side.
  const Vec3& right() const { return right_; }
  const Vec3& up() const { return up_; }
  const Vec3& normal() const { return desc_.normal; }

  // Unoccluded irradiance H0 at point y with unit normal n, per channel, W/m², in closed form:
  // H0 = E · F where F is the form factor from the point to the light, clipped to the point's
  // horizon. Rectangle: Lambert's polygon formula (exact). Disk, and a sphere through the disk of
  // its silhouette: the elementary closed form when the disk is wholly above the horizon, and a
  // 128-gon of equal area, clipped, otherwise (relative error < 1e-4, tested). A textured light
  // uses its mean exitance: exact for a uniform texture, the far-field value otherwise.
  Vec3 unoccluded_irradiance(const Vec3& y, const Vec3& n) const;
  // Whether any of the light lies above the horizon of (y, n) and faces y, i.e. F > 0, and y is
  // inside a spot's cone and the light's range; much cheaper than F itself.
  bool reaches(const Vec3& y, const Vec3& n) const;
  // True only where reaches(y, n) holds at every point y of the box: a rectangle's, disk's or
  // polygon's conditions are linear in y, so they hold inside if they hold at its corners (with
  // a margin against rounding). False where it cannot tell (a sphere, a spot, a mesh or sky).
  bool reaches_all(const Bounds3& ys, const Vec3& n) const;
  // The same for every point of ys with every normal of the box `ns` (a curved receiver's): a
  // sphere wholly above every such horizon (its height over it bounded below term by term);
  // another shape where the box is of one normal, as reaches_all(ys, n).
  bool reaches_all(const Bounds3& ys, const Bounds3& ns) const;
  // True only where reaches(y, n) fails at every point y of the box with every normal of `ns`:
  // beyond the range throughout (any shape), or a sphere wholly below every such horizon.
  bool reaches_none(const Bounds3& ys, const Bounds3& ns) const;
  // The form factor F alone (dimensionless, H0 = E · F · spot_factor).
  double form_factor(const Vec3& y, const Vec3& n) const;
  // A spot's cone at y (LightDesc::spot_axis): 1 inside the inner cone, 0 outside the outer one,
  // and between them KHR_lights_punctual's falloff, the square of (cos θ − cos θ_outer) /
  // (cos θ_inner − cos θ_outer), θ the angle between the axis and the direction from the centre
  // to y. 1 everywhere for a light that is not a spot. It scales the light's irradiance, not
  // its visibility: every method reads it through unoccluded_irradiance and reaches.
  double spot_factor(const Vec3& y) const;
  // The light's reach at y (LightDesc::range): KHR_lights_punctual's recommended window,
  // clamp(1 − (d/range)⁴, 0, 1) with d the distance from the centre (its 1/d² is the form
  // factor's own), 0 at and beyond the range, 1 everywhere for a light without one. Like the
  // spot's cone it scales the light's irradiance, not its visibility (every method reads it
  // through unoccluded_irradiance and reaches).
  double range_factor(const Vec3& y) const;
  // Whether the light may reach some point of the box `ys` (some normal): inside its range, in
  // front of a flat light, within a spot's cone. Conservative: false only where no point of the
  // box is reached; what methods and the light lists (methods/light_lists.h) cull by.
  bool may_reach(const Bounds3& ys) const;
  // The same for a box of points that all have the unit normal n.
  bool may_reach(const Bounds3& ys, const Vec3& n) const;

  // Maps a stratified point u ∈ [0,1)² to a light sample as seen from y with normal n.
  // Rectangle and disk: uniform in area, weight cosθ_light · cosθ_receiver / r².
  // Sphere: uniform in the solid angle of the cone it subtends, weight cosθ_receiver.
  // Either way Σ w·v / Σ w converges to V = H / H0.
  LightSample sample(const Vec3& y, const Vec3& n, const Vec2& u) const;
  // The part of the light above the horizon of (y, n), for samples that all contribute.
  HorizonPart above_horizon(const Vec3& y, const Vec3& n) const;
  // Whether the horizon of (y, n) cuts the light (some of it lies below, a corner of a rectangle,
  // the rim of a disk, the far side of a sphere).
  bool partly_below_horizon(const Vec3& y, const Vec3& n) const;

 private:
  // A rectangle's, disk's or polygon's reach of point y with normal n, as reaches weighs it: how
  // far y lies in front of the light's plane (> 0: the light faces it) and how far the light's
  // highest point lies above y's horizon (> 0: some of it is above).
  struct Reach {
    double front = 0, above = 0;
  };
  Reach flat_reach(const Vec3& y, const Vec3& n) const;
  // Whether every point of the box lies within the range (always, without one).
  bool within_range_throughout(const Bounds3& ys) const;
  // Bounds on the centre's height n·(c − y) over the horizons of points y of ys with normals n
  // of ns: (least, greatest).
  std::pair<double, double> height_over_horizons(const Bounds3& ys, const Bounds3& ns) const;

  LightDesc desc_;
  Vec3 right_, up_;
  int output_ = 0;
  std::uint64_t stream_ = 0;
  Vec3 exitance_;
  std::shared_ptr<const Image> texture_;
  std::shared_ptr<const Sky> sky_;
};

// The scene's lights, with their textures read (through OpenImageIO, sRGB decoded to linear),
// in scene order; a mesh light is its parts (mesh_light_parts), a sky its (Sky::parts, about its
// position at its radius: place_sky), each part with its light's output index. An unreadable
// texture is an error naming scene_file, the light and the image.
Expected<std::vector<Light>> make_lights(const std::vector<LightDesc>& descs,
                                         const std::filesystem::path& scene_file);
// How many of the scene's lights `lights` (from make_lights) stand for: the per-light images.
std::size_t output_count(const std::vector<Light>& lights);
// The planar polygon lights a mesh light is baked as (LightDesc::corners): its triangles, two
// of them joined into one quad wherever they share an edge, lie in one plane and make a convex
// outline (a UV sphere's or a cylinder's quads: half the lights, half the bake's time for them);
// named "<name>#<k>", each with its share of the power by area. Degenerate triangles are left
// out.
std::vector<LightDesc> mesh_light_parts(const LightDesc& mesh);

// The distance from a light's centre at which its irradiance on a surface facing it falls to
// `floor` W/m² (BakeSettings::irradiance_floor), in its brightest channel: a sphere's (a point's,
// a spot's) P/(4π d²), a rectangle's or disk's P/(π d²) along its axis (its far field, never
// below its near one). Infinite for a sun, a sky or a mesh light, which reach everywhere, and
// for a floor of 0.
double range_for_floor(const LightDesc& light, double floor);

// Lambert's formula for the form factor of a planar polygon (vertices relative to the point,
// either winding) seen from a point with unit normal n, after clipping the polygon to the
// half-space n·x >= 0. Exposed for tests.
double polygon_form_factor(std::vector<Vec3> polygon, const Vec3& n);
double polygon_form_factor(const Vec3* polygon, int count, const Vec3& n);

}  // namespace sb
