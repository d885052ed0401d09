// The convolution kernel: the source image scaled and mirrored (docs/design.md §2;
// docs/design.md [S1], "Proof that Convolution is Appropriate").
//
// Seen from a receiver point X at depth r and tangent t (from the light's centre), a light point
// at lateral offset s and depth z (both from the light's centre, in the frame) is hidden by the
// blocker plane at depth d where the segment between them crosses it:
//
//     t + (r − d) / (d (r − z)) · (s − z·t).
//
// For a light in the plane z = 0 this is the paper's t + k·s with k = 1/d − 1/r: the source image
// scaled by k. A light tilted against the axis has z ≠ 0: its points shift by −z·t (the light seen
// along the ray to the receiver, not along the axis) and scale by r/(r − z) (perspective). The
// kernel below is exact for receiver points seen along `view` at depth r; other points of a
// receiver part see it sheared by their distance from `view`, which the planner counts in the
// penumbra error (convolution_plan.cpp). So the occluded, emission-weighted fraction is
// O(t) = Σ_u K(u) P(t − u) with K the light's emission mapped by u = −k·r/(r − z)·(s − z·view),
// normalised. It is made by splatting samples of the light's surface (forward mapping handles the
// perspective without inverting it). The kernel is centred on a pixel (odd size): with an even
// size the whole shadow would shift by half a pixel.
#include "methods/convolution/source_image.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace sb {

namespace {

// Offsets of the light's outline (or, for a sphere, of its silhouette seen along `along`).
std::vector<Vec3> outline(const Light& light, const Vec3& along) {
  std::vector<Vec3> pts;
  std::array<Vec3, 4> corners;
  if (const int count = light.outline(corners); count > 0) {
    for (int k = 0; k < count; ++k) pts.push_back(corners[std::size_t(k)] - light.centre());
    return pts;
  }
  Vec3 u = light.right(), v = light.up();
  if (light.shape() == LightShape::sphere) {
    u = along.unitOrthogonal();
    v = along.cross(u);
  }
  const int n = 64;
  const double r = light.desc().radius / std::cos(std::numbers::pi / n);  // circumscribed
  for (int i = 0; i < n; ++i) {
    const double phi = 2 * std::numbers::pi * i / n;
    pts.push_back(r * (std::cos(phi) * u + std::sin(phi) * v));
  }
  return pts;
}

// The unit direction from the frame's origin through tangent point `view`.
Vec3 view_ray(const ProjectionFrame& frame, const Vec2& view) {
  return (frame.axis + view.x() * frame.e1 + view.y() * frame.e2).normalized();
}

// Where a light offset lands in the kernel, in metres at k = 1 (tangent units over k), before
// mirroring; false when the point is at or beyond the receiver's depth.
bool kernel_point(const ProjectionFrame& frame, const Vec2& view, double r, const Vec3& offset,
                  Vec2* out) {
  const double z = offset.dot(frame.axis);
  if (r - z <= 1e-9 * r) return false;
  const Vec2 s(offset.dot(frame.e1), offset.dot(frame.e2));
  *out = (s - z * view) * (r / (r - z));
  return true;
}

}  // namespace

Vec2 projected_half_extents(const Light& light, const ProjectionFrame& frame, const Vec2& view,
                            double receiver_depth) {
  const Vec3 along = view_ray(frame, view);
  Vec2 half = Vec2::Zero();
  for (const Vec3& c : outline(light, along)) {
    Vec2 p;
    if (kernel_point(frame, view, receiver_depth, c, &p)) half = half.cwiseMax(p.cwiseAbs());
  }
  return half;
}

double depth_half_spread(const Light& light, const ProjectionFrame& frame) {
  double spread = 0;
  for (const Vec3& c : outline(light, frame.axis))
    spread = std::max(spread, std::abs(c.dot(frame.axis)));
  return light.shape() == LightShape::sphere ? 0.0 : spread;
}

namespace {

// The kernel of a source smaller than a pixel: a point light, whose kernel is a delta.
SourceKernel point_kernel(const Light& light) {
  SourceKernel kernel;
  const Vec3 e = light.exitance();
  for (int c = 0; c < 3; ++c) kernel.channels[c].assign(1, e[c] > 0 ? 1.0f : 0.0f);
  kernel.width = kernel.height = 1;
  kernel.grey = e.x() == e.y() && e.y() == e.z();
  return kernel;
}

// The axes across the light along which it is sampled, its extents along them, and whether it
// is round (a disk, or a sphere's silhouette) or a polygon (cells outside it left out).
struct SampleAxes {
  Vec3 axis_u, axis_v;
  double extent_u, extent_v;
  bool round, polygon;
};

// The light's sample axes: its own, a sphere's across the view ray `along`.
SampleAxes sample_axes(const Light& light, const Vec3& along) {
  Vec3 axis_u = light.right(), axis_v = light.up();
  double extent_u = light.desc().width, extent_v = light.desc().height;
  const bool round = light.shape() == LightShape::disk || light.shape() == LightShape::sphere;
  const bool polygon = light.shape() == LightShape::polygon;
  if (round) {
    extent_u = extent_v = 2 * light.desc().radius;
    if (light.shape() == LightShape::sphere) {
      axis_u = along.unitOrthogonal();
      axis_v = along.cross(axis_u);
    }
  } else if (polygon) {  // its box about the centre, cells outside it left out
    const Vec2 half = light.half_extents(axis_u, axis_v);
    extent_u = 2 * half.x();
    extent_v = 2 * half.y();
  }
  return {axis_u, axis_v, extent_u, extent_v, round, polygon};
}

// Calls visit(x, w) for each of the n pixels x that the interval [lo, hi] overlaps, w the width
// of the overlap. The cell's extent is split over the kernel's pixels; what falls beyond an edge
// goes to the edge pixel. The loops run over the kernel only: a light point near the receiver's
// depth stretches its cell over millions of pixels (r / (r − z)), which must not cost as many.
template <class Visit>
void spans(double lo, double hi, int n, Visit&& visit) {
  const int first = std::clamp(int(std::floor(lo + 0.5)), 0, n - 1);
  const int last = std::clamp(int(std::floor(hi + 0.5)), 0, n - 1);
  for (int x = first; x <= last; ++x) {
    const double left = x == 0 ? -std::numeric_limits<double>::infinity() : x - 0.5;
    const double right = x == n - 1 ? std::numeric_limits<double>::infinity() : x + 0.5;
    const double w = std::min(hi, right) - std::max(lo, left);
    if (w > 0) visit(x, w);
  }
}

// The kernel's sums before normalisation: the emission per channel and pixel (channel 0 only
// for a uniform light), its first moments, and the samples' emission-weighted centroid.
struct KernelSums {
  int nw, nh;
  std::array<std::vector<double>, 3> acc;
  std::array<std::vector<double>, 2> moment;
  Vec2 centroid = Vec2::Zero();

  KernelSums(int width, int height) : nw(width), nh(height) {
    for (auto& c : acc) c.assign(std::size_t(nw) * nh, 0.0);
    for (auto& c : moment) c.assign(std::size_t(nw) * nh, 0.0);
  }

  // Splats the sample at light offset (a, b), emission e (e0 in channel 0), as its cell's
  // bounding box about `centre` with half extents `half` and area `area`, in kernel pixels.
  void add_cell(const Vec2& centre, const Vec2& half, double area, bool uniform, const Vec3& e,
                double e0, double a, double b) {
    spans(centre.y() - half.y(), centre.y() + half.y(), nh, [&](int y, double wy) {
      spans(centre.x() - half.x(), centre.x() + half.x(), nw, [&](int x, double wx) {
        const std::size_t at = std::size_t(y) * nw + std::size_t(x);
        const double wgt = wx * wy / area;
        if (uniform) {
          acc[0][at] += wgt;
        } else {
          for (int c = 0; c < 3; ++c) acc[c][at] += wgt * e[c];
        }
        moment[0][at] += wgt * e0 * a;
        moment[1][at] += wgt * e0 * b;
      });
    });
    centroid += e0 * Vec2(a, b);
  }
};

// Splats samples of the light's surface into `sums`, mapped as source_kernel says and mirrored
// about pixel (half_w, half_h); `scale` is in kernel pixels per metre at k = 1.
void splat_light(const Light& light, const ProjectionFrame& frame, const Vec2& view, double r,
                 double scale, int half_w, int half_h, KernelSums& sums) {
  // Samples on the light's surface, several per kernel pixel along each of its axes (fewer for
  // large kernels, whose edges are smooth at pixel scale anyway; a sphere is its silhouette disk
  // seen along the view), equal area each.
  const Vec3 along = view_ray(frame, view);
  const SampleAxes axes = sample_axes(light, along);
  const Vec3 axis_u = axes.axis_u, axis_v = axes.axis_v;
  const double extent_u = axes.extent_u, extent_v = axes.extent_v;
  const bool round = axes.round, polygon = axes.polygon;
  const double px_per_metre = scale * 1.5;  // perspective can stretch by r/(r − z)
  // Each sample stands for a cell of the light, and is splatted as that cell's bounding box
  // (area-weighted over the pixels it overlaps, 2 × 2 at most at this density): the kernel's edge
  // pixels then get their coverage to second order in the cell size, where dropping each sample
  // into one pixel gets it to first order only, and needed 4× more samples per axis for the same
  // error.
  const int per_pixel = 2;
  const int nu = std::clamp(int(std::ceil(per_pixel * extent_u * px_per_metre)), 8, 4096);
  const int nv = std::clamp(int(std::ceil(per_pixel * extent_v * px_per_metre)), 8, 4096);
  // kernel_point's mapping with its dot products taken once: an offset a·axis_u + b·axis_v has
  // depth z = a·zu + b·zv and lateral offset s = a·su + b·sv.
  const double zu = axis_u.dot(frame.axis), zv = axis_v.dot(frame.axis);
  const Vec2 su(axis_u.dot(frame.e1), axis_u.dot(frame.e2));
  const Vec2 sv(axis_v.dot(frame.e1), axis_v.dot(frame.e2));
  const double da = extent_u / nu, db = extent_v / nv;
  const bool uniform = light.shape() == LightShape::sphere || !light.textured();
  for (int j = 0; j < nv; ++j) {
    const double b = ((j + 0.5) / nv - 0.5) * extent_v;
    for (int i = 0; i < nu; ++i) {
      const double a = ((i + 0.5) / nu - 0.5) * extent_u;
      if (round && a * a + b * b > 0.25 * extent_u * extent_u) continue;
      if (polygon && light.source_image(a * axis_u + b * axis_v, light.normal()).isZero()) continue;
      const double z = a * zu + b * zv;
      if (r - z <= 1e-9 * r) continue;  // at or beyond the receiver's depth
      const double stretch = r / (r - z);
      const Vec2 p = (a * su + b * sv - z * view) * stretch;
      // The cell's half extents in kernel pixels (its edges' images, to first order).
      const Vec2 edge_a = (su - zu * view) * (stretch * da * scale);
      const Vec2 edge_b = (sv - zv * view) * (stretch * db * scale);
      const Vec2 half = 0.5 * (edge_a.cwiseAbs() + edge_b.cwiseAbs());
      // Mirrored: the kernel holds the light at −u; pixel x spans [x − 0.5, x + 0.5].
      const Vec2 centre(-p.x() * scale + half_w, -p.y() * scale + half_h);
      double e0 = 1.0;
      Vec3 e = Vec3::Ones();
      if (!uniform) {
        e = light.tint(Vec2(a, b));
        e0 = e[0];
      }
      const double area = 4 * half.x() * half.y();
      if (!(area > 0)) continue;
      sums.add_cell(centre, half, area, uniform, e, e0, a, b);
    }
  }
  if (uniform) {
    for (int c = 1; c < 3; ++c) sums.acc[c] = sums.acc[0];
  }
}

// The kernel's channels from the sums, each normalised to sum 1, and, for a grey light other
// than a sphere, its moments and centroid normalised by channel 0's sum.
void normalise_kernel(const Light& light, const KernelSums& sums, SourceKernel& kernel) {
  const auto& acc = sums.acc;
  const auto& moment = sums.moment;
  for (int c = 0; c < 3; ++c) {
    double sum = 0;
    for (double v : acc[c]) sum += v;
    kernel.channels[c].assign(acc[c].size(), 0.0f);
    if (sum <= 0) continue;
    for (std::size_t k = 0; k < acc[c].size(); ++k) kernel.channels[c][k] = float(acc[c][k] / sum);
  }
  kernel.grey =
      kernel.channels[0] == kernel.channels[1] && kernel.channels[1] == kernel.channels[2];
  double sum0 = 0;
  for (double v : acc[0]) sum0 += v;
  if (kernel.grey && light.shape() != LightShape::sphere && sum0 > 0) {
    for (int m = 0; m < 2; ++m) {
      kernel.moments[m].resize(moment[m].size());
      for (std::size_t k = 0; k < moment[m].size(); ++k)
        kernel.moments[m][k] = float(moment[m][k] / sum0);
    }
    kernel.centroid = sums.centroid / sum0;
  }
}

}  // namespace

SourceKernel source_kernel(const Light& light, const ProjectionFrame& frame,
                           double tangent_per_metre, double pixel, const Vec2& view,
                           double receiver_depth) {
  const double r = receiver_depth;
  const double scale = tangent_per_metre / pixel;  // kernel pixels per metre at k = 1
  const Vec2 radius_px = projected_half_extents(light, frame, view, r) * scale;
  const int half_w = std::max(0, int(std::ceil(radius_px.x() - 0.5)));
  const int half_h = std::max(0, int(std::ceil(radius_px.y() - 0.5)));
  // The source is smaller than a pixel: a point light, whose kernel is a delta.
  if ((half_w == 0 && half_h == 0) || tangent_per_metre <= 0) return point_kernel(light);
  SourceKernel kernel;
  kernel.width = 2 * half_w + 1;
  kernel.height = 2 * half_h + 1;
  KernelSums sums(kernel.width, kernel.height);
  splat_light(light, frame, view, r, scale, half_w, half_h, sums);
  normalise_kernel(light, sums, kernel);
  return kernel;
}

}  // namespace sb
