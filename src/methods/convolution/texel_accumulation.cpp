// Adding convolved leaves into receiver texels (texel_accumulation.h; docs/design.md §6 for the
// irradiance weighting's first-order correction).
#include "methods/convolution/texel_accumulation.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include "core/stopwatch.h"

namespace sb {

namespace {

using Clock = std::chrono::steady_clock;

// A bilinear read of width × height images at continuous pixel coordinates (centres at
// integers), clamped at the border: the four pixels and weights found once, for the several
// images of one grid a texel reads.
class Bilinear {
 public:
  Bilinear(int w, int h, const Vec2& p) {
    const double fx = std::clamp(p.x(), 0.0, double(w - 1));
    const double fy = std::clamp(p.y(), 0.0, double(h - 1));
    const int x0 = std::max(0, std::min(int(fx), w - 2));
    const int y0 = std::max(0, std::min(int(fy), h - 2));
    dx_ = std::min(x0 + 1, w - 1) - x0;
    dy_ = std::size_t(std::min(y0 + 1, h - 1) - y0) * std::size_t(w);
    first_ = std::size_t(y0) * std::size_t(w) + std::size_t(x0);
    tx_ = fx - x0;
    ty_ = fy - y0;
  }
  float operator()(const std::vector<float>& image) const {
    const float* p = image.data() + first_;
    return float((1 - ty_) * ((1 - tx_) * p[0] + tx_ * p[dx_]) +
                 ty_ * ((1 - tx_) * p[dy_] + tx_ * p[dy_ + std::size_t(dx_)]));
  }

 private:
  std::size_t first_ = 0, dy_ = 0;
  int dx_ = 0;
  double tx_ = 0, ty_ = 0;
};

}  // namespace

std::vector<Vec2> weight_gradients(const PlanFrame& fr, const TexelSpace& space,
                                   const Light& light) {
  std::vector<Vec2> g(fr.texels.size(), Vec2::Zero());
  if (light.shape() == LightShape::sphere) return g;
  const Vec3 c = light.centre(), n = light.normal();
  const Vec3 axes[2] = {light.right(), light.up()};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, g.size(), 4096), [&](const auto& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const Texel& t = space.texels[fr.texels[i]];
      const Vec3 nx = t.normal.cast<double>();
      // w = (n·d)(−n_x·d)/|d|⁴ with d = x − y: moving y by s along a gives
      // d ln w/ds = −(n·a)/(n·d) + (n_x·a)/(−n_x·d) + 4 (d·a)/|d|².
      const Vec3 d = t.position.cast<double>() - c;
      const double len2 = d.squaredNorm(), len = std::sqrt(len2);
      const double nd = n.dot(d), xd = -nx.dot(d);
      if (nd <= 1e-3 * len || xd <= 1e-3 * len) continue;
      for (int a = 0; a < 2; ++a)
        g[i][a] = -n.dot(axes[a]) / nd + nx.dot(axes[a]) / xd + 4 * d.dot(axes[a]) / len2;
    }
  });
  return g;
}

void accumulate_leaf(const ConvolutionPlan& plan, const Triple& leaf, const LeafImages& images,
                     BlockerCombine combine, const std::vector<Vec2>& gradient,
                     std::vector<Vec3f>& occlusion, std::vector<Vec3f>& largest,
                     std::vector<float>& error, EulerCounts* euler, PairReport& report) {
  const PlanFrame& fr = plan.frames[leaf.frame];
  const SourceKernel& kernel = images.kernel;
  report.seconds_source += images.seconds_source;
  report.seconds_blocker += images.seconds_blocker;
  report.seconds_fft += images.seconds_fft;
  report.convolutions += images.convolutions;
  report.image_width = std::max(report.image_width, leaf.grid.width);
  report.image_height = std::max(report.image_height, leaf.grid.height);
  report.kernel_width = std::max(report.kernel_width, kernel.width);
  report.kernel_height = std::max(report.kernel_height, kernel.height);
  for (const LeafWindow& win : images.windows) {
    report.fft_width = std::max(report.fft_width, win.tw);
    report.fft_height = std::max(report.fft_height, win.th);
  }

  const auto start = Clock::now();
  // How much of the slab's geometry lies in front of a texel, with half a texel of tolerance so
  // that a blocker standing on the receiver shadows the texels beside its foot.
  // Plain variables, not a structured binding: clang 14 (the fuzz build) cannot capture one.
  const std::pair<double, double> interval = part_interval(leaf.cuts);
  const double lo = interval.first, hi = interval.second;
  const double g_lo = leaf.blocker_depths.lo, g_hi = leaf.blocker_depths.hi;
  const double bias = 0.5 * plan.texel;
  // The footprint's texels, each with the window it reads (windows' boxes are disjoint).
  std::vector<std::pair<int, int>> texels;
  for (std::size_t k = 0; k < images.windows.size(); ++k) {
    const LeafWindow& win = images.windows[k];
    fr.index[std::size_t(leaf.group)].for_each(win.lo, win.hi, [&](int i) {
      const double d = fr.depth[std::size_t(i)];
      const Vec2& tc = fr.tangent[std::size_t(i)];
      if (d <= g_lo || d < lo || d > hi) return;
      if ((tc.array() < win.lo.array()).any() || (tc.array() > win.hi.array()).any()) return;
      texels.emplace_back(i, int(k));
    });
  }
  if (euler) {
    for (const auto& [i, k] : texels) {
      if (euler->touched_flag[std::size_t(i)]) continue;
      euler->touched_flag[std::size_t(i)] = 1;
      euler->touched.push_back(i);
    }
  }
  const bool weighted =
      !gradient.empty() && !images.windows.empty() && !images.windows.front().moment[0].empty();
  const bool with_full = combine == BlockerCombine::sum;
  const int channels = kernel.grey ? 1 : 3;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, texels.size(), 2048), [&](const auto& r) {
    for (std::size_t j = r.begin(); j != r.end(); ++j) {
      const std::size_t i = std::size_t(texels[j].first);
      const LeafWindow& win = images.windows[std::size_t(texels[j].second)];
      const int w = win.grid.width, h = win.grid.height;
      const double depth = fr.depth[i];
      double wt = g_hi > g_lo ? std::clamp((depth + bias - g_lo) / (g_hi - g_lo), 0.0, 1.0) : 1.0;
      for (const ReceiverCut& c : leaf.cuts) wt *= c.weight(depth);
      if (wt <= 0) continue;
      error[i] = std::max(error[i], float(leaf.penumbra_error_texels));
      const Bilinear at(w, h, win.grid.to_pixel(fr.tangent[i]));
      // The moments' correction is the same for every channel (grey kernels only); the whole
      // image takes it too, or the max rule would compare an irradiance-weighted share with an
      // emission-weighted whole and keep the darker of two different quantities.
      double first = 0, first_full = 0, norm = 1;
      if (weighted) {
        // O_w = Σ S·w·P / Σ S·w with w ≈ w0·(1 + g·(a, b)): the occluded irradiance fraction.
        const Vec2& g = gradient[i];
        first = g.x() * at(win.moment[0]) + g.y() * at(win.moment[1]);
        first_full = win.moment_full[0].empty()
                         ? first
                         : g.x() * at(win.moment_full[0]) + g.y() * at(win.moment_full[1]);
        norm = std::max(0.1, 1.0 + g.dot(kernel.centroid));
      }
      for (int c = 0; c < channels; ++c) {
        const double share = at(win.occluded[c]);
        const double o = std::clamp((share + first) / norm, 0.0, 1.0);
        if (leaf.section) {
          for (int out = kernel.grey ? 0 : c; out < (kernel.grey ? 3 : c + 1); ++out)
            euler->count[i][out] -= float(wt * o);
          continue;
        }
        const double f = combine == BlockerCombine::sum ? o : -std::log(std::max(1e-6, 1.0 - o));
        float whole = 0;
        if (with_full) {
          const double v = win.occluded_full[c].empty() ? share : at(win.occluded_full[c]);
          whole = float(wt * std::clamp((v + first_full) / norm, 0.0, 1.0));
        }
        // A grey kernel's one channel stands for all three.
        for (int out = kernel.grey ? 0 : c; out < (kernel.grey ? 3 : c + 1); ++out) {
          occlusion[i][out] += float(wt * f);
          if (with_full) largest[i][out] = std::max(largest[i][out], whole);
          if (euler) euler->count[i][out] += whole;
        }
      }
    }
  });
  report.seconds_lookup += seconds_since(start);
}

void mark_traced(const ConvolutionPlan& plan, const Triple& leaf, std::vector<float>& error) {
  const PlanFrame& fr = plan.frames[leaf.frame];
  const std::pair<double, double> interval = part_interval(leaf.cuts);
  const double g_lo = leaf.blocker_depths.lo;
  fr.index[std::size_t(leaf.group)].for_each(leaf.footprint_lo, leaf.footprint_hi, [&](int i) {
    const double d = fr.depth[std::size_t(i)];
    if (d <= g_lo || d < interval.first || d > interval.second) return;
    error[std::size_t(i)] = std::numeric_limits<float>::infinity();
  });
}

}  // namespace sb
