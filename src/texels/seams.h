// UV seams of a receiver and their stitching: where one edge of the surface is two chart borders
// in the lightmap, a bilinear lookup on either side reads different texels, and a lit surface
// shows a line along every seam. stitch_seams adjusts the texels under both sides so that their
// lookups agree (a least-squares solve, as in Sloan's "Stitch Seams"), after dilation, in every
// image of the receiver. docs/methods.md ("Seams") has the choices and the measured figures.
#pragma once

#include <cstdint>
#include <vector>

#include "core/geometry.h"
#include "core/image.h"
#include "scene/mesh.h"

namespace sb {

// Two vertex normals closer than this angle (degrees) are one smooth surface across an edge; wider
// apart, the edge is hard (a crease the normals split).
inline constexpr double kSmoothEdgeDegrees = 0.5;

// One mesh edge seen from its two triangles: the UVs of its two ends on side a and on side b
// (a[k] and b[k] are the same surface point).
struct SeamEdge {
  Vec2 a[2], b[2];
};

// The mesh's seams: edges whose two triangles meet in space (the same end points, bit for bit)
// but not in UV, where the surface is smooth across the edge (both sides' vertex normals agree
// within 0.5°). A hard edge (normals split) is left out: the light on its two sides differs in
// truth, and matching it would blur a real crease. Edges of more than two triangles are left out.
std::vector<SeamEdge> find_seams(const Mesh& mesh);

// What stitching did to one receiver: its seams, the texels the solve changed, and the
// difference between the two sides' bilinear lookups (over every channel of the receiver's
// image, at the solve's sample points) before and after: the largest, and the share of samples
// where it is visible in an 8-bit image, above 1/255 of `scale`.
struct SeamDifference {
  double largest = 0;
  double visible = 0;  // share of the measured samples, [0, 1]
};
struct SeamReport {
  std::int64_t edges = 0;
  std::int64_t texels = 0;  // the texels the seams' lookups read: those the solve may change
  SeamDifference before, after;
  // Whether the bake's seams pass was on ([bake] seams): after = before when not, and for a
  // receiver without seams either way.
  bool stitched = false;
};

// One image of a receiver to stitch, with its arbitrary texels: covered texels whose value means
// nothing (a visibility where no light reaches, 0 or 1 by convention). They keep their values,
// and a seam sample that reads one is neither solved for nor measured; empty: none.
struct SeamImage {
  Image* image = nullptr;
  std::vector<std::uint8_t> arbitrary;
};

// How the least-squares system is solved: factored (Eigen's LDLᵀ) where its factor stays sparse
// and by conjugate gradients where it would fill in (automatic), or always one way (for tests).
enum class SeamSolver { automatic, factorised, iterative };

// The least-squares system of a receiver's seams at one lightmap size, built once and solved for
// each of its images (the value image, per-light images, shadow-mask visibility): a receiver's
// per-light images are stitched one at a time (pipeline/receiver_stages.cpp).
class SeamStitcher {
 public:
  SeamStitcher(const std::vector<SeamEdge>& seams, int width, int height,
               const std::vector<std::uint8_t>& covered);

  std::int64_t texels() const { return std::int64_t(texel_.size()); }
  // |lookup on side a − lookup on side b| over the measured samples and the channels: the
  // largest, and the share of samples above scale / 255.
  SeamDifference difference(const Image& image, const std::vector<std::uint8_t>& arbitrary,
                            double scale) const;
  // Solves for the image's seam texels, every channel, each kept within the values around it.
  void stitch(Image& image, const std::vector<std::uint8_t>& arbitrary, SeamSolver solver) const;

 private:
  struct Sample {
    int texel[8];    // side a's four bilinear texels, then side b's (pixel indices)
    int unknown[8];  // the same texels as indices into texel_
    double weight[8];
  };
  bool measured(const Sample& s, const std::vector<std::uint8_t>& arbitrary) const;
  // The steps of stitch: each unknown's prior weight, and one channel's bounds on its unknowns.
  std::vector<double> prior_weights(const std::vector<std::uint8_t>& arbitrary) const;
  void channel_bounds(const std::vector<std::uint8_t>& arbitrary, const std::vector<double>& prior,
                      const std::vector<double>& x0, std::vector<double>& lo_of,
                      std::vector<double>& hi_of) const;
  std::vector<Sample> samples_;
  std::vector<int> texel_;             // the solve's unknowns: pixel indices
  std::vector<std::uint8_t> covered_;  // per unknown
};

// Stitches `images` (all width × height of one receiver) along `seams`, each on its own, and
// reports on the first (its differences against `scale`: 1 for a visibility, the largest value
// for an irradiance); with `solve` false, only measures them (after = before, texels 0).
// `covered`: the lightmap's coverage (TexelSpace::covered); uncovered texels (the dilated
// margin) are freer to move than covered ones, which hold baked values.
SeamReport stitch_seams(const std::vector<SeamEdge>& seams,
                        const std::vector<std::uint8_t>& covered,
                        const std::vector<SeamImage>& images, double scale, bool solve = true,
                        SeamSolver solver = SeamSolver::automatic);

}  // namespace sb
