// One leaf's convolution (Soler & Sillion 1998, docs/design.md [S1];
// docs/design.md §2–4): the source kernel (source_image), the blocker images (blocker_image: the
// cluster's share of the nearest layer, its whole image, a convex solid's section) and their FFT
// convolutions, on the leaf's grid or on a window per island of its blockers (leaf_windows).
#include "methods/convolution/leaf_convolution.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <utility>

#include "core/stopwatch.h"

namespace sb {

namespace {

using Clock = std::chrono::steady_clock;

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

}  // namespace

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

}  // namespace sb
