// Soft shadow textures by convolution (Soler & Sillion, "Fast Calculation of Soft Shadow Textures
// Using Convolution", SIGGRAPH 1998; ../shared/seeds/001_414ff95054935c53.txt; the mathematics in
// design-notes §2–4).
//
// For each light and receiver: choose the virtual parallel configuration (virtual_configuration),
// render the source kernel (source_image) and the blocker image (blocker_image) on one grid of the
// tangent plane, convolve them by FFT (fft_convolution) to get the occluded fraction O, and give
// each lit texel V = 1 − O read bilinearly at its central projection through the light's centre.
// That projection makes hard-shadow positions exact for the light's centre whatever the
// geometry; only penumbra widths are approximate, by at most the penumbra error ε reported.
//
// V here is the emission-weighted unoccluded fraction V_u of design-notes §1 (the paper's split
// H ≈ H0 · V_u), not the irradiance-weighted V of the reference; §1 says by how much they differ.
#include "convolution_bake.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "blocker_image.h"
#include "fft_convolution.h"
#include "source_image.h"

namespace sb {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Bilinear read of a width × height image at continuous pixel coordinates (centres at integers),
// clamped at the border.
float bilinear(const std::vector<float>& image, int w, int h, const Vec2& p) {
  const double fx = std::clamp(p.x(), 0.0, double(w - 1));
  const double fy = std::clamp(p.y(), 0.0, double(h - 1));
  const int x0 = std::max(0, std::min(int(fx), w - 2));
  const int y0 = std::max(0, std::min(int(fy), h - 2));
  const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
  const double tx = fx - x0, ty = fy - y0;
  const auto at = [&](int x, int y) { return double(image[std::size_t(y) * w + x]); };
  return float((1 - ty) * ((1 - tx) * at(x0, y0) + tx * at(x1, y0)) +
               ty * ((1 - tx) * at(x0, y1) + tx * at(x1, y1)));
}

}  // namespace

double texel_size(const Mesh& mesh, int width, int height) {
  double world = 0, uv = 0;
  for (auto f : mesh.mesh.faces()) {
    const Triangle t = triangle(mesh.mesh, f);
    world += 0.5 * (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).norm();
    const Vec2 a = t.uv[1] - t.uv[0], b = t.uv[2] - t.uv[0];
    uv += 0.5 * std::abs(a.x() * b.y() - a.y() * b.x());
  }
  if (uv <= 0) return 0;
  return std::sqrt(world / (uv * double(width) * height));
}

namespace {

// One light's visibility over one set of texels seen through one frustum: the virtual
// configuration, source kernel, blocker image, convolution and lookup. Writes V per channel into
// visibility[t] for each t in `texels`, and fills `report`.
void convolve_part(const TexelSpace& space, const std::vector<std::size_t>& texels,
                   const Light& light, const ProjectionFrame& frame, double texel,
                   const ConvolutionInputs& in, std::vector<Vec3f>& visibility,
                   PairReport& report) {
  auto start = Clock::now();
  report.lit_texels = std::int64_t(texels.size());
  for (int k = 0; k < 3; ++k) report.axis[k] = frame.axis[k];
  DepthRange receiver_depths;
  ShadowCaster caster;
  for (std::size_t t : texels) {
    const Vec3 p = space.texels[t].position.cast<double>();
    receiver_depths.extend(frame.depth(p));
    caster.receiver.extend(p);
  }
  // Texels this close to the light's plane across D (or behind it) cannot be projected; they
  // keep V = 1 and are counted. The caller's choice of frusta keeps them rare.
  const double near = std::max(1e-4, 1e-3 * receiver_depths.hi);
  Vec2 t_lo = Vec2::Constant(std::numeric_limits<double>::infinity()), t_hi = -t_lo;
  DepthRange projected_depths;
  for (std::size_t t : texels) {
    const Vec3 p = space.texels[t].position.cast<double>();
    visibility[t] = Vec3f::Ones();
    if (frame.depth(p) <= near) {
      ++report.outside_texels;
      continue;
    }
    projected_depths.extend(frame.depth(p));
    const Vec2 tc = frame.tangent(p);
    t_lo = t_lo.cwiseMin(tc);
    t_hi = t_hi.cwiseMax(tc);
  }
  if (projected_depths.empty()) return;
  caster.light_radius = light.shape() == LightShape::rectangle
                            ? 0.5 * std::hypot(light.desc().width, light.desc().height)
                            : light.desc().radius;
  const ProjectedBlockers blockers =
      project_blockers(in.blockers, frame, near, projected_depths.hi, caster);
  const DepthRange blocker_depths = blocker_depths_over(blockers, t_lo, t_hi);
  const VirtualConfiguration config = choose_configuration(frame, blocker_depths, projected_depths,
                                                           light.extent_across(frame.axis));
  report.seconds_configure = seconds_since(start);

  report.receiver_depth_lo = projected_depths.lo;
  report.receiver_depth_hi = projected_depths.hi;
  report.blocker_plane = config.blocker_plane;
  report.receiver_plane = config.receiver_plane;
  report.rho_lo = config.rho_lo;
  report.rho_hi = config.rho_hi;
  report.rho = config.rho;
  report.light_extent = config.light_extent;
  report.penumbra_error = config.penumbra_error;
  report.penumbra_error_texels = texel > 0 ? config.penumbra_error / texel : 0;
  if (blocker_depths.empty()) return;  // nothing can shadow these texels
  report.blocker_depth_lo = blocker_depths.lo;
  report.blocker_depth_hi = blocker_depths.hi;

  start = Clock::now();
  const double k = 1.0 / config.blocker_plane - 1.0 / config.receiver_plane;
  // One blocker pixel per receiver texel at the receiver plane, unless the image would exceed
  // max_image (then coarser, uniformly).
  const Vec2 span = t_hi - t_lo;
  double pixel = texel > 0 ? texel / config.receiver_plane : span.maxCoeff() / 512;
  const Vec2 kernel_extent = 2 * k * light.half_extents(frame.e1, frame.e2);
  const double needed = (span + kernel_extent).maxCoeff();
  if (needed / pixel + 4 > in.max_image) pixel = needed / (in.max_image - 4);
  const SourceKernel kernel = source_kernel(light, frame, k, pixel);
  report.seconds_source = seconds_since(start);

  start = Clock::now();
  // The convolution is exact where the kernel stays inside the image: pad the texels' footprint
  // by the kernel's radius (plus one pixel for the bilinear lookup).
  const int margin_x = kernel.width / 2 + 1, margin_y = kernel.height / 2 + 1;
  TangentGrid grid;
  grid.pixel = pixel;
  grid.origin = t_lo - Vec2(margin_x, margin_y) * pixel;
  grid.width = int(std::ceil(span.x() / pixel)) + 2 * margin_x + 1;
  grid.height = int(std::ceil(span.y() / pixel)) + 2 * margin_y + 1;
  const std::vector<float> coverage = blocker_coverage(blockers, grid);
  report.seconds_blocker = seconds_since(start);

  start = Clock::now();
  auto& fft = FftConvolver::shared();
  const int tw = FftConvolver::fast_size(grid.width), th = FftConvolver::fast_size(grid.height);
  const bool grey = kernel.grey;
  std::array<std::vector<float>, 3> occluded;
  for (int c = 0; c < (grey ? 1 : 3); ++c) {
    const auto spectrum =
        fft.kernel_spectrum(kernel.channels[c], kernel.width, kernel.height, tw, th);
    fft.convolve(coverage, grid.width, grid.height, *spectrum, occluded[c]);
  }
  report.seconds_fft = seconds_since(start);
  report.pixel = pixel;
  report.image_width = grid.width;
  report.image_height = grid.height;
  report.kernel_width = kernel.width;
  report.kernel_height = kernel.height;
  report.fft_width = tw;
  report.fft_height = th;
  report.convolutions = grey ? 1 : 3;

  start = Clock::now();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, texels.size(), 1024), [&](const auto& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const std::size_t t = texels[i];
      const Vec3 p = space.texels[t].position.cast<double>();
      if (frame.depth(p) <= near) continue;
      const Vec2 at = grid.to_pixel(frame.tangent(p));
      for (int c = 0; c < 3; ++c) {
        const float o = bilinear(occluded[grey ? 0 : c], grid.width, grid.height, at);
        visibility[t][c] = std::clamp(1.0f - o, 0.0f, 1.0f);
      }
    }
  });
  report.seconds_lookup = seconds_since(start);
}

// The widest angle, from the light's centre, between a receiver's texels and its frustum's axis
// that one projection serves; beyond it the tangent plane stretches without bound (tan 60° = 1.7).
constexpr double kMaxFrustumHalfAngleDeg = 60.0;

}  // namespace

Image bake_convolution(const TexelSpace& space, const ConvolutionInputs& in,
                       std::vector<PairReport>* reports) {
  const auto& lights = *in.lights;
  const std::size_t n = space.texels.size();
  const double texel = texel_size(*in.receiver, space.width, space.height);
  // Per texel, Σ_l w_l·V_l (accumulated in the output) and Σ_l w_l, where the weight w_l is H0_l.
  // One light's visibility needs no closed form: its weight is its exitance where it reaches
  // the texel (so that a channel it does not emit stays 0), which is much cheaper.
  const bool weights_needed = lights.size() > 1 || in.quantity == Quantity::irradiance;
  Image out(space.width, space.height, 3, 0.0f);
  std::vector<Vec3f> weight_sum(n, Vec3f::Zero());
  std::vector<Vec3f> visibility(n);
  std::vector<std::uint8_t> reached(n);
  auto position = [&](std::size_t t) { return Vec3(space.texels[t].position.cast<double>()); };

  for (const Light& light : lights) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const auto& r) {
      for (std::size_t t = r.begin(); t != r.end(); ++t)
        reached[t] = light.reaches(position(t), space.texels[t].normal.cast<double>());
    });
    std::vector<std::size_t> lit;
    Bounds3 lit_bounds;
    for (std::size_t t = 0; t < n; ++t) {
      if (!reached[t]) continue;
      lit.push_back(t);
      lit_bounds.extend(position(t));
    }
    auto add_report = [&](PairReport report, const char* part) {
      report.light = light.desc().name;
      report.receiver = in.receiver->name;
      report.part = part;
      if (reports) reports->push_back(std::move(report));
    };
    if (lit.empty()) {
      add_report(PairReport{}, "");
      continue;
    }
    // One frustum from the light's centre towards the middle of the lit texels (design-notes
    // §3) when it holds them all within kMaxFrustumHalfAngleDeg; otherwise (a light beside or
    // among its receiver) the six faces of a cube around the light, each its own frustum.
    const ProjectionFrame central = frame_towards(light.centre(), lit_bounds.centre());
    double widest = 1.0;
    for (std::size_t t : lit) {
      const Vec3 d = position(t) - light.centre();
      const double len = d.norm();
      widest = std::min(widest, len > 0 ? d.dot(central.axis) / len : 1.0);
    }
    if (widest >= std::cos(kMaxFrustumHalfAngleDeg * std::numbers::pi / 180.0)) {
      PairReport report;
      convolve_part(space, lit, light, central, texel, in, visibility, report);
      add_report(std::move(report), "");
    } else {
      static const char* kFaces[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
      std::array<std::vector<std::size_t>, 6> faces;
      for (std::size_t t : lit) {
        const Vec3 d = position(t) - light.centre();
        int axis;
        d.cwiseAbs().maxCoeff(&axis);
        faces[2 * axis + (d[axis] < 0 ? 1 : 0)].push_back(t);
      }
      for (int f = 0; f < 6; ++f) {
        if (faces[f].empty()) continue;
        Vec3 axis = Vec3::Zero();
        axis[f / 2] = f % 2 ? -1.0 : 1.0;
        PairReport report;
        convolve_part(space, faces[f], light, frame_towards(light.centre(), light.centre() + axis),
                      texel, in, visibility, report);
        add_report(std::move(report), kFaces[f]);
      }
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, lit.size(), 4096), [&](const auto& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        const std::size_t t = lit[i];
        const Texel& tx = space.texels[t];
        const Vec3f w =
            (weights_needed ? light.unoccluded_irradiance(position(t), tx.normal.cast<double>())
                            : light.exitance())
                .cast<float>();
        float* px = out.at(tx.x, tx.y);
        for (int c = 0; c < 3; ++c) px[c] += w[c] * visibility[t][c];
        weight_sum[t] += w;
      }
    });
  }

  if (in.quantity == Quantity::visibility) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const auto& r) {
      for (std::size_t t = r.begin(); t != r.end(); ++t) {
        float* px = out.at(space.texels[t].x, space.texels[t].y);
        for (int c = 0; c < 3; ++c) px[c] = weight_sum[t][c] > 0 ? px[c] / weight_sum[t][c] : 0.0f;
      }
    });
  }
  return out;
}

}  // namespace sb
