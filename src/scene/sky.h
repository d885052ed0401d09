// A sky: light from every direction at infinity, uniform, an equirectangular environment map
// (an HDR/EXR image, as Blender's Environment Texture maps it) or an analytic clear sky
// (sky_models.h), made a map of its own. Two routes bake it:
//  - its parts (sky_parts): the sphere of directions cut into spherical triangles of roughly
//    equal flux, as the seed document's "one directional light per patch of roughly equal
//    brightness", each made a planar polygon light far away with its patch's mean radiance.
//    Every method bakes polygons, so every method bakes a sky with no code of its own; a
//    triangle seen from the scene covers its patch's solid angle exactly (to the scene's size
//    over the sky's distance), so the parts tile the sphere, a uniform sky is exact whatever the
//    number of parts, and a map is approximated only by its mean over each patch;
//  - rays over the sky itself (methods/sky_rays.h): the reference's, sampling the map's own
//    pixels by their flux (and the cosine), no patches.
#pragma once

#include <filesystem>
#include <memory>
#include <vector>

#include "core/error.h"
#include "core/geometry.h"
#include "core/image.h"
#include "scene/scene.h"

namespace sb {

class Sky {
 public:
  // `radiance` per channel (W/m²/sr; colour · strength); `map` an equirectangular linear RGB
  // image scaled by it, or null for a uniform sky; `rotation` radians about `up`, the scene's
  // zenith (unit): the map's own Z (sky_frame).
  Sky(const Vec3& radiance, std::shared_ptr<const Image> map, double rotation,
      const Vec3& up = Vec3::UnitZ());

  bool uniform() const { return map_ == nullptr; }
  // Radiance arriving from unit direction `d` (where the light comes from), per channel: the
  // map's pixel that d falls in (nearest, so that the parts, the sampling and this agree).
  Vec3 radiance(const Vec3& d) const;
  // A direction drawn with density proportional to the map's flux (a pixel's luminance times its
  // solid angle, uniform within the pixel), and that density per steradian; for a uniform sky,
  // uniform over the sphere. pdf(d) is the same density at any direction.
  Vec3 sample(const Vec2& u, double* density) const;
  double pdf(const Vec3& d) const;

  // The polygon lights the sky is baked as, `count` of them at most (a part whose radiance is 0
  // in every channel is left out): the 20 faces of an icosahedron, the one with the most flux
  // split into four (its edges' midpoints pushed out onto the sphere, so the split faces still
  // tile it) until another split would pass `count`. Corners on the sphere of `distance` metres
  // about `centre`, counter-clockwise seen from inside; named "<name>#<k>", power π · area with
  // colour the patch's mean radiance, so that its exitance is π L.
  std::vector<LightDesc> parts(const LightDesc& desc, const Vec3& centre, double distance,
                               int count) const;

 private:
  // Pixel (column, row) of direction d, and the direction at (u, v) ∈ [0,1]² of the image.
  void pixel_of(const Vec3& d, int* x, int* y) const;
  Vec3 direction_at(double u, double v) const;

  Vec3 radiance_;
  std::shared_ptr<const Image> map_;
  double rotation_ = 0;
  // The map's axes in the scene: X (its middle column), Y, Z (its top row), Z = `up`.
  Mat3 frame_ = Mat3::Identity();
  // Sampling tables: the cumulative distribution over rows, then over columns within each row
  // (rows + 1 and rows × (columns + 1) entries), and each pixel's probability.
  std::vector<double> row_cdf_, column_cdf_, pixel_probability_;
};

// The direction (unit, in a map's own axes: Z its zenith) at image coordinates (u, v) ∈ [0, 1]²
// of an equirectangular map, v = 1 its top row: Cycles' equirectangular mapping, the middle
// column +X, u growing towards −Y.
Vec3 equirectangular_direction(double u, double v);

// The sky of a sky light (LightDesc::shape sky): its map read through OpenImageIO when it names
// one (the scene file's folder resolved by the reader). Errors name scene_file, the light and the
// image.
Expected<std::shared_ptr<const Sky>> make_sky(const LightDesc& desc,
                                              const std::filesystem::path& scene_file);

// The scene axes a sky's map lies along (rows of the matrix: the map's X, Y and Z): Z is `up`,
// X is +X made perpendicular to it (+Y where up lies along X), Y = Z × X. With up = +Z it is
// the identity; with up = +Y, a glTF level's zenith, X stays X and Y is −Z: the axes Blender's
// glTF importer gives the file, so a map looks in shadowbake as in Blender.
Mat3 sky_frame(const Vec3& up);

// The distance at which the bake puts a sky's parts for a scene within `bounds` (a sun's,
// sun_light.h).
void place_sky(LightDesc& sky, const Bounds3& bounds);

}  // namespace sb
