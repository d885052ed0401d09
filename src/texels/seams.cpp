// Seam stitching (seams.h). Written here rather than taken from a library: the solve is a few
// dozen lines over Eigen's sparse solvers, and what it needs to know (which texels a bilinear
// lookup reads, how the lightmap's rows run, which texels are margin) is this project's own.
//
// The system. Along each seam edge, sample points t have a lookup on side a, Σ w_i x_i over the
// four texels under its UV there, and one on side b; each sample asks a − b = 0. Every texel that
// some lookup reads is an unknown x_t, held near its baked value x0_t by a weight p_t:
//
//     minimise  Σ_samples (a − b)²  +  Σ_t p_t (x_t − x0_t)²,
//
// whose normal equations (AᵀA + P) x = P x0 are symmetric positive definite (p_t > 0) and are
// solved per channel and per image: factored (Eigen's SimplicialLDLT) where the factor stays
// sparse, else by conjugate gradients (SeamStitcher::stitch says when). The weights are small, so
// the seam terms win: covered texels, which hold baked values, have p = 1e-3; margin texels, which
// only dilation filled, 1e-6, so that the solve moves the margin first. A sample's difference is
// then left at about p / (Σ w² + p) of what it was, under 1 % for covered texels.
//
// The samples. A lookup along a straight UV edge is bilinear in each texel cell it crosses, so
// the difference of two lookups is a quadratic in t between the points where either side's
// position crosses a row or column of texel centres. Each such piece is sampled at its start and
// its middle (and the edge at its end): with the ends of the neighbouring pieces, three points of
// each quadratic, so a difference that vanishes at the samples vanishes along the whole edge.
#include "texels/seams.h"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <tuple>
#include <unordered_map>
#include <utility>

namespace sb {

namespace {

constexpr double kCoveredPrior = 1e-3;
constexpr double kMarginPrior = 1e-6;
constexpr double kHeldPrior = 1e3;  // an unknown held at a bound (SeamStitcher::stitch)
// The conjugate gradients' relative residual |b − Ax| / |b|.
constexpr double kSolveTolerance = 1e-10;
// Above this many entries of the LDLᵀ factor per unknown, the solve iterates instead. Smart UV
// Project's layouts of the corpus give 3 to 7; Lightmap Pack's of Suzanne, 192.
constexpr double kMaxFactorEntriesPerUnknown = 50;

// Eigen's LDLᵀ, telling how many entries its factor will have once the pattern is analysed
// (the elimination tree's column counts, which Eigen keeps but does not show).
class MeasuredLdlt : public Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> {
 public:
  double factor_entries() const { return double(m_nonZerosPerCol.sum()); }
};
constexpr int kMaxRounds = 8;
// Vertex normals on the two sides closer than this cosine are one smooth surface.
const double kSmoothCos = std::cos(kSmoothEdgeDegrees * std::numbers::pi / 180.0);

// One side of a boundary edge: its end points' bits in a canonical order, and the halfedge of
// its triangle that runs along it.
struct BorderSide {
  PositionBits first, second;
  bool reversed = false;  // the halfedge runs from `second` to `first`
  TriMesh::HalfedgeHandle halfedge;
};

// A UV position in the lookup's pixel coordinates: texel (x, y)'s centre at (x, y), row 0 at
// v = 1 (core/image.h).
Vec2 pixel_of(const Vec2& uv, int width, int height) {
  return {uv.x() * width - 0.5, (1.0 - uv.y()) * height - 0.5};
}

// The four texels and weights of a bilinear lookup at pixel position p, clamped to the image.
void bilinear(const Vec2& p, int width, int height, int* texel, double* weight) {
  const double fx = std::floor(p.x()), fy = std::floor(p.y());
  const double tx = p.x() - fx, ty = p.y() - fy;
  const auto clamp_x = [&](double x) { return int(std::clamp(x, 0.0, double(width - 1))); };
  const auto clamp_y = [&](double y) { return int(std::clamp(y, 0.0, double(height - 1))); };
  const int x0 = clamp_x(fx), x1 = clamp_x(fx + 1), y0 = clamp_y(fy), y1 = clamp_y(fy + 1);
  texel[0] = y0 * width + x0;
  texel[1] = y0 * width + x1;
  texel[2] = y1 * width + x0;
  texel[3] = y1 * width + x1;
  weight[0] = (1 - tx) * (1 - ty);
  weight[1] = tx * (1 - ty);
  weight[2] = (1 - tx) * ty;
  weight[3] = tx * ty;
}

// Where a straight path from p0 to p1 crosses a whole-number x or y inside the image (0 to
// width − 1, 0 to height − 1), as parameters in (0, 1). Beyond the image the clamped lookup does
// not change along that axis, so UVs far outside [0, 1] add no crossings.
void add_crossings(const Vec2& p0, const Vec2& p1, int width, int height,
                   std::vector<double>& out) {
  for (int axis = 0; axis < 2; ++axis) {
    const double a = p0[axis], b = p1[axis];
    if (a == b) continue;
    const double last = double((axis == 0 ? width : height) - 1);
    const double lo = std::max(std::min(a, b), -1.0), hi = std::min(std::max(a, b), last + 1);
    for (double line = std::max(std::ceil(lo), 0.0); line < hi && line <= last; line += 1.0)
      if (line > std::min(a, b)) out.push_back((line - a) / (b - a));
  }
}

// One channel of an image as a right-hand side of the solve: its baked values x0, its bounds lo
// and hi per unknown, the values the priors pull towards, and the solution.
struct SeamChannel {
  std::size_t c;
  std::vector<double> x0, lo, hi, target;
  Eigen::VectorXd x;
};

// The priors as a diagonal matrix. Added as a matrix: coeffRef on a diagonal entry the seam
// terms lack would insert into the compressed storage, one shift of all entries each.
Eigen::SparseMatrix<double> prior_matrix(const std::vector<double>& prior) {
  const std::size_t n = prior.size();
  std::vector<Eigen::Triplet<double>> diagonal;
  diagonal.reserve(n);
  for (std::size_t u = 0; u < n; ++u)
    diagonal.emplace_back(Eigen::Index(u), Eigen::Index(u), prior[u]);
  Eigen::SparseMatrix<double> priors(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  priors.setFromTriplets(diagonal.begin(), diagonal.end());
  return priors;
}

// Holds each unknown some channel's solution put outside its bounds (a prior of kHeldPrior) at
// the bound it crossed; returns whether any was.
bool hold_out_of_bounds(std::vector<double>& prior, std::vector<SeamChannel>& rhs_of) {
  bool held_more = false;
  for (std::size_t u = 0; u < prior.size(); ++u) {
    if (prior[u] >= kHeldPrior) continue;
    bool out = false;
    for (const SeamChannel& ch : rhs_of) {
      const double slack = 1e-6 * (ch.hi[u] - ch.lo[u]);
      const double x = ch.x[Eigen::Index(u)];
      out = out || x < ch.lo[u] - slack || x > ch.hi[u] + slack;
    }
    if (!out) continue;
    prior[u] = kHeldPrior;
    for (SeamChannel& ch : rhs_of)
      ch.target[u] = std::clamp(ch.x[Eigen::Index(u)], ch.lo[u], ch.hi[u]);
    held_more = true;
  }
  return held_more;
}

// Solves (seam terms + priors) x = priors × target for every channel, in rounds that hold the
// unknowns leaving their bounds; false where the solver fails (the image then stays as baked).
//
// Where the seams cannot be matched within the texel grid (a chart narrower than a bilinear
// footprint, charts closer than one), the unconstrained solution overshoots: it would put
// values into the lightmap that nothing baked (a visibility below 0). An active set keeps each
// unknown within its bounds: the unknowns that left them are held at the bound they crossed
// (a prior of kHeldPrior) and the system is solved again, until none leaves them.
// A direct factorisation (LDLᵀ) where its factor stays sparse, as it does for seams between a
// few dozen charts; else conjugate gradients, preconditioned by an incomplete Cholesky factor
// and started from the baked values (then from the last round's solution). Where every edge is
// a seam (Lightmap Pack's chart per quad couples texels all over the image) the factor fills in
// almost completely: 95 s for Suzanne at 256², against 7 s by conjugate gradients; on Smart UV
// Project's layouts the factorisation is 20 times faster than the iteration.
bool solve_within_bounds(const Eigen::SparseMatrix<double>& seam_terms, std::vector<double>& prior,
                         std::vector<SeamChannel>& rhs_of, SeamSolver solver) {
  const std::size_t n = prior.size();
  MeasuredLdlt ldlt;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                           Eigen::IncompleteCholesky<double>>
      iterative;
  iterative.setTolerance(kSolveTolerance);
  bool direct = true;
  for (SeamChannel& ch : rhs_of)
    ch.x = Eigen::Map<const Eigen::VectorXd>(ch.x0.data(), Eigen::Index(n));
  for (int round = 0; round < kMaxRounds; ++round) {
    const Eigen::SparseMatrix<double> priors = prior_matrix(prior);
    const Eigen::SparseMatrix<double> normal = seam_terms + priors;
    if (round == 0) {
      ldlt.analyzePattern(normal);
      direct = solver == SeamSolver::automatic
                   ? ldlt.factor_entries() <= kMaxFactorEntriesPerUnknown * double(n)
                   : solver == SeamSolver::factorised;
    }
    if (direct) {
      ldlt.factorize(normal);
      if (ldlt.info() != Eigen::Success) return false;
    } else {
      iterative.compute(normal);
      if (iterative.info() != Eigen::Success) return false;
    }
    for (SeamChannel& ch : rhs_of) {
      Eigen::VectorXd rhs(static_cast<Eigen::Index>(n));
      for (std::size_t u = 0; u < n; ++u) rhs[Eigen::Index(u)] = prior[u] * ch.target[u];
      const Eigen::VectorXd guess = ch.x;
      ch.x = direct ? Eigen::VectorXd(ldlt.solve(rhs))
                    : Eigen::VectorXd(iterative.solveWithGuess(rhs, guess));
    }
    if (!hold_out_of_bounds(prior, rhs_of)) break;
  }
  return true;
}

}  // namespace

std::vector<SeamEdge> find_seams(const Mesh& mesh) {
  const TriMesh& m = mesh.mesh;
  const auto point = [&](TriMesh::VertexHandle v) {
    const TriMesh::Point& p = m.point(v);
    return Vec3(p[0], p[1], p[2]);
  };
  std::vector<BorderSide> sides;
  for (const auto h : m.halfedges()) {
    if (m.is_boundary(h) || !m.is_boundary(m.opposite_halfedge_handle(h))) continue;
    BorderSide side;
    side.first = position_bits(point(m.from_vertex_handle(h)));
    side.second = position_bits(point(m.to_vertex_handle(h)));
    if (side.second < side.first) {
      std::swap(side.first, side.second);
      side.reversed = true;
    }
    side.halfedge = h;
    sides.push_back(side);
  }
  const auto key_less = [](const BorderSide& x, const BorderSide& y) {
    return std::tie(x.first, x.second) < std::tie(y.first, y.second);
  };
  std::sort(sides.begin(), sides.end(), key_less);
  // A side's ends in the canonical order: (vertex at `first`, vertex at `second`).
  const auto ends = [&](const BorderSide& s) {
    auto from = m.from_vertex_handle(s.halfedge), to = m.to_vertex_handle(s.halfedge);
    if (s.reversed) std::swap(from, to);
    return std::pair{from, to};
  };
  const auto uv = [&](TriMesh::VertexHandle v) {
    const auto t = m.texcoord2D(v);
    return Vec2(t[0], t[1]);
  };
  const auto normal = [&](TriMesh::VertexHandle v) {
    const auto n = m.normal(v);
    return Vec3(n[0], n[1], n[2]);
  };
  std::vector<SeamEdge> seams;
  for (std::size_t i = 0; i < sides.size();) {
    std::size_t j = i + 1;
    while (j < sides.size() && !key_less(sides[i], sides[j])) ++j;
    if (j - i == 2) {
      const auto [a0, a1] = ends(sides[i]);
      const auto [b0, b1] = ends(sides[i + 1]);
      const bool smooth =
          normal(a0).dot(normal(b0)) >= kSmoothCos && normal(a1).dot(normal(b1)) >= kSmoothCos;
      const bool apart = uv(a0) != uv(b0) || uv(a1) != uv(b1);
      if (smooth && apart) seams.push_back({{uv(a0), uv(a1)}, {uv(b0), uv(b1)}});
    }
    i = j;
  }
  return seams;
}

SeamStitcher::SeamStitcher(const std::vector<SeamEdge>& seams, int width, int height,
                           const std::vector<std::uint8_t>& covered) {
  if (seams.empty() || width <= 0 || height <= 0) return;
  std::vector<double> ts;
  for (const SeamEdge& seam : seams) {
    const Vec2 a0 = pixel_of(seam.a[0], width, height), a1 = pixel_of(seam.a[1], width, height);
    const Vec2 b0 = pixel_of(seam.b[0], width, height), b1 = pixel_of(seam.b[1], width, height);
    ts.assign({0.0, 1.0});
    add_crossings(a0, a1, width, height, ts);
    add_crossings(b0, b1, width, height, ts);
    std::sort(ts.begin(), ts.end());
    ts.erase(std::unique(ts.begin(), ts.end()), ts.end());
    const auto add_sample = [&](double t) {
      Sample s;
      bilinear(a0 + t * (a1 - a0), width, height, s.texel, s.weight);
      bilinear(b0 + t * (b1 - b0), width, height, s.texel + 4, s.weight + 4);
      samples_.push_back(s);
    };
    for (std::size_t k = 0; k + 1 < ts.size(); ++k) {
      add_sample(ts[k]);
      add_sample(0.5 * (ts[k] + ts[k + 1]));
    }
    add_sample(1.0);
  }
  // Unknowns: every texel a sample reads, numbered in the order first read.
  std::unordered_map<int, int> unknown;
  for (Sample& s : samples_)
    for (int k = 0; k < 8; ++k) {
      const auto [it, added] = unknown.emplace(s.texel[k], int(texel_.size()));
      if (added) texel_.push_back(s.texel[k]);
      s.unknown[k] = it->second;
    }
  covered_.resize(texel_.size());
  for (std::size_t u = 0; u < texel_.size(); ++u) covered_[u] = covered[std::size_t(texel_[u])];
}

bool SeamStitcher::measured(const Sample& s, const std::vector<std::uint8_t>& arbitrary) const {
  if (arbitrary.empty()) return true;
  for (int k = 0; k < 8; ++k)
    if (s.weight[k] != 0 && arbitrary[std::size_t(s.texel[k])]) return false;
  return true;
}

SeamDifference SeamStitcher::difference(const Image& image,
                                        const std::vector<std::uint8_t>& arbitrary,
                                        double scale) const {
  SeamDifference out;
  std::int64_t measured_samples = 0, visible = 0;
  for (const Sample& s : samples_) {
    if (!measured(s, arbitrary)) continue;
    ++measured_samples;
    double largest = 0;
    for (int c = 0; c < image.channels; ++c) {
      double d = 0;
      for (int k = 0; k < 8; ++k) {
        const double v =
            image.pixels[std::size_t(s.texel[k]) * std::size_t(image.channels) + std::size_t(c)];
        d += (k < 4 ? s.weight[k] : -s.weight[k]) * v;
      }
      largest = std::max(largest, std::abs(d));
    }
    visible += largest > scale / 255.0;
    out.largest = std::max(out.largest, largest);
  }
  out.visible = measured_samples > 0 ? double(visible) / double(measured_samples) : 0.0;
  return out;
}

// Covered texels keep their baked values with kCoveredPrior, margin texels with kMarginPrior;
// arbitrary texels keep theirs (kHeldPrior), and the samples that read them ask nothing.
std::vector<double> SeamStitcher::prior_weights(const std::vector<std::uint8_t>& arbitrary) const {
  const std::size_t n = texel_.size();
  std::vector<double> prior(n);
  for (std::size_t u = 0; u < n; ++u) {
    const bool arbitrary_texel = !arbitrary.empty() && arbitrary[std::size_t(texel_[u])];
    prior[u] = arbitrary_texel ? kHeldPrior : covered_[u] ? kCoveredPrior : kMarginPrior;
  }
  return prior;
}

// A channel's bounds per unknown, from its baked values x0: the smallest and largest x0 among the
// covered texels that share a solved sample with the unknown, or among all its texels for a
// sample that reads none; an unknown no solved sample reads is bound to its own x0.
void SeamStitcher::channel_bounds(const std::vector<std::uint8_t>& arbitrary,
                                  const std::vector<double>& prior, const std::vector<double>& x0,
                                  std::vector<double>& lo_of, std::vector<double>& hi_of) const {
  const std::size_t n = texel_.size();
  lo_of.assign(n, std::numeric_limits<double>::infinity());
  hi_of.assign(n, -std::numeric_limits<double>::infinity());
  for (const Sample& s : samples_) {
    if (!measured(s, arbitrary)) continue;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int pass = 0; pass < 2 && lo > hi; ++pass)
      for (int k = 0; k < 8; ++k) {
        const std::size_t u = std::size_t(s.unknown[k]);
        if (pass == 0 && prior[u] != kCoveredPrior) continue;
        lo = std::min(lo, x0[u]);
        hi = std::max(hi, x0[u]);
      }
    for (int k = 0; k < 8; ++k) {
      const std::size_t u = std::size_t(s.unknown[k]);
      lo_of[u] = std::min(lo_of[u], lo);
      hi_of[u] = std::max(hi_of[u], hi);
    }
  }
  for (std::size_t u = 0; u < n; ++u)
    if (lo_of[u] > hi_of[u]) lo_of[u] = hi_of[u] = x0[u];  // read by no sample solved for
}

void SeamStitcher::stitch(Image& image, const std::vector<std::uint8_t>& arbitrary,
                          SeamSolver solver) const {
  const std::size_t n = texel_.size();
  if (n == 0) return;
  std::vector<double> prior = prior_weights(arbitrary);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(samples_.size() * 8);
  Eigen::Index rows = 0;
  for (const Sample& s : samples_) {
    if (!measured(s, arbitrary)) continue;
    for (int k = 0; k < 8; ++k) {
      const double w = k < 4 ? s.weight[k] : -s.weight[k];
      if (w != 0) entries.emplace_back(rows, s.unknown[k], w);
    }
    ++rows;
  }
  if (rows == 0) return;
  Eigen::SparseMatrix<double> a(rows, Eigen::Index(n));
  a.setFromTriplets(entries.begin(), entries.end());  // sums a texel read by both sides
  const Eigen::SparseMatrix<double> seam_terms = a.transpose() * a;
  // Each channel is one right-hand side: its baked values x0 and its bounds.
  const std::size_t channels = std::size_t(image.channels);
  std::vector<SeamChannel> rhs_of;
  for (std::size_t c = 0; c < channels; ++c) {
    SeamChannel ch{c, std::vector<double>(n), {}, {}, {}, {}};
    for (std::size_t u = 0; u < n; ++u)
      ch.x0[u] = image.pixels[std::size_t(texel_[u]) * channels + c];
    channel_bounds(arbitrary, prior, ch.x0, ch.lo, ch.hi);
    ch.target = ch.x0;
    rhs_of.push_back(std::move(ch));
  }
  if (!solve_within_bounds(seam_terms, prior, rhs_of, solver)) return;  // leaves it as baked
  for (const SeamChannel& ch : rhs_of)
    for (std::size_t u = 0; u < n; ++u) {
      if (!arbitrary.empty() && arbitrary[std::size_t(texel_[u])]) continue;  // as baked, exactly
      image.pixels[std::size_t(texel_[u]) * channels + ch.c] =
          float(std::clamp(ch.x[Eigen::Index(u)], ch.lo[u], ch.hi[u]));
    }
}

SeamReport stitch_seams(const std::vector<SeamEdge>& seams,
                        const std::vector<std::uint8_t>& covered,
                        const std::vector<SeamImage>& images, double scale, bool solve,
                        SeamSolver solver) {
  SeamReport report;
  if (images.empty() || seams.empty()) return report;
  const SeamImage& first = images.front();
  const SeamStitcher stitcher(seams, first.image->width, first.image->height, covered);
  report.edges = std::int64_t(seams.size());
  report.before = stitcher.difference(*first.image, first.arbitrary, scale);
  if (!solve) {
    report.after = report.before;
    return report;
  }
  report.texels = stitcher.texels();
  for (const SeamImage& image : images) stitcher.stitch(*image.image, image.arbitrary, solver);
  report.after = stitcher.difference(*first.image, first.arbitrary, scale);
  return report;
}

}  // namespace sb
