// Area lights: their shapes, emission and closed-form unoccluded irradiance.
//
// H0 (docs/design.md §1): for a Lambertian emitter of exitance E, H0(y) = E · F(y) with F the
// point-to-surface form factor, F = (1/π) ∫ cosθ_y dω over the part of the light above y's
// horizon. For a polygon, Lambert's formula gives F exactly as a sum over edges:
//   F = (1/2π) Σ_i  acos(â_i · â_{i+1}) · n · normalize(a_i × a_{i+1}).
// For a disk wholly above the horizon the vector form factor has an elementary closed form
// (the classic parallel and perpendicular disk form factors are its two components, and F is
// linear in n); a disk cut by the horizon falls back to an equal-area polygon. A sphere seen from
// y shows exactly the solid angle of its silhouette disk, so it reuses the disk.
//
// Sampling for the reference (docs/design.md §7) is light_sampling.cpp's.
#include "scene/lights.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/image_io.h"
#include "core/sampling.h"
#include "scene/light_geometry.h"
#include "scene/sky.h"

namespace sb {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Disk of centre c (relative to the receiving point), unit axis m pointing at the emitting side,
// radius R: form factor from a point at the origin with unit normal n.
double disk_form_factor(const Vec3& c, const Vec3& m, const Vec3& right, const Vec3& up, double R,
                        const Vec3& n) {
  const Vec3 to_point = -c;          // from the disk centre to the point
  const double h = to_point.dot(m);  // height above the disk's plane
  if (h <= 0) return 0.0;            // behind the emitting side
  const Vec3 radial = to_point - h * m;
  const double rho = radial.norm();
  const Vec3 n_in_plane = n - n.dot(m) * m;
  // Lowest value of n·(x − y) over the disk's points x: the disk is wholly above the horizon
  // when it is positive.
  const double lowest = n.dot(c) - R * n_in_plane.norm();
  if (n.dot(c) + R * n_in_plane.norm() <= 0) return 0.0;  // wholly below the horizon
  if (lowest >= 0) {
    const double A = h * h + rho * rho + R * R;
    const double S = std::sqrt((h * h + (rho - R) * (rho - R)) * (h * h + (rho + R) * (rho + R)));
    const double f_axial = 0.5 * (1.0 - (h * h + rho * rho - R * R) / S);  // normal = -m
    // Perpendicular component, normal pointing from the point towards the axis; written as
    // 2hR²ρ / (S (A + S)) rather than (h / 2ρ)(A / S − 1) so it stays exact as ρ → 0.
    const double f_radial = 2.0 * h * R * R * rho / (S * (A + S));
    double f = f_axial * n.dot(-m);
    if (rho > 0) f += f_radial * n.dot(-radial / rho);
    return std::max(0.0, f);
  }
  // Cut by the horizon: a regular polygon with the disk's area.
  const DiskPolygon& unit = disk_polygon();
  const double r_poly = R * unit.area_radius;
  std::array<Vec3, kDiskPolygonSides> poly;
  for (int i = 0; i < kDiskPolygonSides; ++i) {
    const Vec2& u = unit.unit[std::size_t(i)];
    poly[std::size_t(i)] = c + r_poly * (u.x() * right + u.y() * up);
  }
  return polygon_form_factor(poly.data(), kDiskPolygonSides, n);
}

// RGB of pixel (x, y): grey images repeat their one channel; alpha is ignored.
Vec3 pixel_rgb(const Image& image, int x, int y) {
  const float* p = image.at(x, y);
  return image.channels >= 3 ? Vec3(p[0], p[1], p[2]) : Vec3::Constant(p[0]);
}

Vec3 texture_mean(const Image& image) {
  Vec3 sum = Vec3::Zero();
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) sum += pixel_rgb(image, x, y);
  return sum / (double(image.width) * image.height);
}

// Bilinear lookup at (u, v) ∈ [0, 1]², v up (row 0 is v = 1), clamped at the border.
Vec3 bilinear_rgb(const Image& image, double u, double v) {
  const double fx = std::clamp(u, 0.0, 1.0) * image.width - 0.5;
  const double fy = (1.0 - std::clamp(v, 0.0, 1.0)) * image.height - 0.5;
  const int x0 = std::clamp(int(std::floor(fx)), 0, image.width - 1);
  const int y0 = std::clamp(int(std::floor(fy)), 0, image.height - 1);
  const int x1 = std::min(x0 + 1, image.width - 1), y1 = std::min(y0 + 1, image.height - 1);
  const double tx = std::clamp(fx - x0, 0.0, 1.0), ty = std::clamp(fy - y0, 0.0, 1.0);
  return (1 - ty) * ((1 - tx) * pixel_rgb(image, x0, y0) + tx * pixel_rgb(image, x1, y0)) +
         ty * ((1 - tx) * pixel_rgb(image, x0, y1) + tx * pixel_rgb(image, x1, y1));
}

}  // namespace

// Computed on first use, shared by every light (light_geometry.h).
const DiskPolygon& disk_polygon() {
  static const DiskPolygon polygon = [] {
    DiskPolygon p;
    const double sides = kDiskPolygonSides;
    p.area_radius = std::sqrt(2.0 * kPi / (sides * std::sin(2.0 * kPi / sides)));
    for (int i = 0; i < kDiskPolygonSides; ++i) {
      const double t = 2.0 * kPi * i / sides;
      p.unit[std::size_t(i)] = Vec2(std::cos(t), std::sin(t));
    }
    return p;
  }();
  return polygon;
}

double polygon_form_factor(std::vector<Vec3> polygon, const Vec3& n) {
  return polygon_form_factor(polygon.data(), int(polygon.size()), n);
}

double polygon_form_factor(const Vec3* polygon, int count, const Vec3& n) {
  // Clipped to the horizon without allocating (this runs per texel and light): a convex polygon
  // gains at most one corner; a non-convex one at most one per edge.
  constexpr int kMax = 2 * kDiskPolygonSides + 2;
  std::array<Vec3, kMax> fixed;
  std::vector<Vec3> large;  // for an outline of more corners than the disks' own
  if (2 * count + 2 > kMax) large.resize(std::size_t(2 * count + 2));
  Vec3* clipped = large.empty() ? fixed.data() : large.data();
  int m = 0;
  for (int i = 0; i < count; ++i) {
    const Vec3& a = polygon[i];
    const Vec3& b = polygon[(i + 1) % count];
    const double da = n.dot(a), db = n.dot(b);
    if (da >= 0) clipped[std::size_t(m++)] = a;
    if ((da >= 0) != (db >= 0)) clipped[std::size_t(m++)] = a + (b - a) * (da / (da - db));
  }
  if (m < 3) return 0.0;
  double sum = 0;
  Vec3 a = clipped[0].normalized();
  const Vec3 first = a;
  for (int i = 0; i < m; ++i) {
    const Vec3 b = i + 1 < m ? clipped[std::size_t(i + 1)].normalized() : first;
    const Vec3 cross = a.cross(b);
    const double len = cross.norm();
    if (len >= 1e-300) sum += std::atan2(len, a.dot(b)) * n.dot(cross / len);
    a = b;
  }
  return std::abs(sum) / (2.0 * kPi);
}

Light::Light(const LightDesc& desc, std::shared_ptr<const Image> texture, int output,
             std::shared_ptr<const Sky> sky)
    : desc_(desc), output_(output), texture_(std::move(texture)), sky_(std::move(sky)) {
  if (desc_.shape == LightShape::polygon &&
      (desc_.corners.size() == 3 || desc_.corners.size() == 4)) {
    // Its plane from its corners, counter-clockwise seen from the emitting side (the fan from
    // its first corner), its centre the area-weighted centroid; `up` towards its first corner.
    const std::vector<Vec3>& c = desc_.corners;
    Vec3 normal = Vec3::Zero(), centroid = Vec3::Zero();
    for (std::size_t k = 1; k + 1 < c.size(); ++k) {
      const Vec3 cross = (c[k] - c[0]).cross(c[k + 1] - c[0]);
      normal += cross;
      centroid += cross.norm() * (c[0] + c[k] + c[k + 1]) / 3.0;
    }
    desc_.position = centroid / normal.norm();
    desc_.normal = normal.normalized();
    desc_.up = (c[0] - desc_.position).normalized();
  }
  if (desc_.shape == LightShape::sphere || desc_.shape == LightShape::mesh ||
      desc_.shape == LightShape::sky) {
    up_ = Vec3::UnitZ();
    right_ = Vec3::UnitX();
  } else {
    // In the light's plane whatever the description holds (the scene reader makes `up`
    // perpendicular to the normal; a description built by hand may not).
    up_ = (desc_.up - desc_.up.dot(desc_.normal) * desc_.normal).normalized();
    right_ = up_.cross(desc_.normal).normalized();
  }
  stream_ = name_stream(desc_.name);
  exitance_ = desc_.color * (desc_.power / area());
  if (texture_) exitance_ = exitance_.cwiseProduct(texture_mean(*texture_));
}

int Light::outline(std::array<Vec3, 4>& corners) const {
  if (desc_.shape == LightShape::rectangle) {
    const Vec3 hw = 0.5 * desc_.width * right_, hh = 0.5 * desc_.height * up_;
    const Vec3& c = desc_.position;
    corners = {c - hw - hh, c + hw - hh, c + hw + hh, c - hw + hh};
    return 4;
  }
  if (desc_.shape == LightShape::polygon && desc_.corners.size() == 3) {
    corners = {desc_.corners[0], desc_.corners[1], desc_.corners[2], desc_.corners[2]};
    return 3;
  }
  if (desc_.shape == LightShape::polygon && desc_.corners.size() == 4) {
    corners = {desc_.corners[0], desc_.corners[1], desc_.corners[2], desc_.corners[3]};
    return 4;
  }
  return 0;
}

Vec3 Light::tint(const Vec2& local) const {
  if (!texture_) return Vec3::Ones();
  // Texture coordinates over the light's bounding rectangle: u along right, v along up.
  const double w = desc_.shape == LightShape::rectangle ? desc_.width : 2 * desc_.radius;
  const double h = desc_.shape == LightShape::rectangle ? desc_.height : 2 * desc_.radius;
  return bilinear_rgb(*texture_, local.x() / w + 0.5, local.y() / h + 0.5);
}

double Light::extent_across(const Vec3& axis) const {
  switch (desc_.shape) {
    case LightShape::rectangle: {
      // The longer diagonal of the parallelogram the rectangle projects to.
      const Vec3 a = 0.5 * desc_.width * right_, b = 0.5 * desc_.height * up_;
      auto across = [&](const Vec3& v) { return (v - v.dot(axis) * axis).norm(); };
      return 2 * std::max(across(a + b), across(a - b));
    }
    case LightShape::disk:
    case LightShape::sphere:
      return 2 * desc_.radius;  // an ellipse's major axis, or the sphere's outline
    case LightShape::polygon: {
      // Its longest side or diagonal seen across the axis.
      std::array<Vec3, 4> c;
      const int count = outline(c);
      double longest = 0;
      for (int i = 0; i < count; ++i)
        for (int j = i + 1; j < count; ++j) {
          const Vec3 side = c[std::size_t(i)] - c[std::size_t(j)];
          longest = std::max(longest, (side - side.dot(axis) * axis).norm());
        }
      return longest;
    }
    case LightShape::mesh:
    case LightShape::sky:
      break;
  }
  return 0;
}

Vec2 Light::half_extents(const Vec3& e1, const Vec3& e2) const {
  auto along = [&](const Vec3& e) {
    switch (desc_.shape) {
      case LightShape::rectangle:
        return 0.5 * (desc_.width * std::abs(right_.dot(e)) + desc_.height * std::abs(up_.dot(e)));
      case LightShape::disk:
        return desc_.radius * std::sqrt(std::max(0.0, 1.0 - std::pow(desc_.normal.dot(e), 2)));
      case LightShape::sphere:
        return desc_.radius;
      case LightShape::polygon: {
        // About the centroid: the farthest corner along e (an outline's bounding box about
        // the centre, as the other shapes' are).
        double half = 0;
        for (const Vec3& c : desc_.corners) half = std::max(half, std::abs((c - centre()).dot(e)));
        return half;
      }
      case LightShape::mesh:
      case LightShape::sky:
        break;
    }
    return 0.0;
  };
  return Vec2(along(e1), along(e2));
}

Vec3 Light::source_image(const Vec3& offset, const Vec3& axis) const {
  if (desc_.shape == LightShape::sphere) {
    return (offset - offset.dot(axis) * axis).norm() <= desc_.radius ? Vec3::Ones() : Vec3::Zero();
  }
  // Slide along the axis onto the light's plane.
  const double facing = axis.dot(desc_.normal);
  if (std::abs(facing) < 1e-9) return Vec3::Zero();  // seen edge-on: no area
  const Vec3 on_light = offset - axis * (offset.dot(desc_.normal) / facing);
  const Vec2 local(on_light.dot(right_), on_light.dot(up_));
  bool inside = false;
  if (desc_.shape == LightShape::rectangle) {
    inside = std::abs(local.x()) <= 0.5 * desc_.width && std::abs(local.y()) <= 0.5 * desc_.height;
  } else if (desc_.shape == LightShape::disk) {
    inside = local.squaredNorm() <= desc_.radius * desc_.radius;
  } else if (desc_.shape == LightShape::polygon) {
    // On the inner side of each edge (counter-clockwise about the normal).
    const Vec3 x = centre() + on_light;
    inside = true;
    const std::size_t count = desc_.corners.size();
    for (std::size_t k = 0; k < count && inside; ++k) {
      const Vec3& a = desc_.corners[k];
      const Vec3& b = desc_.corners[(k + 1) % count];
      inside = (b - a).cross(x - a).dot(desc_.normal) >= 0;
    }
  }
  return inside ? tint(local) : Vec3::Zero();
}

double Light::area() const {
  switch (desc_.shape) {
    case LightShape::rectangle:
      return desc_.width * desc_.height;
    case LightShape::disk:
      return kPi * desc_.radius * desc_.radius;
    case LightShape::sphere:
      return 4.0 * kPi * desc_.radius * desc_.radius;
    case LightShape::polygon: {  // the fan from its first corner
      const std::vector<Vec3>& c = desc_.corners;
      double sum = 0;
      for (std::size_t k = 1; k + 1 < c.size(); ++k)
        sum += 0.5 * (c[k] - c[0]).cross(c[k + 1] - c[0]).norm();
      return sum;
    }
    case LightShape::mesh: {  // its triangles
      const std::vector<Vec3>& c = desc_.corners;
      double sum = 0;
      for (std::size_t k = 0; k + 2 < c.size(); k += 3)
        sum += 0.5 * (c[k + 1] - c[k]).cross(c[k + 2] - c[k]).norm();
      return sum;
    }
    case LightShape::sky:
      break;  // baked as its parts
  }
  return 0;
}

double Light::form_factor(const Vec3& y, const Vec3& n) const {
  const Vec3 c = desc_.position - y;
  switch (desc_.shape) {
    case LightShape::rectangle:
    case LightShape::polygon: {
      if (c.dot(desc_.normal) >= 0) return 0.0;  // the point is behind the emitting side
      std::array<Vec3, 4> corners;
      const int count = outline(corners);
      for (int k = 0; k < count; ++k) corners[std::size_t(k)] -= y;
      return polygon_form_factor(corners.data(), count, n);
    }
    case LightShape::disk:
      return disk_form_factor(c, desc_.normal, right_, up_, desc_.radius, n);
    case LightShape::sphere: {
      const double d = c.norm(), r = desc_.radius;
      if (d <= r) return 0.0;
      // Wholly above the horizon: the classic (r/d)²·cos θ (the silhouette disk's form factor,
      // below, in closed form).
      const double height = n.dot(c);
      if (height >= r) return r * r * height / (d * d * d);
      // The silhouette: a disk facing the point, at distance (d² − r²)/d, of radius r·√(d²−r²)/d.
      const Vec3 axis = -c / d;
      const Vec3 sil_centre = c * (1.0 - r * r / (d * d));
      const double sil_radius = r * std::sqrt(d * d - r * r) / d;
      const Vec3 a = any_orthogonal(axis);
      return disk_form_factor(sil_centre, axis, a, axis.cross(a), sil_radius, n);
    }
    case LightShape::mesh:
    case LightShape::sky:
      break;  // baked as its parts
  }
  return 0.0;
}

Vec3 Light::unoccluded_irradiance(const Vec3& y, const Vec3& n) const {
  const double window = range_factor(y);
  if (!(window > 0)) return Vec3::Zero();
  return exitance_ * (form_factor(y, n) * spot_factor(y) * window);
}

Expected<std::vector<Light>> make_lights(const std::vector<LightDesc>& descs,
                                         const std::filesystem::path& scene_file) {
  std::vector<Light> lights;
  lights.reserve(descs.size());
  for (const auto& d : descs) {
    std::shared_ptr<const Image> texture;
    const int output = int(&d - descs.data());
    if (d.shape == LightShape::sky) {
      auto sky = make_sky(d, scene_file);
      if (!sky) return sky.error();
      const double distance = d.radius > 0 ? d.radius : 1e4;
      for (const LightDesc& part : (*sky)->parts(d, d.position, distance, d.sky_parts))
        lights.emplace_back(part, nullptr, output, *sky);
      continue;
    }
    if (!d.texture.empty()) {
      auto image = read_image(d.texture, /*linearise=*/true);
      const std::string where = scene_file.string() + ":" + std::to_string(d.line) + ": light '" +
                                d.name + "': texture: ";
      if (!image) return scene_error(where + image.error().message);
      if (image->width < 1 || image->height < 1 || texture_mean(*image).maxCoeff() <= 0) {
        return scene_error(where + d.texture.string() + ": the image is empty or black");
      }
      texture = std::make_shared<const Image>(std::move(*image));
    }
    if (d.shape == LightShape::mesh) {
      for (const LightDesc& part : mesh_light_parts(d)) lights.emplace_back(part, nullptr, output);
    } else {
      lights.emplace_back(d, std::move(texture), output);
    }
  }
  return lights;
}

std::size_t output_count(const std::vector<Light>& lights) {
  return lights.empty() ? 0 : std::size_t(lights.back().output()) + 1;
}

}  // namespace sb
