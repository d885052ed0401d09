#include "scene/sky.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <queue>

#include "core/image_io.h"
#include "scene/sky_models.h"
#include "scene/sun_light.h"

namespace sb {

namespace {

constexpr double pi = std::numbers::pi;

// The map an analytic sky is baked through: 0.7° pixels, where its radiance (the sun's glow
// falls by e over some 25°) varies by well under a percent from one to the next.
constexpr int kAnalyticMapWidth = 512;

double luminance(const Vec3& c) { return 0.2126 * c.x() + 0.7152 * c.y() + 0.0722 * c.z(); }

// The solid angle of the spherical triangle of unit corners a, b, c (Van Oosterom & Strackee).
double solid_angle(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double numerator = std::abs(a.dot(b.cross(c)));
  const double denominator = 1 + a.dot(b) + b.dot(c) + c.dot(a);
  return 2 * std::atan2(numerator, denominator);
}

// The icosahedron's 12 corners (unit) and 20 faces, counter-clockwise seen from outside.
void icosahedron(std::vector<Vec3>& corners, std::vector<std::array<int, 3>>& faces) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  corners = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
             {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (Vec3& c : corners) c.normalize();
  faces = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
           {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
           {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
}

// A patch of the sky being split: its corners (unit, counter-clockwise seen from outside), the
// map's pixels whose centres fall in it, and its flux (Σ L·Ω over them, or L·Ω for a uniform sky).
struct Patch {
  std::array<Vec3, 3> corner;
  std::vector<std::uint32_t> pixels;
  Vec3 flux = Vec3::Zero();
  int depth = 0;
  bool contains(const Vec3& d) const {
    for (int k = 0; k < 3; ++k)
      if (d.dot(corner[std::size_t(k)].cross(corner[std::size_t((k + 1) % 3)])) < 0) return false;
    return true;
  }
};

}  // namespace

Mat3 sky_frame(const Vec3& up) {
  const Vec3 z = up.normalized();
  Vec3 x = Vec3::UnitX() - Vec3::UnitX().dot(z) * z;
  if (x.norm() < 1e-6) x = Vec3::UnitY() - Vec3::UnitY().dot(z) * z;
  x.normalize();
  Mat3 frame;
  frame.row(0) = x;
  frame.row(1) = z.cross(x);
  frame.row(2) = z;
  return frame;
}

Sky::Sky(const Vec3& radiance, std::shared_ptr<const Image> map, double rotation, const Vec3& up)
    : radiance_(radiance), map_(std::move(map)), rotation_(rotation), frame_(sky_frame(up)) {
  if (!map_) return;
  const int w = map_->width, h = map_->height;
  pixel_probability_.assign(std::size_t(w) * std::size_t(h), 0.0);
  column_cdf_.assign(std::size_t(h) * std::size_t(w + 1), 0.0);
  row_cdf_.assign(std::size_t(h + 1), 0.0);
  double total = 0;
  for (int y = 0; y < h; ++y) {
    // A row's solid angle per pixel: (2π / w)·(π / h)·cos(elevation at its centre).
    const double elevation = (0.5 - (y + 0.5) / h) * pi;
    const double omega = 2 * pi / w * pi / h * std::cos(elevation);
    double row = 0;
    for (int x = 0; x < w; ++x) {
      const float* p = map_->at(x, y);
      const Vec3 c(p[0], p[map_->channels > 1 ? 1 : 0], p[map_->channels > 2 ? 2 : 0]);
      const double weight = std::max(0.0, luminance(c)) * omega;
      pixel_probability_[std::size_t(y) * std::size_t(w) + std::size_t(x)] = weight;
      row += weight;
      column_cdf_[std::size_t(y) * std::size_t(w + 1) + std::size_t(x + 1)] = row;
    }
    total += row;
    row_cdf_[std::size_t(y + 1)] = total;
  }
  if (!(total > 0)) {  // black: sampled uniformly (it adds nothing whatever is drawn)
    for (int y = 0; y < h; ++y) {
      const double omega = 2 * pi / w * pi / h * std::cos((0.5 - (y + 0.5) / h) * pi);
      for (int x = 0; x < w; ++x) {
        pixel_probability_[std::size_t(y) * std::size_t(w) + std::size_t(x)] = omega;
        column_cdf_[std::size_t(y) * std::size_t(w + 1) + std::size_t(x + 1)] = omega * (x + 1);
      }
      total += omega * w;
      row_cdf_[std::size_t(y + 1)] = total;
    }
  }
  for (double& p : pixel_probability_) p /= total;
  for (double& c : row_cdf_) c /= total;
}

void Sky::pixel_of(const Vec3& d, int* x, int* y) const {
  // Cycles' equirectangular mapping (direction_to_equirectangular) of the direction the map is
  // looked up at, d turned by the rotation about +Z: u = 1/2 − atan2(y, x) / 2π (+X at the
  // image's middle column), v = 1/2 + elevation / π; row 0 is v = 1 (the zenith).
  const Vec3 m = frame_ * d;  // in the map's axes
  const double c = std::cos(rotation_), s = std::sin(rotation_);
  const Vec3 r(c * m.x() - s * m.y(), s * m.x() + c * m.y(), m.z());
  const double u = 0.5 - std::atan2(r.y(), r.x()) / (2 * pi);
  const double v = std::atan2(r.z(), std::hypot(r.x(), r.y())) / pi + 0.5;
  *x = std::clamp(int(std::floor(u * map_->width)), 0, map_->width - 1);
  *y = std::clamp(int(std::floor((1 - v) * map_->height)), 0, map_->height - 1);
}

Vec3 equirectangular_direction(double u, double v) {
  const double phi = (0.5 - u) * 2 * pi, elevation = (v - 0.5) * pi;
  return {std::cos(phi) * std::cos(elevation), std::sin(phi) * std::cos(elevation),
          std::sin(elevation)};
}

Vec3 Sky::direction_at(double u, double v) const {
  const Vec3 r = equirectangular_direction(u, v);
  const double c = std::cos(rotation_), s = std::sin(rotation_);
  const Vec3 m(c * r.x() + s * r.y(), -s * r.x() + c * r.y(), r.z());  // turned back
  return frame_.transpose() * m;                                       // in the scene's axes
}

Vec3 Sky::radiance(const Vec3& d) const {
  if (!map_) return radiance_;
  int x = 0, y = 0;
  pixel_of(d, &x, &y);
  const float* p = map_->at(x, y);
  const int ch = map_->channels;
  return radiance_.cwiseProduct(Vec3(p[0], p[ch > 1 ? 1 : 0], p[ch > 2 ? 2 : 0]));
}

Vec3 Sky::sample(const Vec2& u, double* density) const {
  if (!map_) {
    const double z = 1 - 2 * u.x(), r = std::sqrt(std::max(0.0, 1 - z * z));
    const double phi = 2 * pi * u.y();
    *density = 1 / (4 * pi);
    return Vec3(r * std::cos(phi), r * std::sin(phi), z);
  }
  const int w = map_->width, h = map_->height;
  // The row, then the column within it, by inverting the cumulative distributions; the offset
  // within the chosen cell, rescaled, places the point within the pixel.
  const auto row_it = std::upper_bound(row_cdf_.begin() + 1, row_cdf_.end(), u.y());
  const int y = std::clamp(int(row_it - row_cdf_.begin()) - 1, 0, h - 1);
  const double row_lo = row_cdf_[std::size_t(y)], row_hi = row_cdf_[std::size_t(y + 1)];
  const double fy = row_hi > row_lo ? (u.y() - row_lo) / (row_hi - row_lo) : 0.5;
  const double* columns = &column_cdf_[std::size_t(y) * std::size_t(w + 1)];
  const double target = u.x() * columns[w];
  const int x = std::clamp(
      int(std::upper_bound(columns + 1, columns + w + 1, target) - columns) - 1, 0, w - 1);
  const double fx =
      columns[x + 1] > columns[x] ? (target - columns[x]) / (columns[x + 1] - columns[x]) : 0.5;
  const Vec3 d =
      direction_at((x + std::clamp(fx, 0.0, 1.0)) / w, 1 - (y + std::clamp(fy, 0.0, 1.0)) / h);
  *density = pdf(d);
  return d;
}

double Sky::pdf(const Vec3& d) const {
  if (!map_) return 1 / (4 * pi);
  int x = 0, y = 0;
  pixel_of(d, &x, &y);
  // A pixel's probability spread over its solid angle, (2π / w)·(π / h)·cos(elevation) per unit
  // of (u, v) area: at the point itself, so that the density is exact within the pixel.
  const double z = (frame_ * d).z();  // the sine of the elevation, in the map's axes
  const double cos_elevation = std::sqrt(std::max(0.0, 1 - z * z));
  const double omega = 2 * pi / map_->width * pi / map_->height * std::max(cos_elevation, 1e-9);
  return pixel_probability_[std::size_t(y) * std::size_t(map_->width) + std::size_t(x)] / omega;
}

std::vector<LightDesc> Sky::parts(const LightDesc& desc, const Vec3& centre, double distance,
                                  int count) const {
  std::vector<Vec3> corners;
  std::vector<std::array<int, 3>> faces;
  icosahedron(corners, faces);
  std::vector<Patch> patches;
  for (const auto& f : faces) {
    Patch p;
    p.corner = {corners[std::size_t(f[0])], corners[std::size_t(f[1])], corners[std::size_t(f[2])]};
    patches.push_back(std::move(p));
  }
  // A uniform sky's flux is L·Ω; a map's is its pixels', each given to the patch its centre
  // falls in.
  const auto weigh = [&](Patch& p) {
    if (!map_) {
      p.flux = radiance_ * solid_angle(p.corner[0], p.corner[1], p.corner[2]);
      return;
    }
    p.flux = Vec3::Zero();
    const int w = map_->width, h = map_->height;
    for (const std::uint32_t i : p.pixels) {
      const int x = int(i % std::uint32_t(w)), y = int(i / std::uint32_t(w));
      const double omega = 2 * pi / w * pi / h * std::cos((0.5 - (y + 0.5) / h) * pi);
      const float* px = map_->at(x, y);
      const int ch = map_->channels;
      p.flux += omega * radiance_.cwiseProduct(Vec3(px[0], px[ch > 1 ? 1 : 0], px[ch > 2 ? 2 : 0]));
    }
  };
  if (map_) {
    const int w = map_->width, h = map_->height;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const Vec3 d = direction_at((x + 0.5) / w, 1 - (y + 0.5) / h);
        std::size_t k = 0;
        while (k + 1 < patches.size() && !patches[k].contains(d)) ++k;
        patches[k].pixels.push_back(std::uint32_t(y * w + x));
      }
  }
  for (Patch& p : patches) weigh(p);
  // Split the patch of most flux (by luminance; of most solid angle among equals) while a split,
  // which adds three, keeps within `count`; a patch is split at most 12 times (about 0.02°), and
  // a map's only while it holds 8 pixels or more: below that the map has no detail to follow.
  const auto key = [&](const Patch& p) {
    return std::pair(luminance(p.flux), solid_angle(p.corner[0], p.corner[1], p.corner[2]));
  };
  const auto splittable = [&](const Patch& p) {
    return p.depth < 12 && (!map_ || p.pixels.size() >= 8);
  };
  while (int(patches.size()) + 3 <= count) {
    std::size_t best = patches.size();
    for (std::size_t k = 0; k < patches.size(); ++k)
      if (splittable(patches[k]) &&
          (best == patches.size() || key(patches[best]) < key(patches[k])))
        best = k;
    if (best == patches.size()) break;
    Patch parent = std::move(patches[best]);
    const Vec3 &a = parent.corner[0], &b = parent.corner[1], &c = parent.corner[2];
    const Vec3 ab = (a + b).normalized(), bc = (b + c).normalized(), ca = (c + a).normalized();
    std::array<Patch, 4> children;
    children[0].corner = {a, ab, ca};
    children[1].corner = {ab, b, bc};
    children[2].corner = {ca, bc, c};
    children[3].corner = {ab, bc, ca};
    const int w = map_ ? map_->width : 1, h = map_ ? map_->height : 1;
    for (const std::uint32_t i : parent.pixels) {
      const int x = int(i % std::uint32_t(w)), y = int(i / std::uint32_t(w));
      const Vec3 d = direction_at((x + 0.5) / w, 1 - (y + 0.5) / h);
      std::size_t k = 0;
      while (k < 3 && !children[k].contains(d)) ++k;
      children[k].pixels.push_back(i);
    }
    for (Patch& child : children) {
      child.depth = parent.depth + 1;
      weigh(child);
    }
    patches[best] = std::move(children[0]);
    for (int k = 1; k < 4; ++k) patches.push_back(std::move(children[std::size_t(k)]));
  }
  std::vector<LightDesc> out;
  for (const Patch& p : patches) {
    const double omega = solid_angle(p.corner[0], p.corner[1], p.corner[2]);
    // Its pixels' flux over its solid angle, so that the parts together carry the map's flux
    // exactly (a patch holds the pixels whose centres fall in it).
    const Vec3 mean = map_ ? Vec3(p.flux / omega) : radiance_;
    if (!(mean.maxCoeff() > 0) || !(omega > 0)) continue;
    LightDesc part = desc;
    part.shape = LightShape::polygon;
    part.name = desc.name + "#" + std::to_string(out.size());
    // Counter-clockwise seen from inside: the outside order reversed.
    part.corners = {centre + distance * p.corner[0], centre + distance * p.corner[2],
                    centre + distance * p.corner[1]};
    const Vec3 e1 = part.corners[1] - part.corners[0], e2 = part.corners[2] - part.corners[0];
    part.power = pi * 0.5 * e1.cross(e2).norm();
    part.color = mean;
    part.texture.clear();
    out.push_back(std::move(part));
  }
  return out;
}

Expected<std::shared_ptr<const Sky>> make_sky(const LightDesc& desc,
                                              const std::filesystem::path& scene_file) {
  const Vec3 radiance = desc.color * desc.sky_strength;
  const double rotation = desc.sky_rotation_deg * pi / 180;
  if (desc.sky_turbidity > 0) {  // an analytic sky, as a map in its own axes
    const Vec3 sun = sky_frame(desc.up) * -desc.sky_sun_direction;
    auto map = std::make_shared<const Image>(
        preetham_map(sun, desc.sky_turbidity, kAnalyticMapWidth, kAnalyticMapWidth / 2));
    return std::make_shared<const Sky>(radiance, std::move(map), rotation, desc.up);
  }
  if (desc.texture.empty())
    return std::make_shared<const Sky>(radiance, nullptr, rotation, desc.up);
  const std::string where =
      scene_file.string() + ":" + std::to_string(desc.line) + ": light '" + desc.name + "': map: ";
  auto image = read_image(desc.texture, /*linearise=*/true);
  if (!image) return scene_error(where + image.error().message);
  if (image->width < 2 || image->height < 1)
    return scene_error(where + desc.texture.string() + ": the image is empty");
  for (const float v : image->pixels)
    if (!std::isfinite(v) || v < 0)
      return scene_error(where + desc.texture.string() +
                         ": holds a negative or non-finite value; a sky's radiance is >= 0");
  return std::make_shared<const Sky>(radiance, std::make_shared<const Image>(std::move(*image)),
                                     rotation, desc.up);
}

void place_sky(LightDesc& sky, const Bounds3& bounds) {
  sky.position = bounds.centre();
  sky.radius = sun_distance(bounds);
}

}  // namespace sb
