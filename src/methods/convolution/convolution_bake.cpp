// Soft shadow textures by convolution (Soler & Sillion, "Fast Calculation of Soft Shadow Textures
// Using Convolution", SIGGRAPH 1998; ../shared/seeds/001_414ff95054935c53.txt; the mathematics in
// design-notes §2–4).
//
// For each receiver, plan_convolution (convolution_plan.cpp) chooses the hierarchy of (light part,
// blocker cluster, receiver part) triples. Each leaf triple renders its source kernel
// (source_image) and blocker image (blocker_image) on one grid of its frustum's tangent plane,
// convolves them by FFT (fft_convolution) to get the occluded fraction O, and gives each texel
// of its footprint O read bilinearly at the texel's central projection through the light part's
// centre. That projection makes hard-shadow positions exact for the light's centre whatever the
// geometry; only penumbra widths are approximate, by at most the penumbra error ε reported.
// A leaf whose blockers fall into islands far apart (a table's legs in one slab) is convolved on
// a window per island (leaf_windows): the same values, by linearity, for far fewer pixels.
//
// Combining leaves at a texel: a receiver split's two parts are blended by their cut weights (a
// partition of unity across the seam); a slab's shadow counts in proportion to the part of its
// geometry in front of the texel; blocker clusters combine by BlockerCombine, which becomes a
// weighted sum S = Σ w·f(O) with f(O) = O, V = 1 − min(S, 1) (sum) or f(O) = −ln(1 − O),
// V = exp(−S) (product). Light parts add weighted by their own unoccluded irradiance at the texel
// (by their share of the power with `weighting = "emission"`).
//
// With `sum`, each cluster's image is its share of the nearest layer (nearest_layer_coverage),
// so the shares partition the hard shadow seen from the light's centre. A cluster hidden behind
// another there still hides light from other points of the light: a bracket's base lies under
// the shadow of its own wall, yet the floor beneath the base is dark whatever the wall does. So
// the occluded fraction is at least each cluster's own, from its whole image:
// O = max(Σ O_share, max O_whole) (a union is at least as large as any of its sets). The
// second convolution is skipped for clusters that nothing hides.
//
// Neither holds the light that a thick solid hides from off-centre light points only: rays that
// enter a post through a side the light's centre does not see. For a convex closed solid
// (add_sections) the plan keeps its slabs together: each slab's whole image is capped by the
// solid's section at its near depth (the solid slab's projection, not the ring of its faces), and
// a section leaf sits at every depth between two slabs. A line from the texel to a light point
// meets a convex solid in one interval, which touches k consecutive slabs and crosses the k − 1
// sections between them inside the solid, so Σ whole slabs − Σ sections (Euler's count) is the
// fraction of the light the solid hides, E; O = max(Σ O_share, max O_whole, max E). Each term
// is convolved at its own plane: sections exactly, slabs within their penumbra error.
//
// V is the irradiance-weighted visibility of the reference to first order across the light
// (design-notes §6): the weight cos·cos/distance² of the light's points seen from a texel is
// expanded about the centre, and the kernel's two first moments, convolved with the same image,
// give the correction (two more convolutions per leaf; ConvolutionInputs::weighted). Without it
// V is the emission-weighted V_u of design-notes §1.
#include "methods/convolution/convolution_bake.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "methods/convolution/blocker_image.h"
#include "methods/convolution/buried_texels.h"
#include "methods/convolution/convolution_plan.h"
#include "core/memory_size.h"
#include "methods/convolution/source_image.h"

namespace sb {

namespace {

using Clock = std::chrono::steady_clock;

// Transform pixels of the leaves convolved together before their images are added in (about
// 5 images of 4 bytes each per pixel: 64 MiB).
constexpr std::size_t kBatchPixels = std::size_t(1) << 22;

// Bytes per transform pixel of a leaf being convolved: its blocker images (share and whole, 8),
// its results (3 colour channels and 2 moments, for the share and the whole: 40), FFTW's padded
// input and spectrum (12) and the cached kernel spectra (5 kernels of half a spectrum: 20),
// rounded up for the allocator.
constexpr double kBytesPerTransformPixel = 96;

// How far outside a solid's face plane a texel may lie and still count as buried in it, in
// receiver texels: a floor texel under a box's bottom face lies on that plane up to rounding.
constexpr double kBuriedTolerance = 1e-3;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

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

// The irradiance weight w = cos θ_light · cos θ_receiver / distance² of the light's points seen
// from each texel, to first order across the light: the gradient of ln w at the light's centre
// along its right and up axes, per metre (design-notes §6). Zero where the light's centre lies
// on or below the texel's horizon or the texel on or behind the light's plane (cosines under
// 1e-3), where a first-order weight would mislead.
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

// Euler's counts of a frame's convex solids (add_sections): the solid whose leaves are being
// added (leaves are sorted so that each solid's come together), its count per frame texel, the
// texels it touched, and per texel the largest count of the solids done.
struct EulerCounts {
  int solid = -1;
  std::vector<Vec3f> count, largest;
  std::vector<std::uint8_t> touched_flag;
  std::vector<int> touched;

  explicit EulerCounts(std::size_t texels)
      : count(texels, Vec3f::Zero()), largest(texels, Vec3f::Zero()), touched_flag(texels, 0) {}
  // Starts the count of `next`, folding the previous solid's into `largest`.
  void begin(int next) {
    if (next == solid) return;
    for (int i : touched) {
      largest[std::size_t(i)] = largest[std::size_t(i)].cwiseMax(count[std::size_t(i)]);
      count[std::size_t(i)] = Vec3f::Zero();
      touched_flag[std::size_t(i)] = 0;
    }
    touched.clear();
    solid = next;
  }
};

// One window of a leaf's grid and its convolved images: the whole grid, or, where the leaf's
// blockers fall into islands whose shadows cannot meet (leaf_windows), the part around one
// island. `lo`, `hi` bound the tangents of the texels that read it.
struct LeafWindow {
  TangentGrid grid;
  Vec2 lo = Vec2::Zero(), hi = Vec2::Zero();
  int tw = 0, th = 0;
  std::array<std::vector<float>, 3> occluded;       // share of the nearest layer ⊛ kernel
  std::array<std::vector<float>, 3> occluded_full;  // whole image ⊛ kernel; empty if equal
  std::array<std::vector<float>, 2> moment;         // share ⊛ moment kernels (weighting)
  std::array<std::vector<float>, 2> moment_full;    // whole ⊛ moment kernels, if whole differs
};

// One leaf's convolved images, made independently of every other leaf (so leaves run in
// parallel) and then added into the frame's texels by accumulate_leaf.
struct LeafImages {
  SourceKernel kernel;
  std::vector<LeafWindow> windows;
  int convolutions = 0;
  double seconds_source = 0, seconds_blocker = 0, seconds_fft = 0;
};

// A leaf's blockers often fall into islands far apart: the four legs of a table, cut into the
// same slab, project to four small squares at the corners of one large image. Convolution is
// linear and the kernel reaches only `reach` from a blocker pixel, so each island can be
// convolved on a window of its own, read by the texels within `reach` of it, as long as no such
// texel is within reach of another island: the values are those of the whole grid, for a
// fraction of its pixels. `boxes` are tangent boxes holding every polygon that can put coverage
// into the leaf's images. Returns the windows (islands merged until their grown boxes are
// disjoint), or the whole grid alone where the windows would not save at least a third of its
// transform.
std::vector<LeafWindow> leaf_windows(const Triple& leaf, const SourceKernel& kernel,
                                     const std::vector<std::pair<Vec2, Vec2>>& boxes,
                                     const ConvolutionBackend& fft) {
  const TangentGrid& g = leaf.grid;
  std::vector<LeafWindow> whole(1);
  whole[0].grid = g;
  whole[0].lo = leaf.footprint_lo;
  whole[0].hi = leaf.footprint_hi;
  whole[0].tw = leaf.fft_width;
  whole[0].th = leaf.fft_height;
  // The kernel's half extents plus two pixels (rasterisation and bilinear reads).
  const Vec2 reach = Vec2(kernel.width / 2 + 2, kernel.height / 2 + 2) * g.pixel;
  const Vec2 grid_lo = g.origin, grid_hi = g.origin + Vec2(g.width, g.height) * g.pixel;
  auto apart = [&](const std::pair<Vec2, Vec2>& a, const std::pair<Vec2, Vec2>& b) {
    return ((a.second + reach).array() < (b.first - reach).array()).any() ||
           ((b.second + reach).array() < (a.first - reach).array()).any();
  };
  std::vector<std::pair<Vec2, Vec2>> islands;
  for (auto box : boxes) {
    if (((box.second + reach).array() < grid_lo.array()).any() ||
        ((box.first - reach).array() > grid_hi.array()).any())
      continue;  // wholly outside the grid: rasterises to nothing
    // Absorb every island this box (as it grows) comes within reach of.
    for (bool merged = true; merged;) {
      merged = false;
      for (std::size_t i = 0; i < islands.size(); ++i) {
        if (apart(box, islands[i])) continue;
        box.first = box.first.cwiseMin(islands[i].first);
        box.second = box.second.cwiseMax(islands[i].second);
        islands.erase(islands.begin() + std::ptrdiff_t(i));
        merged = true;
        break;
      }
    }
    islands.push_back(box);
  }
  if (islands.size() < 2) return whole;
  std::vector<LeafWindow> windows;
  int tw = 0, th = 0;
  for (const auto& [lo, hi] : islands) {
    LeafWindow w;
    const Vec2 a = (lo - reach - g.origin) / g.pixel, b = (hi + reach - g.origin) / g.pixel;
    const int x0 = std::max(0, int(std::floor(a.x()))), y0 = std::max(0, int(std::floor(a.y())));
    const int x1 = std::min(g.width, int(std::ceil(b.x())) + 1);
    const int y1 = std::min(g.height, int(std::ceil(b.y())) + 1);
    if (x0 >= x1 || y0 >= y1) continue;
    w.grid.pixel = g.pixel;
    w.grid.origin = g.origin + Vec2(x0, y0) * g.pixel;
    w.grid.width = x1 - x0;
    w.grid.height = y1 - y0;
    w.lo = (lo - reach).cwiseMax(leaf.footprint_lo);
    w.hi = (hi + reach).cwiseMin(leaf.footprint_hi);
    tw = std::max(tw, fft.transform_size(w.grid.width));
    th = std::max(th, fft.transform_size(w.grid.height));
    windows.push_back(std::move(w));
  }
  // One transform size for all windows: the kernel's spectra and FFTW's plans are shared.
  if (double(windows.size()) * tw * th > (2.0 / 3.0) * double(leaf.fft_width) * leaf.fft_height)
    return whole;
  for (LeafWindow& w : windows) {
    w.tw = tw;
    w.th = th;
  }
  return windows;
}

// Renders one leaf's kernel and blocker images and convolves them.
LeafImages convolve_leaf(const ConvolutionPlan& plan, const Triple& leaf, BlockerCombine combine,
                         bool weighted, bool windows, ConvolutionBackend& fft) {
  LeafImages out;
  const PlanFrame& fr = plan.frames[leaf.frame];
  const Light& light = plan.light_parts[fr.light_part].part;
  auto start = Clock::now();
  const double k =
      std::max(0.0, 1.0 / leaf.config.blocker_plane - 1.0 / leaf.config.receiver_plane);
  out.kernel =
      source_kernel(light, fr.frame, k, leaf.grid.pixel, leaf.view, leaf.config.receiver_plane);
  const SourceKernel& kernel = out.kernel;
  out.seconds_source = seconds_since(start);
  start = Clock::now();
  // A closed solid's surface clipped to depths before `depth`, unculled: the crossings whose
  // parity gives its section there (blocker_coverage).
  ProjectedBlockers before;
  if (leaf.solid_faces)  // slabs and sections of convex solids
    before = project_faces(*leaf.solid_faces, fr.frame, fr.near, leaf.slab_lo, ShadowCaster{});
  // Which polygons of the root layer are this cluster's, for its share of the layer's hard
  // shadow (nearest_layer_coverage).
  std::vector<std::uint8_t> mine;
  if (!leaf.section) {
    mine.assign(leaf.layer->polygons.size(), 0);
    std::vector<std::pair<const Mesh*, int>> own;
    for (const FaceRef& f : leaf.faces) own.emplace_back(f.mesh, f.face);
    std::sort(own.begin(), own.end());
    const Triple* root = &leaf;
    while (root->parent >= 0) root = &plan.triples[std::size_t(root->parent)];
    for (std::size_t i = 0; i < mine.size(); ++i) {
      const FaceRef& f = root->faces[std::size_t(leaf.layer->polygons[i].source)];
      mine[i] = std::binary_search(own.begin(), own.end(), std::make_pair(f.mesh, f.face));
    }
  }
  // Everything that can put coverage into the images: the cluster's polygons in the layer that
  // meet its slab, its own projected faces, and the solid's crossings.
  std::vector<std::pair<Vec2, Vec2>> boxes;
  if (windows) {
    for (std::size_t i = 0; i < mine.size(); ++i) {
      const auto& pg = leaf.layer->polygons[i];
      if (mine[i] && pg.depth_lo <= leaf.slab_hi && pg.depth_hi >= leaf.slab_lo)
        boxes.emplace_back(pg.lo, pg.hi);
    }
    for (const auto& pg : leaf.blockers.polygons) boxes.emplace_back(pg.lo, pg.hi);
    for (const auto& pg : before.polygons) boxes.emplace_back(pg.lo, pg.hi);
  }
  out.windows = leaf_windows(leaf, kernel, boxes, fft);
  out.seconds_blocker += seconds_since(start);

  const int channels = kernel.grey ? 1 : 3;
  weighted = weighted && !kernel.moments[0].empty();
  // A kernel wider than the window's transform (a light close to the blockers' depth, seen
  // through a small window) must still fit in it: its pixels wrap around the transform.
  for (LeafWindow& win : out.windows) {
    win.tw = std::max(win.tw, fft.transform_size(kernel.width));
    win.th = std::max(win.th, fft.transform_size(kernel.height));
  }
  for (LeafWindow& win : out.windows) {
    start = Clock::now();
    std::vector<float> coverage, full;
    if (leaf.section) {
      coverage = blocker_coverage(ProjectedBlockers{}, win.grid, &before);
    } else {
      // This cluster's share of the root layer's hard shadow.
      coverage = nearest_layer_coverage(*leaf.layer, mine, leaf.slab_lo, leaf.slab_hi, win.grid);
      if (combine == BlockerCombine::sum) {
        // A slab of a convex closed solid is capped by its section at its near side, so that
        // its whole image is the solid slab's projection rather than the ring of its faces.
        full = blocker_coverage(leaf.blockers, win.grid, leaf.solid_faces ? &before : nullptr);
        // Nothing of the cluster hidden behind others: its full image is its share.
        bool hidden = false;
        for (std::size_t i = 0; i < full.size() && !hidden; ++i)
          hidden = full[i] > coverage[i] + 1e-6f;
        if (!hidden) full.clear();
      }
    }
    out.seconds_blocker += seconds_since(start);
    start = Clock::now();
    // Every kernel of the leaf (colour channels, then the two moments) against each image,
    // which is transformed once for all of them.
    std::vector<std::shared_ptr<const KernelSpectrum>> spectra;
    std::vector<const KernelSpectrum*> kernels;
    std::vector<std::vector<float>*> to_share, to_full;
    auto add = [&](const std::vector<float>& values, std::vector<float>& share,
                   std::vector<float>& whole) {
      spectra.push_back(fft.kernel_spectrum(values, kernel.width, kernel.height, win.tw, win.th));
      kernels.push_back(spectra.back().get());
      to_share.push_back(&share);
      to_full.push_back(&whole);
    };
    for (int c = 0; c < channels; ++c)
      add(kernel.channels[c], win.occluded[c], win.occluded_full[c]);
    if (weighted)
      for (int m = 0; m < 2; ++m) add(kernel.moments[m], win.moment[m], win.moment_full[m]);
    const int w = win.grid.width, h = win.grid.height;
    fft.convolve(coverage, w, h, kernels, to_share);
    if (!full.empty()) fft.convolve(full, w, h, kernels, to_full);
    out.seconds_fft += seconds_since(start);
    out.convolutions += (channels + (weighted ? 2 : 0)) * (full.empty() ? 1 : 2);
  }
  return out;
}

// Adds a convolved leaf's weighted occlusion into `occlusion` (per frame texel), and its whole
// image's occlusion into `largest` (the max rule of `sum`; see the file's header).
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

// A traced leaf's footprint texels: their value is not the convolution's to give (+infinity).
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

}  // namespace

double convolution_images_bytes(const ConvolutionPlan& plan) {
  // The batches of bake_convolution: leaves together up to kBatchPixels, a larger one alone.
  double largest_leaf = 0, all = 0;
  for (const Triple& tr : plan.triples) {
    if (!tr.children.empty() || tr.empty || tr.traced) continue;
    const double pixels = double(tr.fft_width) * double(tr.fft_height);
    largest_leaf = std::max(largest_leaf, pixels);
    all += pixels;
  }
  return std::max(largest_leaf, std::min(all, double(kBatchPixels))) * kBytesPerTransformPixel;
}

Expected<ConvolutionVisibility> bake_convolution(const TexelSpace& space,
                                                 const ConvolutionInputs& in,
                                                 std::vector<PairReport>* reports,
                                                 ConvolutionPlan* plan_out) {
  const auto& lights = *in.plan.lights;
  const std::size_t n = space.texels.size();
  auto start = Clock::now();
  ConvolutionPlan plan = plan_convolution(space, in.plan);
  const double plan_seconds = seconds_since(start);
  if (const double needed = convolution_images_bytes(plan); needed > in.memory_for_images) {
    int widest = 0, tallest = 0;
    for (const Triple& tr : plan.triples) {
      if (!tr.children.empty() || tr.empty) continue;
      if (double(tr.fft_width) * tr.fft_height > double(widest) * tallest) {
        widest = tr.fft_width;
        tallest = tr.fft_height;
      }
    }
    return scene_error(fmt::format(
        "receiver '{}': the convolution's images need about {} (its largest transform is "
        "{}x{}), more than the {} max_memory leaves them; lower 'max_image' or raise "
        "'error_texels' or max_memory",
        in.plan.receiver->name, format_bytes(needed), widest, tallest,
        format_bytes(in.memory_for_images)));
  }

  // Per light part and texel: V, and whether one of the part's frames reaches the texel.
  std::vector<std::vector<Vec3f>> part_visible(plan.light_parts.size());
  std::vector<std::vector<std::uint8_t>> part_reached(plan.light_parts.size());
  std::vector<std::vector<float>> part_error(plan.light_parts.size());
  for (std::size_t f = 0; f < plan.frames.size(); ++f) {
    PlanFrame& fr = plan.frames[f];
    const LightPart& lp = plan.light_parts[fr.light_part];
    PairReport report;
    report.light = lp.name;
    report.receiver = in.plan.receiver->name;
    report.part = fr.face;
    for (int k = 0; k < 3; ++k) report.axis[k] = fr.frame.axis[k];
    report.lit_texels = std::int64_t(fr.texels.size());
    report.outside_texels = fr.outside_texels;
    report.seconds_configure = f == 0 ? plan_seconds : 0;
    std::vector<Vec3f> occlusion(fr.texels.size(), Vec3f::Zero());
    std::vector<Vec3f> largest(fr.texels.size(), Vec3f::Zero());
    // Negative until a leaf shades the texel: see ConvolutionVisibility::error_texels.
    std::vector<float> error(fr.texels.size(), -1.0f);
    EulerCounts euler(in.combine == BlockerCombine::sum ? fr.texels.size() : 0);
    const std::vector<Vec2> gradient =
        in.weighted ? weight_gradients(fr, space, lp.part) : std::vector<Vec2>{};
    std::vector<std::size_t> leaves;
    for (std::size_t t = 0; t < plan.triples.size(); ++t) {
      const Triple& tr = plan.triples[t];
      // Sections count only in the sum's Euler counts.
      if (tr.section && in.combine != BlockerCombine::sum) continue;
      if (tr.frame != int(f) || !tr.children.empty() || tr.empty) continue;
      if (tr.traced) {
        mark_traced(plan, tr, error);
      } else {
        leaves.push_back(t);
      }
    }
    // Each convex solid's leaves together, so that one count at a time is held.
    std::stable_sort(leaves.begin(), leaves.end(), [&](std::size_t a, std::size_t b) {
      return plan.triples[a].euler < plan.triples[b].euler;
    });
    // Leaves are convolved in parallel, a batch at a time (their images held until added), with
    // one FFTW thread each: on 2 cores two threads slow a transform below ~400² down
    // (tests/bench/fft_bench.cpp). A larger leaf is convolved alone, with FFTW's threads.
    // Adding into the texels stays in leaf order, so the result does not depend on scheduling.
    DepthRange blockers, receivers;
    for (std::size_t first = 0; first < leaves.size();) {
      std::size_t last = first;
      std::size_t pixels = 0;
      while (last < leaves.size()) {
        const Triple& tr = plan.triples[leaves[last]];
        const std::size_t area = std::size_t(tr.fft_width) * std::size_t(tr.fft_height);
        if (last > first &&
            (in.fft->threaded(tr.fft_width, tr.fft_height) || pixels + area > kBatchPixels))
          break;
        pixels += area;
        ++last;
        if (in.fft->threaded(tr.fft_width, tr.fft_height)) break;
      }
      std::vector<LeafImages> images(last - first);
      std::vector<double> seconds(last - first, 0.0);
      tbb::parallel_for(std::size_t(first), last, [&](std::size_t b) {
        const auto leaf_start = Clock::now();
        images[b - first] = convolve_leaf(plan, plan.triples[leaves[b]], in.combine, in.weighted,
                                          in.island_windows, *in.fft);
        seconds[b - first] = seconds_since(leaf_start);
      });
      for (std::size_t b = first; b < last; ++b) {
        Triple& tr = plan.triples[leaves[b]];
        const auto leaf_start = Clock::now();
        const bool counted = tr.euler >= 0 && in.combine == BlockerCombine::sum;
        if (counted) euler.begin(tr.euler);
        accumulate_leaf(plan, tr, images[b - first], in.combine, gradient, occlusion, largest,
                        error, counted ? &euler : nullptr, report);
        images[b - first] = LeafImages{};
        tr.seconds = seconds[b - first] + seconds_since(leaf_start);
        ++report.triples;
        blockers.extend(tr.blocker_depths.lo);
        blockers.extend(tr.blocker_depths.hi);
        receivers.extend(tr.receiver_depths.lo);
        receivers.extend(tr.receiver_depths.hi);
        if (tr.config.penumbra_error + tr.view_error >= report.penumbra_error) {
          report.penumbra_error = tr.config.penumbra_error + tr.view_error;
          report.penumbra_error_texels = tr.penumbra_error_texels;
          report.rho_lo = tr.config.rho_lo;
          report.rho_hi = tr.config.rho_hi;
          report.rho = tr.config.rho;
          report.blocker_plane = tr.config.blocker_plane;
          report.receiver_plane = tr.config.receiver_plane;
          report.light_extent = tr.config.light_extent;
          report.pixel = tr.grid.pixel;
        }
      }
      first = last;
    }
    euler.begin(-1);  // folds the last solid's count
    if (!blockers.empty()) {
      report.blocker_depth_lo = blockers.lo;
      report.blocker_depth_hi = blockers.hi;
      report.receiver_depth_lo = receivers.lo;
      report.receiver_depth_hi = receivers.hi;
    }
    auto& vis = part_visible[std::size_t(fr.light_part)];
    auto& hit = part_reached[std::size_t(fr.light_part)];
    auto& err = part_error[std::size_t(fr.light_part)];
    if (vis.empty()) {
      vis.assign(n, Vec3f::Zero());
      hit.assign(n, 0);
      err.assign(n, 0.0f);
    }
    // Without a shaft test a texel no leaf reached is simply lit (0); with one, it lies in a
    // shaft a blocker may cross, and the plan did not account for it (negative).
    for (std::size_t i = 0; i < fr.texels.size(); ++i)
      err[fr.texels[i]] = in.plan.maybe_blocked ? error[i] : std::max(error[i], 0.0f);
    for (std::size_t i = 0; i < fr.texels.size(); ++i) {
      Vec3f v;
      for (int c = 0; c < 3; ++c) {
        float o = std::max(occlusion[i][c], largest[i][c]);
        if (!euler.largest.empty()) o = std::max(o, euler.largest[i][c]);
        v[c] = in.combine == BlockerCombine::sum ? std::clamp(1.0f - o, 0.0f, 1.0f)
                                                 : std::exp(-occlusion[i][c]);
      }
      vis[fr.texels[i]] = v;
      hit[fr.texels[i]] = 1;
    }
    if (reports) reports->push_back(std::move(report));
  }

  // Per light, its parts' V averaged at each texel by the parts' weights: with the irradiance
  // weighting, each part's own unoccluded irradiance there (V is irradiance-weighted, and the
  // part nearer the texel brings more of it); without, its share of the power (V_u weights the
  // light by area). Where every part that reaches a texel sees the same V (fully lit or fully
  // hidden, most texels), that is the average whatever the weights, and no closed form is
  // evaluated.
  std::vector<std::vector<Vec3f>> visible(lights.size());
  std::vector<std::vector<std::uint8_t>> reached(lights.size());
  std::vector<std::vector<float>> error(lights.size());
  for (std::size_t l = 0; l < lights.size(); ++l) {
    std::vector<int> parts;
    for (std::size_t p = 0; p < plan.light_parts.size(); ++p)
      if (plan.light_parts[p].light == int(l) && !part_visible[p].empty()) parts.push_back(int(p));
    const std::vector<std::uint8_t>* maybe = in.plan.maybe_blocked ? &(*in.plan.maybe_blocked)[l] : nullptr;
    if (parts.empty() && !maybe) continue;
    visible[l].assign(n, Vec3f::Zero());
    reached[l].assign(n, 0);
    error[l].assign(n, 0.0f);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const auto& r) {
      for (std::size_t t = r.begin(); t != r.end(); ++t) {
        if (maybe && !(*maybe)[t]) {
          // Nothing lies between the texel and the light (ShaftCuller): all of it is seen.
          const Texel& tx = space.texels[t];
          if (lights[l].reaches(tx.position.cast<double>(), tx.normal.cast<double>())) {
            visible[l][t] = Vec3f::Ones();
            reached[l][t] = 1;
          }
          continue;
        }
        const Vec3f* first = nullptr;
        bool same = true;
        for (int p : parts) {
          if (!part_reached[std::size_t(p)][t]) continue;
          const Vec3f& v = part_visible[std::size_t(p)][t];
          if (!first) first = &v;
          same = same && (v - *first).cwiseAbs().maxCoeff() <= 1e-6f;
          const float e = part_error[std::size_t(p)][t];
          error[l][t] =
              (e < 0 || error[l][t] < 0) ? std::min(e, error[l][t]) : std::max(e, error[l][t]);
        }
        if (!first) continue;
        reached[l][t] = 1;
        if (same) {
          visible[l][t] = *first;
          continue;
        }
        const Texel& tx = space.texels[t];
        Vec3 sum = Vec3::Zero();
        double weight = 0;
        for (int p : parts) {
          if (!part_reached[std::size_t(p)][t]) continue;
          const LightPart& lp = plan.light_parts[std::size_t(p)];
          // Plus a trace of the power share, so that a texel no part's closed form reaches
          // still averages its parts by power rather than dropping the light.
          const double w = in.weighted ? lp.part.unoccluded_irradiance(tx.position.cast<double>(),
                                                                       tx.normal.cast<double>())
                                                 .sum() +
                                             1e-9 * lp.fraction
                                       : lp.fraction;
          sum += w * part_visible[std::size_t(p)][t].cast<double>();
          weight += w;
        }
        visible[l][t] = (sum / weight).cast<float>();
      }
    });
  }

  // A texel inside a convex closed blocker (a floor under a box) sees no light: exactly, rather
  // than through the slabs' approximate count (buried_texels.h).
  const std::vector<std::uint8_t> buried =
      in.plan.clusters ? buried_texels(space, *in.plan.receiver, in.plan.blockers, *in.plan.clusters,
                                  kBuriedTolerance * plan.texel)
                  : std::vector<std::uint8_t>(n, 0);

  ConvolutionVisibility out;
  out.visible = std::move(visible);
  out.reached = std::move(reached);
  out.error_texels = std::move(error);
  out.buried = buried;
  if (plan_out) *plan_out = std::move(plan);
  return out;
}

}  // namespace sb
