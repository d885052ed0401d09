// The convolution kernel: the source image scaled and mirrored (design-notes §2;
// ../shared/seeds/001_414ff95054935c53.txt, "Proof that Convolution is Appropriate").
//
// Seen from a receiver point, a point s of the source (an offset across D from the light's centre)
// is hidden when the blocker image is opaque at t + k·s, t being the receiver point's tangent
// coordinates and k = 1/d* − 1/r*. So the occluded, emission-weighted fraction is
// O(t) = Σ_s S(s) P(t + k·s) / Σ S = Σ_u K(u) P(t − u) with K(u) = S(−u/k) / Σ S: the source image
// scaled by k (per metre to tangent units), mirrored through its centre, normalised. The kernel is
// centred on a pixel (odd size): with an even size the whole shadow would shift by half a pixel.
#include "source_image.h"

#include <algorithm>
#include <cmath>

namespace sb {

SourceKernel source_kernel(const Light& light, const ProjectionFrame& frame,
                           double tangent_per_metre, double pixel) {
  SourceKernel kernel;
  const Vec2 radius_px = light.half_extents(frame.e1, frame.e2) * (tangent_per_metre / pixel);
  const int half_w = std::max(0, int(std::ceil(radius_px.x())));
  const int half_h = std::max(0, int(std::ceil(radius_px.y())));
  kernel.width = 2 * half_w + 1;
  kernel.height = 2 * half_h + 1;
  const int nw = kernel.width, nh = kernel.height;
  for (auto& c : kernel.channels) c.assign(std::size_t(nw) * nh, 0.0f);
  if ((half_w == 0 && half_h == 0) || tangent_per_metre <= 0) {
    // The source is smaller than a pixel: a point light, whose kernel is a delta.
    const Vec3 e = light.exitance();
    for (int c = 0; c < 3; ++c) kernel.channels[c].assign(1, e[c] > 0 ? 1.0f : 0.0f);
    kernel.width = kernel.height = 1;
    kernel.grey = e.x() == e.y() && e.y() == e.z();
    return kernel;
  }
  // Fewer samples per pixel for large kernels, whose edges are smooth at pixel scale anyway.
  const int larger = std::max(nw, nh);
  const int samples = larger <= 64 ? 8 : larger <= 256 ? 4 : 2;
  const double metres_per_px = pixel / tangent_per_metre;
  std::array<double, 3> sum = {0, 0, 0};
  for (int j = 0; j < nh; ++j) {
    for (int i = 0; i < nw; ++i) {
      Vec3 acc = Vec3::Zero();
      for (int sy = 0; sy < samples; ++sy) {
        for (int sx = 0; sx < samples; ++sx) {
          const double ux = i - half_w + (sx + 0.5) / samples - 0.5;
          const double uy = j - half_h + (sy + 0.5) / samples - 0.5;
          // Mirrored: kernel offset u reads the source at −u.
          const Vec3 offset = -(ux * frame.e1 + uy * frame.e2) * metres_per_px;
          acc += light.source_image(offset, frame.axis);
        }
      }
      for (int c = 0; c < 3; ++c) {
        kernel.channels[c][std::size_t(j) * nw + i] = float(acc[c]);
        sum[c] += acc[c];
      }
    }
  }
  for (int c = 0; c < 3; ++c) {
    if (sum[c] <= 0) continue;
    for (float& v : kernel.channels[c]) v = float(v / sum[c]);
  }
  kernel.grey =
      kernel.channels[0] == kernel.channels[1] && kernel.channels[1] == kernel.channels[2];
  return kernel;
}

}  // namespace sb
