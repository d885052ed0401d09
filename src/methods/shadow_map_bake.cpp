// The shadow-map filtering baselines (docs/design.md §7), in lightmap texel space: each lit texel
// looks itself up in a shadow map rendered from the light's centre (shadow_map.cpp) and filters
// depth comparisons around that point.
//
//   pcf           Reeves, Salesin & Cook, "Rendering antialiased shadows with depth maps",
//                 SIGGRAPH 1987 (docs/design.md [S2], "Percentage closer
//                 filtering"): the fraction of comparisons that pass over a fixed footprint of
//                 radius pcf_radius shadow-map pixels.
//   pcss          Fernando, "Percentage-closer soft shadows", SIGGRAPH 2005 sketch (summarised in
//                 docs/design.md [S4] §2–3): a blocker search, the average
//                 blocker depth d_b, the parallel-planes penumbra w = L·(d_r − d_b)/d_b, PCF over
//                 a footprint of that size.
//   adaptive-pcf  Uralsky, GPU Gems 2 ch. 17 (docs/design.md [S3]): jittered
//                 stratified samples warped to a disk, 8 estimation samples on its rim first, the
//                 full set only where they disagree.
//   chun-oh       Chun & Oh, IEICE Trans. Inf. & Syst. E100-D(3), 2017
//                 (docs/design.md [S5]): the PCSS filter area split
//                 quad-tree-wise while the shadow tests' variance E(v) − E(v)² exceeds a threshold
//                 or the light's image varies, each sub-region lit by its own part of the light.
//
// The footprint geometry is the parallel-planes one of docs/design.md §2, read in the shadow map's
// tangent coordinates: the ray from a light point s (metres across the axis from the centre) to
// a receiver point at depth d_r crosses depth d at tangent t_r + s·(1/d − 1/d_r). So a blocker
// plane at d_b hides light point s exactly where the map's tap at t_r + k·s is blocked,
// k = 1/d_b − 1/d_r, and L·(d_r − d_b)/d_b on the receiver is L·k in the map. The PCSS-style
// footprints below are the light's outline seen along the axis (its bounding box across e1, e2,
// with taps outside the light's shape left out), scaled by k.
//
// Like the convolution, every method gives the emission-weighted unoccluded fraction V_u, not
// the reference's irradiance-weighted V (docs/design.md §1). Lights combine through LightMix.
#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "core/sampling.h"
#include "methods/shadow_map.h"

namespace sb {

namespace {

enum class Filter { pcf, pcss, adaptive, chun_oh };

// Each frustum is widened by this fraction of its receiver points' extent, so that the filter
// footprints of the outermost points (and of points beside a cube face's seam) stay in the map;
// taps that leave it read "no blocker". A quarter covers the showcase's penumbrae; a blocker far
// outside the receiver's cone with a penumbra wider than that is missed (a documented limit).
constexpr double kFrustumMargin = 0.25;
// PCF: taps one pixel apart over the footprint, at most 33 × 33.
constexpr int kMaxPcfTapsPerSide = 33;
// PCSS blocker search: 9 × 9 point taps (Fernando used 16–64; Klein et al. show 8 missing thin
// blockers), the point's own pixel among them, warped towards it (search_blockers says why).
constexpr int kSearchTapsPerSide = 9;
// PCSS filter: taps about one pixel apart, at most 16 × 16 (256, more than the 32–64 of the
// real-time papers: an offline baker can afford less banding). A fixed grid, as Fernando's fixed
// Poisson disk: banding rather than noise where the footprint is wide.
constexpr int kMaxPcssTapsPerSide = 16;
// Adaptive PCF: 8 estimation samples on the rim and a full set of at most 64 (Uralsky's counts).
constexpr int kEstimationSamples = 8;
constexpr int kMaxAdaptiveSamples = 64;
// Chun–Oh: a region is split while E(v) − E(v)² exceeds this (0.11 < E < 0.89), or while it is
// partly lit and the light's image varies over its part of the light; down to 4 × 4 regions.
// Each region takes its own grid of up to 8 × 8 taps (Uralsky's 64), so a split region is tested
// at twice the density, as the paper's "visibility tests for more positions". Their threshold,
// 0.2244 (0.35 < E < 0.65), left the outer penumbra on the 8 × 8 grid's steps: on
// scenes/parallel at 256², RMSE against the exact V_u 0.0143 with it, 0.0067 with 0.1, for
// 2.2× the taps (48 → 154 per lit texel).
constexpr double kVarianceThreshold = 0.1;
constexpr int kChunOhLevels = 3;  // 1, 2 × 2, 4 × 4 regions
constexpr int kMaxRegionTapsPerSide = 8;
// Samples per side of the light's image (over its bounding box across the axis) for region
// colours, the shape's area and whether the image varies in a region.
constexpr int kImageSamplesPerSide = 32;

// Normalised light coordinates: u ∈ [−1, 1]² is the light point s = (u.x·half.x, u.y·half.y)
// metres along (e1, e2) from its centre; the tap for it lies at at + k·s / pixel.
Vec2 cell_centre(int i, int j, int n, const Vec2& lo, double width) {
  return lo + Vec2((i + 0.5) * width / n, (j + 0.5) * width / n);
}

// The light as the filters of one frustum see it: its outline and image across the axis.
struct LightOutline {
  Vec2 half = Vec2::Zero();  // half extents along e1, e2, metres
  double disk_radius = 0;    // radius of the disk with the outline's area, metres
  // pcss_mask[n][j·n + i]: 1 where the n × n grid's tap (i, j) falls on the light
  std::array<std::vector<float>, kMaxPcssTapsPerSide + 1> pcss_mask;
  // Chun–Oh regions, level by level (1 + 4 + 16): the light's emission over the region (per
  // channel, summed image samples), whether the image varies there, and per tap count m the
  // emitting taps of its m × m grid.
  struct Region {
    Vec3 emission = Vec3::Zero();
    bool varies = false;
    std::array<std::vector<float>, kMaxRegionTapsPerSide + 1> mask;
  };
  std::vector<Region> regions;
};

int region_index(int level, int ix, int iy) {
  static constexpr int kFirst[kChunOhLevels] = {0, 1, 5};
  return kFirst[level] + iy * (1 << level) + ix;
}

LightOutline outline_of(const Light& light, const ProjectionFrame& frame, bool regions) {
  LightOutline o;
  o.half = light.half_extents(frame.e1, frame.e2);
  auto emission = [&](const Vec2& u) {
    return light.source_image(u.x() * o.half.x() * frame.e1 + u.y() * o.half.y() * frame.e2,
                              frame.axis);
  };
  auto emits = [&](const Vec2& u) { return emission(u).maxCoeff() > 0 ? 1.0f : 0.0f; };
  for (int n = 1; n <= kMaxPcssTapsPerSide; ++n) {
    o.pcss_mask[n].resize(n * n);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        o.pcss_mask[n][j * n + i] = emits(cell_centre(i, j, n, Vec2(-1, -1), 2.0));
  }
  constexpr int g = kImageSamplesPerSide;
  std::vector<Vec3> image(g * g);
  int emitting = 0;
  Vec3 brightest = Vec3::Zero();
  for (int j = 0; j < g; ++j)
    for (int i = 0; i < g; ++i) {
      image[j * g + i] = emission(cell_centre(i, j, g, Vec2(-1, -1), 2.0));
      emitting += image[j * g + i].maxCoeff() > 0;
      brightest = brightest.cwiseMax(image[j * g + i]);
    }
  const double area = 4 * o.half.x() * o.half.y() * emitting / double(g * g);
  o.disk_radius = std::sqrt(area / std::numbers::pi);
  if (!regions) return o;
  o.regions.resize(region_index(kChunOhLevels - 1, 0, 0) + (1 << 2 * (kChunOhLevels - 1)));
  for (int level = 0; level < kChunOhLevels; ++level) {
    const int side = 1 << level, cells = g / side;
    const double width = 2.0 / side;
    for (int iy = 0; iy < side; ++iy)
      for (int ix = 0; ix < side; ++ix) {
        LightOutline::Region& r = o.regions[region_index(level, ix, iy)];
        Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
        for (int j = iy * cells; j < (iy + 1) * cells; ++j)
          for (int i = ix * cells; i < (ix + 1) * cells; ++i) {
            r.emission += image[j * g + i];
            lo = lo.cwiseMin(image[j * g + i]);
            hi = hi.cwiseMax(image[j * g + i]);
          }
        // Varies: by more than 1% of the light's brightest value in some channel (an edge of
        // the light's shape inside the region counts).
        r.varies = ((hi - lo).array() > 0.01 * brightest.array()).any();
        const Vec2 region_lo(-1 + ix * width, -1 + iy * width);
        for (int m = 1; m <= kMaxRegionTapsPerSide; ++m) {
          r.mask[m].resize(m * m);
          for (int j = 0; j < m; ++j)
            for (int i = 0; i < m; ++i)
              r.mask[m][j * m + i] = emits(cell_centre(i, j, m, region_lo, width));
        }
      }
  }
  return o;
}

// Fernando's blocker search, over the region where a blocker at the map's nearest depth could
// hide part of the light from the receiver point (t_r ± half·(1/nearest − 1/d_r)); a blocker
// found at depth d counts only when it lies inside the pyramid from the point to the light,
// |offset| ≤ half·(1/d − 1/d_r), which keeps the far corners of a wide search (sized for the
// nearest blocker in the whole map) from picking up blockers that cannot shadow the point.
// That pyramid narrows to the point itself, so a blocker standing on the receiver fills only
// the middle of the search region near its base, and the nearer the map's nearest blocker (the
// receiver itself, where it blocks and comes close to the light), the smaller that middle. The
// 9 × 9 grid is warped, u = g·|g| for g on a regular grid from −1 to 1: its middle tap is the
// point's own pixel (a blocker there lies in the pyramid), the next ones 1/16 of the way out,
// the outermost on the edge. A regular grid lost the contact shadows of the showcase's box and
// torus, and of a thin wall standing on a blocking floor.
// Returns k = 1/d_b − 1/d_r for the mean blocker depth d_b, or a negative value when nothing
// was found.
double search_blockers(const ShadowMap& map, const ReceiverPoint& r, const LightOutline& light) {
  const double nearest = std::max(map.nearest, map.near);
  if (!(nearest < r.depth - r.bias)) return -1;
  const double k_search = 1 / nearest - 1 / r.depth;
  const Vec2 reach = light.half * (k_search / map.pixel);  // pixels per unit of u
  constexpr int n = kSearchTapsPerSide;
  double depth_sum = 0;
  int found = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const Vec2 g(-1 + 2.0 * i / (n - 1), -1 + 2.0 * j / (n - 1));  // corners included
      const Vec2 u = g.cwiseProduct(g.cwiseAbs());                   // denser towards the point
      const Vec2 at = r.at + u.cwiseProduct(reach);
      if (!(at.x() > -1 && at.y() > -1 && at.x() < map.size && at.y() < map.size)) continue;
      double depth;
      if (!blocked(map, r, int(std::floor(at.x() + 0.5)), int(std::floor(at.y() + 0.5)), &depth))
        continue;
      if (u.cwiseAbs().maxCoeff() * k_search > 1 / depth - 1 / r.depth) continue;
      depth_sum += depth;
      ++found;
    }
  if (found == 0) return -1;
  return std::max(0.0, 1 / (depth_sum / found) - 1 / r.depth);
}

struct Counters {
  std::int64_t lit = 0;          // (texel, light) pairs filtered
  std::int64_t blockers = 0;     // of which the blocker search found blockers
  std::int64_t taps = 0;         // bilinear filter taps (four depth tests each), search excluded
  std::int64_t full = 0;         // adaptive: took the full set
  std::int64_t estimated = 0;    // adaptive: settled by the estimation samples
  std::int64_t regions = 0;      // chun-oh: leaf regions used
  std::int64_t split = 0;        // chun-oh: split at least once
  std::int64_t split_twice = 0;  // chun-oh: down to 4 × 4 somewhere
  Counters& operator+=(const Counters& o) {
    lit += o.lit, blockers += o.blockers, taps += o.taps, full += o.full;
    estimated += o.estimated, regions += o.regions, split += o.split;
    split_twice += o.split_twice;
    return *this;
  }
};

// Reeves's PCF over the square of half-width `radius` pixels: taps one pixel apart (at most
// 33 × 33, further apart beyond a radius of 16), each the bilinear four-comparison lookup.
double pcf(const ShadowMap& map, const ReceiverPoint& r, double radius, Counters& c) {
  const int n = radius > 0 ? std::min(2 * int(std::ceil(radius)) + 1, kMaxPcfTapsPerSide) : 1;
  const double step = n > 1 ? 2 * radius / (n - 1) : 0;
  double sum = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      sum += lit_fraction(map, r, r.at + Vec2(-radius + i * step, -radius + j * step));
  c.taps += n * n;
  return sum / (n * n);
}

// Which light points lie above the receiver's horizon (the plane of its shading normal):
// the reference weights the others 0 in H and H0 alike, so V = H/H0 leaves them out, and so do
// the footprints below. Without it the receiver's own body, met by the taps of light points
// below its horizon, greyed a band beyond a curved object's terminator.
struct Horizon {
  double height = 0;          // n · (light centre − point)
  Vec2 slope = Vec2::Zero();  // (n · e1, n · e2)
  bool above(const Vec2& light_point) const { return height + slope.dot(light_point) > 0; }
};

double pcss(const ShadowMap& map, const ReceiverPoint& r, const Horizon& horizon,
            const LightOutline& light, double k, Counters& c) {
  const Vec2 reach = light.half * (k / map.pixel);  // pixels per unit of u
  const int n = std::clamp(int(std::ceil(2 * reach.maxCoeff())) + 1, 1, kMaxPcssTapsPerSide);
  const std::vector<float>& mask = light.pcss_mask[n];
  double sum = 0, weight = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const Vec2 u = cell_centre(i, j, n, Vec2(-1, -1), 2.0);
      if (mask[j * n + i] == 0 || !horizon.above(u.cwiseProduct(light.half))) continue;
      sum += lit_fraction(map, r, r.at + u.cwiseProduct(reach));
      weight += 1;
      ++c.taps;
    }
  return weight > 0 ? sum / weight : lit_fraction(map, r, r.at);
}

// Shirley & Chiu's concentric map from [0, 1)² to the unit disk: the square's border cells go
// to the disk's outer ring, and strata keep compact shapes.
Vec2 concentric_disk(const Vec2& p) {
  const double a = 2 * p.x() - 1, b = 2 * p.y() - 1;
  if (a == 0 && b == 0) return Vec2::Zero();
  double r, phi;
  if (std::abs(a) > std::abs(b)) {
    r = a, phi = (std::numbers::pi / 4) * (b / a);
  } else {
    r = b, phi = std::numbers::pi / 2 - (std::numbers::pi / 4) * (a / b);
  }
  return r * Vec2(std::cos(phi), std::sin(phi));
}

// The cells of an n × n grid on its border, `count` of them evenly spaced around it (as indices
// j·n + i): under the concentric map they are the disk's rim.
std::vector<int> rim_cells(int n, int count) {
  std::vector<int> border;
  for (int i = 0; i < n; ++i) border.push_back(i);                     // bottom row
  for (int j = 1; j < n; ++j) border.push_back(j * n + n - 1);         // right column
  for (int i = n - 2; i >= 0; --i) border.push_back((n - 1) * n + i);  // top row
  for (int j = n - 2; j >= 1; --j) border.push_back(j * n);            // left column
  std::vector<int> picked;
  for (int e = 0; e < count; ++e) picked.push_back(border[e * border.size() / count]);
  return picked;
}

// Uralsky's adaptive PCF. The footprint is PCSS's estimate (the disk with the area of the
// light's outline, scaled by k), not the fixed pcf_radius: with a fixed footprint the method
// would be PCF with noise, its penumbrae unrelated to the light; with the estimate it is a
// soft-shadow method whose error against the reference means something, and the estimation
// samples still skip the filter wherever the disk is wholly lit or wholly shadowed. The samples:
// an n × n jittered grid (n = ⌊√min(samples, 64)⌋, at least 3; 8 × 8 by default) through the
// concentric map, each a bilinear lookup; the estimation samples are 8 of its border cells,
// evenly spaced around the rim, and count in the full set's mean as in Uralsky's listing 17-2.
double adaptive_pcf(const ShadowMap& map, const ReceiverPoint& r, const Horizon& horizon,
                    double radius, double radius_px, int n, const std::vector<int>& rim, Rng& rng,
                    bool always_full, Counters& c) {
  // The jittered grid is drawn whole, in a fixed order, so the full set is the same samples
  // whether or not the estimate settles the texel. Samples of light points below the horizon
  // are left out (lit < 0 marks them).
  std::array<Vec2, kMaxAdaptiveSamples> disk;
  std::array<double, kMaxAdaptiveSamples> lit;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double x = (i + rng.next_double()) / n, y = (j + rng.next_double()) / n;
      disk[j * n + i] = concentric_disk(Vec2(x, y));
      lit[j * n + i] = horizon.above(radius * disk[j * n + i]) ? 2.0 : -1.0;  // 2: not yet read
    }
  bool all_lit = true, all_shadowed = true, any = false;
  for (int s : rim) {
    if (lit[s] < 0) continue;
    lit[s] = lit_fraction(map, r, r.at + radius_px * disk[s]);
    all_lit = all_lit && lit[s] == 1.0;
    all_shadowed = all_shadowed && lit[s] == 0.0;
    any = true;
    ++c.taps;
  }
  if (any && (all_lit || all_shadowed) && !always_full) {
    ++c.estimated;
    return all_lit ? 1.0 : 0.0;
  }
  ++c.full;
  double sum = 0;
  int count = 0;
  for (int s = 0; s < n * n; ++s) {
    if (lit[s] < 0) continue;
    if (lit[s] > 1) {
      lit[s] = lit_fraction(map, r, r.at + radius_px * disk[s]);
      ++c.taps;
    }
    sum += lit[s];
    ++count;
  }
  return count > 0 ? sum / count : lit_fraction(map, r, r.at);
}

// One Chun–Oh region: the mean lit fraction over its taps on the light and above the horizon,
// and the share of its taps above the horizon (which scales its emission).
struct RegionResult {
  double visibility = 1, above = 1;
};

RegionResult region_visibility(const ShadowMap& map, const ReceiverPoint& r, const Horizon& horizon,
                               const Vec2& half, const Vec2& reach,
                               const LightOutline::Region& region, int level, int ix, int iy,
                               Counters& c) {
  const double width = 2.0 / (1 << level);
  const int m = std::clamp(int(std::ceil(width * reach.maxCoeff())) + 1, 1, kMaxRegionTapsPerSide);
  const Vec2 lo(-1 + ix * width, -1 + iy * width);
  const std::vector<float>& mask = region.mask[m];
  double sum = 0, weight = 0, all = 0;
  int above = 0;
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      const Vec2 u = cell_centre(i, j, m, lo, width);
      if (!horizon.above(u.cwiseProduct(half))) continue;
      const double lit = lit_fraction(map, r, r.at + u.cwiseProduct(reach));
      sum += mask[j * m + i] * lit;
      weight += mask[j * m + i];
      all += lit;
      ++above;
      ++c.taps;
    }
  RegionResult result;
  result.above = double(above) / (m * m);
  // A sliver of the light between the taps: every tap speaks for it.
  if (above > 0) result.visibility = weight > 0 ? sum / weight : all / above;
  return result;
}

Vec3 chun_oh(const ShadowMap& map, const ReceiverPoint& r, const Horizon& horizon,
             const LightOutline& light, double k, Counters& c) {
  const Vec2 reach = light.half * (k / map.pixel);
  Vec3 lit = Vec3::Zero(), emitted = Vec3::Zero();
  struct Node {
    int level, ix, iy;
  };
  std::array<Node, 1 + 4 + 16> stack;
  int top = 0, deepest = 0;
  stack[top++] = {0, 0, 0};
  while (top > 0) {
    const Node node = stack[--top];
    const LightOutline::Region& region = light.regions[region_index(node.level, node.ix, node.iy)];
    if (region.emission.maxCoeff() <= 0) continue;  // no light behind this part of the filter
    const RegionResult result = region_visibility(map, r, horizon, light.half, reach, region,
                                                  node.level, node.ix, node.iy, c);
    if (result.above == 0) continue;  // wholly below the horizon
    const double e = result.visibility;
    const bool partly = e > 0 && e < 1;
    if (node.level + 1 < kChunOhLevels &&
        (e - e * e > kVarianceThreshold || (partly && region.varies))) {
      for (int q = 0; q < 4; ++q)
        stack[top++] = {node.level + 1, 2 * node.ix + (q & 1), 2 * node.iy + (q >> 1)};
      deepest = std::max(deepest, node.level + 1);
      continue;
    }
    lit += e * result.above * region.emission;
    emitted += result.above * region.emission;
    ++c.regions;
  }
  c.split += deepest >= 1;
  c.split_twice += deepest >= 2;
  if (emitted.maxCoeff() <= 0) return Vec3::Constant(lit_fraction(map, r, r.at));
  Vec3 v = Vec3::Ones();
  for (int ch = 0; ch < 3; ++ch)
    if (emitted[ch] > 0) v[ch] = std::clamp(lit[ch] / emitted[ch], 0.0, 1.0);
  return v;
}

}  // namespace

MixedImages bake_shadow_map_filter(const TexelSpace& space, const BaselineInputs& in,
                                   MethodStats* stats, const ShadowFilterOptions& options) {
  const BaselineSettings& settings = in.settings;
  Filter filter = Filter::pcf;
  if (settings.method == "pcss") {
    filter = Filter::pcss;
  } else if (settings.method == "adaptive-pcf") {
    filter = Filter::adaptive;
  } else if (settings.method == "chun-oh") {
    filter = Filter::chun_oh;
  } else if (settings.method != "pcf") {
    // The registry makes this method for those four names only.
    throw std::invalid_argument("bake_shadow_map_filter: not a shadow-map filter: " +
                                settings.method);
  }
  const auto& lights = *in.lights;
  LightMix mix(space, lights, settings.quantity, LightMix::Order::light_major, in.keep_per_light);
  const int grid =
      std::max(3, int(std::sqrt(double(std::clamp(settings.samples, 1, kMaxAdaptiveSamples)))));
  const std::vector<int> rim = rim_cells(grid, kEstimationSamples);
  tbb::combinable<Counters> counters;
  int maps = 0;

  const std::size_t n = space.texels.size();
  std::vector<std::uint8_t> reached(n);
  for (std::size_t l = 0; l < lights.size(); ++l) {
    const Light& light = lights[l];
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const auto& range) {
      for (std::size_t t = range.begin(); t != range.end(); ++t)
        reached[t] = light.reaches(space.texels[t].position.cast<double>(),
                                   space.texels[t].normal.cast<double>());
    });
    std::vector<std::size_t> lit;
    std::vector<Vec3> positions;
    for (std::size_t t = 0; t < n; ++t) {
      if (!reached[t]) continue;
      lit.push_back(t);
      positions.push_back(space.shadow_origin(t).cast<double>());
    }
    std::vector<Vec3> visibility(lit.size(), Vec3::Ones());
    for (const ShadowFrustum& frustum : fit_frusta(light.centre(), positions, kFrustumMargin)) {
      const ShadowMap map = render_shadow_map(in.blockers, frustum.frame, frustum.half_extent,
                                              settings.shadow_map, frustum.near);
      ++maps;
      const LightOutline outline = outline_of(light, frustum.frame, filter == Filter::chun_oh);
      tbb::parallel_for(
          tbb::blocked_range<std::size_t>(0, frustum.points.size(), 256), [&](const auto& range) {
            Counters& c = counters.local();
            for (std::size_t i = range.begin(); i != range.end(); ++i) {
              const std::size_t p = frustum.points[i];
              const Texel& texel = space.texels[lit[p]];
              // The point lifted onto the smooth surface and its shading normal, as the
              // reference's rays leave from (texel_space.h): on a coarsely tessellated curved
              // object the facets' own planes would put a facet-by-facet staircase into the
              // terminator; on flat faces both are the triangle's.
              const Vec3 origin = space.shadow_origin(lit[p]).cast<double>();
              const Vec3 normal = texel.normal.cast<double>();
              if (!(frustum.frame.depth(origin) > 0)) continue;
              const ReceiverPoint r = receiver_point(map, origin, normal);
              ++c.lit;
              if (filter == Filter::pcf) {
                visibility[p] = Vec3::Constant(pcf(map, r, settings.pcf_radius, c));
                continue;
              }
              const double k = search_blockers(map, r, outline);
              if (k < 0) continue;  // nothing between the point and the light: V = 1
              ++c.blockers;
              Horizon horizon;
              horizon.height = normal.dot(light.centre() - origin);
              horizon.slope = Vec2(normal.dot(frustum.frame.e1), normal.dot(frustum.frame.e2));
              if (filter == Filter::pcss) {
                visibility[p] = Vec3::Constant(pcss(map, r, horizon, outline, k, c));
              } else if (filter == Filter::adaptive) {
                Rng rng(stream_seed(settings.seed, stream_seed(in.stream, light.stream()),
                                    std::uint64_t(texel.y) * space.width + texel.x));
                visibility[p] = Vec3::Constant(adaptive_pcf(
                    map, r, horizon, outline.disk_radius, outline.disk_radius * k / map.pixel, grid,
                    rim, rng, options.adaptive_always_full, c));
              } else {
                visibility[p] = chun_oh(map, r, horizon, outline, k, c);
              }
            }
          });
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, lit.size(), 4096), [&](const auto& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) mix.set(l, lit[i], visibility[i]);
    });
  }

  if (stats) {
    Counters total;
    counters.combine_each([&](const Counters& c) { total += c; });
    const double pairs = std::max<std::int64_t>(total.lit, 1);
    stats->emplace_back("shadow_maps", maps);
    stats->emplace_back("mean_filter_taps", double(total.taps) / pairs);
    if (filter != Filter::pcf) stats->emplace_back("blocker_fraction", total.blockers / pairs);
    if (filter == Filter::adaptive) {
      stats->emplace_back("full_filter_fraction", total.full / pairs);
      stats->emplace_back("estimate_only_fraction", total.estimated / pairs);
      stats->emplace_back("full_set_samples", grid * grid);
    }
    if (filter == Filter::chun_oh) {
      stats->emplace_back("split_fraction", total.split / pairs);
      stats->emplace_back("split_twice_fraction", total.split_twice / pairs);
      stats->emplace_back("mean_regions", total.regions / std::max(1.0, double(total.blockers)));
    }
  }
  return mix.finish();
}

MixedImages bake_shadow_map_filter(const TexelSpace& space, const BaselineInputs& in,
                                   MethodStats* stats) {
  return bake_shadow_map_filter(space, in, stats, ShadowFilterOptions{});
}

}  // namespace sb
