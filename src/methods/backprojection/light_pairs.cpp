// Stage 2's exact evaluations of one uniform light (light_pairs.h): a listed tile's blockers
// prepared once, then per texel the ray to the light's centre where it settles an umbra, else the
// texel's blockers back-projected onto the light (penumbra_estimator.h).
#include "methods/backprojection/light_pairs.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <limits>
#include <memory>
#include <span>

#include "methods/backprojection/penumbra_estimator.h"
#include "methods/backprojection/piercing_blockers.h"
#include "methods/backprojection/tile_blockers.h"
#include "methods/backprojection/tile_shafts.h"
#include "methods/backprojection/umbra_proofs.h"
#include "occluders/blocker_solids.h"
#include "occluders/shadow_rays.h"

namespace sb {

namespace {

// A texel whose patch lists more polygons than this first tries the ray to the light's centre.
constexpr std::size_t kRayFirst = 8;

// Stage 2's exact evaluations of one uniform light (texel_refinement.h's PairSource).
// A light whose form factor at a texel is below this shows it a sliver at its horizon.
constexpr double kSliver = 1e-8;
// A ray origin this far from its texel, relative to a sphere light's distance, sees the sphere's
// near side shifted by a hundredth of its radius or more.
constexpr double kParallax = 1e-2;

class LightPairs final : public PairSource {
 public:
  LightPairs(const TexelSpace& space, const Light& light, const BackprojectionInputs& in,
             const TileShafts& tiles)
      : space_(space),
        light_(light),
        in_(in),
        tiles_(tiles),
        offset_(in.rays->surface_offset()),
        estimator_(light, in.light_rows, offset_),
        piercing_(piercing_blockers(*in.culler, light)),
        prepared_of_(tiles.patches.size(), -1) {
    // The listed patches' blockers, and those of the umbrae whose texels the refinement may
    // evaluate as its cells' corners: the umbra patches of a tile that holds cells, or of a tile
    // right of, below or below-right of one.
    const auto searched = [&](int tx, int ty) {
      if (tx < 0 || ty < 0) return false;
      const TileShafts::Kind k = tiles.kind[std::size_t(ty) * std::size_t(tiles.tiles_x) + tx];
      return k == TileShafts::Kind::listed || k == TileShafts::Kind::all;
    };
    std::vector<std::size_t> prepare;  // those patches, each given its place in prepared_
    for (std::size_t i = 0; i < tiles.kind.size(); ++i) {
      const int tx = int(i % std::size_t(tiles.tiles_x)), ty = int(i / std::size_t(tiles.tiles_x));
      const bool corners = searched(tx, ty) || searched(tx - 1, ty) || searched(tx, ty - 1) ||
                           searched(tx - 1, ty - 1);
      for (std::uint32_t p = tiles.first_patch[i]; p < tiles.first_patch[i + 1]; ++p) {
        const TileShafts::Kind k = tiles.patches[p].kind;
        if (k == TileShafts::Kind::listed || (k == TileShafts::Kind::umbra && corners)) {
          prepared_of_[p] = std::int32_t(prepare.size());
          prepare.push_back(p);
        }
      }
    }
    prepared_.resize(prepare.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, prepare.size(), 8), [&](const auto& r) {
      std::vector<std::uint32_t> listed;
      for (std::size_t k = r.begin(); k != r.end(); ++k) {
        const TileShafts::Patch& patch = tiles.patches[prepare[k]];
        const std::vector<std::uint32_t>* candidates = &patch.candidates;
        // An umbra the shaft test proved without listing its candidates (tile_shafts.cpp):
        // listed here, where its texels are cells' corners; where they are too many, its
        // texels search the hierarchy.
        if (candidates->empty()) {
          if (!in.culler->tile_candidates(patch.origins, light, kTileCandidates, listed) ||
              listed.empty()) {
            prepared_of_[prepare[k]] = -1;
            continue;
          }
          std::sort(listed.begin(), listed.end());
          candidates = &listed;
        }
        prepared_[k] =
            tile_blockers(*in.culler, light, *candidates, patch.origins, offset_, piercing_);
      }
    });
  }

  void evaluate(std::size_t t, PairSample& out) const override {
    const Texel& tx = space_.texels[t];
    const Vec3 p = tx.position.cast<double>(), n = tx.normal.cast<double>();
    const Vec3 origin = space_.ray_origin(t, offset_);
    out = PairSample();
    const double form_factor = light_.form_factor(p, n);
    if (!(form_factor > 0)) return;
    if (form_factor < kSliver) return sliver(t, out);
    // A sphere light seen from a ray origin lifted far from the texel (a coarse mesh's smooth
    // surface): the reference aims its rays from the origin at the sphere's near side as the
    // texel sees it, which the origin sees shifted by parallax, where the rows see the
    // silhouette's disk. Where the shift is a noticeable part of the sphere's radius, the rows'
    // fixed points are traced to where the reference aims.
    // Every ray traced there runs from the origin to the light, inside the origin's shaft: where
    // no blocker may lie in it (most such texels of a level's smooth-shaded curves), V is
    // exactly 1 without them; where one triangle hides all of the light from the origin (below),
    // exactly 0.
    const bool parallax = light_.shape() == LightShape::sphere &&
                          (origin - p).norm() > kParallax * (light_.centre() - p).norm();
    if (parallax) {
      const std::vector<std::uint32_t>& listed = tiles_.patches[patch_index(tx.x, tx.y)].candidates;
      if (!in_.culler->maybe_blocked(origin, p, n, light_, listed.empty() ? nullptr : &listed)) {
        out.route = TexelRoute::clear;
        out.visibility = 1;
        return;
      }
    }
    const std::int32_t at = prepared_of_[patch_index(tx.x, tx.y)];
    bool centre_hidden = false;
    if (centre_umbra(origin, at, parallax, centre_hidden, out)) return;
    if (parallax) return traced(t, p, n, origin, form_factor, out);
    PenumbraSample sample;
    if (!estimate(p, n, origin, at, centre_hidden, form_factor, sample, out))
      return traced(t, p, n, origin, form_factor, out);
    if (!sample.contributes) return sliver(t, out);  // no rows above the horizon: a sliver
    // Nothing hid any of the light: exactly 1, as a clear shaft.
    out.route = out.triangles.empty() ? TexelRoute::clear : TexelRoute::exact;
    out.visibility = float(sample.visibility);
    out.nearest = float(sample.nearest_blocker);
    out.umbra = sample.umbra;
    // All of the light hidden, by one convex solid alone: its umbra, however the estimator took
    // it (a ball resting on the floor, by its faces where its silhouette reaches below the
    // texel's origin).
    if (out.visibility == 0 && out.triangles.size() == 1 &&
        (out.triangles[0] & ShaftCuller::kSolidKey))
      out.umbra = out.triangles[0];
  }

  double angular_width(std::size_t t) const override {
    const Vec3 y = space_.texels[t].position.cast<double>();
    const Vec3 to = y - light_.centre();
    const double distance = std::max(to.norm(), 1e-12);
    const LightDesc& d = light_.desc();
    switch (light_.shape()) {
      case LightShape::rectangle:
        return std::min(d.width, d.height) * std::abs(light_.normal().dot(to)) /
               (distance * distance);
      case LightShape::disk:
        return 2 * d.radius * std::abs(light_.normal().dot(to)) / (distance * distance);
      case LightShape::sphere:
        return 2 * d.radius / distance;
      case LightShape::polygon: {
        // A width no wider than its narrowest: its area over its longest side or diagonal
        // (twice that for a triangle, whose height it is).
        double longest = 0;
        for (const Vec3& a : d.corners)
          for (const Vec3& b : d.corners) longest = std::max(longest, (a - b).norm());
        const double factor = d.corners.size() == 3 ? 2.0 : 1.0;
        return factor * light_.area() / std::max(longest, 1e-300) *
               std::abs(light_.normal().dot(to)) / (distance * distance);
      }
      case LightShape::mesh:
      case LightShape::sky:
        break;
    }
    return 0;
  }

  bool sees_unlisted(const std::vector<std::size_t>& texels,
                     const std::vector<std::uint32_t>& listed) const override {
    // Texel by texel, among its patch's candidates no sample listed; but for those of a convex
    // solid every texel of the patch lies on (their own surface: a ray that leaves it above the
    // horizon does not come back to it, and where it grazes it the samples listed it). A texel
    // of a patch without a list searches the whole hierarchy.
    thread_local std::vector<Vec3> origins;
    thread_local std::vector<std::uint32_t> unlisted;
    for (std::size_t k = 0; k < texels.size();) {
      const Texel& first = space_.texels[texels[k]];
      const TileShafts::Patch& patch = tiles_.patch(first.x, first.y);
      // The run of texels of this patch that starts here.
      std::size_t end = k + 1;
      while (end < texels.size() &&
             &tiles_.patch(space_.texels[texels[end]].x, space_.texels[texels[end]].y) == &patch)
        ++end;
      origins.clear();
      Bounds3 box;
      for (std::size_t j = k; j < end; ++j) {
        origins.push_back(space_.ray_origin(texels[j], offset_));
        box.extend(origins.back());
      }
      // A clear or umbra patch's texels hold their exact values already: the cell interpolates
      // none of them.
      if (patch.kind == TileShafts::Kind::clear || patch.kind == TileShafts::Kind::umbra) {
        k = end;
        continue;
      }
      if (patch.kind != TileShafts::Kind::listed) {
        for (std::size_t j = k; j < end; ++j) {
          const Texel& tx = space_.texels[texels[j]];
          if (in_.culler->maybe_blocked(origins[j - k], tx.position.cast<double>(),
                                        tx.normal.cast<double>(), light_, nullptr, &listed))
            return true;
        }
        k = end;
        continue;
      }
      unlisted.clear();
      std::uint32_t on_key = 0, off_key = 0;  // the last solid found to hold the texels, or not
      for (std::uint32_t i : patch.candidates) {
        const std::uint32_t key = in_.culler->blocker_key(i);
        if (std::binary_search(listed.begin(), listed.end(), key)) continue;
        if (key & ShaftCuller::kSolidKey) {
          if (key != on_key && key != off_key)
            (on_solid(key, origins, box) ? on_key : off_key) = key;
          if (key == on_key) continue;
        }
        unlisted.push_back(i);
      }
      // The run's box first: a triangle in no shaft from it is in no texel's (most cells'
      // runs, whose every texel would otherwise search the list).
      thread_local std::vector<std::uint32_t> found;
      if (!unlisted.empty() &&
          (end - k == 1 || in_.culler->tile_candidates(box, light_, 0, found, &unlisted)))
        for (std::size_t j = k; j < end; ++j) {
          const Texel& tx = space_.texels[texels[j]];
          if (in_.culler->maybe_blocked(origins[j - k], tx.position.cast<double>(),
                                        tx.normal.cast<double>(), light_, &unlisted))
            return true;
        }
      k = end;
    }
    return false;
  }

  bool one_triangle_hides(const std::array<std::size_t, 5>& samples,
                          const std::vector<std::uint32_t>& seen) const override {
    const Texel& first = space_.texels[samples[0]];
    const TileShafts::Patch& patch = tiles_.patch(first.x, first.y);
    if (patch.kind != TileShafts::Kind::listed && patch.kind != TileShafts::Kind::umbra)
      return false;
    // The centre (the last sample) first.
    std::array<Vec3, 5> origins;
    for (std::size_t k = 0; k < 5; ++k) origins[k] = space_.ray_origin(samples[4 - k], offset_);
    // The first sample's patch's candidates of what the samples saw (a triangle hiding all of the
    // light from it is among them).
    for (std::uint32_t i : patch.candidates) {
      if (std::binary_search(seen.begin(), seen.end(), in_.culler->blocker_key(i)) &&
          hides_from_all(light_, in_.culler->triangle_corners(i), origins, offset_))
        return true;
    }
    return false;
  }

  bool ball_hides(const std::vector<std::size_t>& texels,
                  const std::vector<std::uint32_t>& seen) const override {
    Bounds3 box;
    for (std::size_t t : texels) box.extend(space_.ray_origin(t, offset_));
    if (box.empty()) return false;
    std::array<Vec3, 8> corners;
    for (int k = 0; k < 8; ++k) corners[std::size_t(k)] = box.corner(k);
    thread_local std::vector<std::uint32_t> tried;  // a solid's triangles each name it
    tried.clear();
    for (std::uint32_t key : seen)
      for (std::uint32_t solid_key : in_.culler->solids_with_balls(key)) {
        if (std::find(tried.begin(), tried.end(), solid_key) != tried.end()) continue;
        tried.push_back(solid_key);
        const BlockerSolid& solid = in_.culler->solid_of_key(solid_key);
        // Every origin outside the solid: farther from the ball's centre than all its corners.
        const Vec3 nearest = solid.inner_centre.cwiseMax(box.lo).cwiseMin(box.hi);
        if (!((nearest - solid.inner_centre).norm() > solid.outer_radius)) continue;
        const auto hides = [&](const Vec3& origin) {
          return ball_hides_light(light_, solid.inner_centre, solid.inner_radius, origin, offset_);
        };
        if (std::all_of(corners.begin(), corners.end(), hides)) return true;
      }
    return false;
  }

 private:
  // A sliver of light at the texel's horizon (F below 1e-8: a texel on an edge, or near a
  // curved blocker's terminator): whether geometry within a hair of the ray origin hides it is
  // the rays' call, so the texel takes the reference's own estimate, as a texel whose visible
  // part is too thin for the estimator's rows does.
  void sliver(std::size_t t, PairSample& out) const {
    // One batch per thread, grown to the bake's samples (an earlier bake may have had fewer).
    thread_local ShadowRays batch(0);
    if (batch.capacity() < in_.samples) batch = ShadowRays(in_.samples);
    thread_local std::vector<Vec2> strata;
    Vec3 v;
    out = PairSample();
    if (!estimate_visibility(space_, t, light_, *in_.rays, in_.samples, in_.seed, in_.stream, batch,
                             strata, &v))
      return;
    out.route = TexelRoute::traced;
    out.visibility = float(v.x());
    // Nothing listed, as nothing hides the sliver, or a blocker at an unknown distance.
    out.nearest = v.x() == 1 ? std::numeric_limits<float>::infinity() : 0.0f;
  }

  // The rows' fixed points traced (PenumbraEstimator::visibility_traced).
  void traced(std::size_t t, const Vec3& p, const Vec3& n, const Vec3& origin, double form_factor,
              PairSample& out) const {
    const PenumbraSample sample =
        estimator_.visibility_traced(p, n, origin, *in_.rays, form_factor);
    if (!sample.contributes) return sliver(t, out);
    out.route = TexelRoute::traced;
    out.listed = false;
    out.visibility = float(sample.visibility);
    out.nearest = float(sample.nearest_blocker);
  }

  // Whether the ray to the light's centre settles the texel in one triangle's umbra (then `out`
  // holds it); `centre_hidden`: whether that ray meets a blocker at all.
  bool centre_umbra(const Vec3& origin, std::int32_t at, bool parallax, bool& centre_hidden,
                    PairSample& out) const {
    // The light's centre first, where the texel's blockers are many (not listed, a dense mesh's
    // outline, or more polygons than kRayFirst) or are to be traced: where the ray to it meets a
    // triangle that hides all of the light alone, the texel lies in that triangle's umbra,
    // exactly, whatever else its shaft holds. (A few polygons or convex solids cost the
    // estimator less than the ray.)
    const bool busy = parallax || at < 0 || !prepared_[std::size_t(at)].outlines.empty() ||
                      prepared_[std::size_t(at)].polygons.size() > kRayFirst;
    if (const RayScene::Hit hit =
            busy ? in_.rays->first_hit_face(origin, light_.centre() - origin, 1.0)
                 : RayScene::Hit();
        hit.face >= 0) {
      centre_hidden = true;
      const std::uint32_t triangle = in_.culler->triangle_of_face(hit.face);
      if (triangle_hides_light(light_, in_.culler->triangle_corners(triangle), origin, offset_)) {
        out.route = TexelRoute::umbra;
        out.visibility = 0;
        out.nearest = 0;  // the shaft is not listed: nearer blockers are unknown
        const std::uint32_t key = in_.culler->blocker_key(triangle);
        out.triangles.assign(1, key);
        // A convex solid's face: the solid's umbra, which holds the face's (and is convex), so
        // that samples behind different faces of one box lie in one umbra.
        out.umbra = key & ShaftCuller::kSolidKey ? key : triangle;
        return true;
      }
    }
    return false;
  }

  // The estimator's sample at the texel from its blockers; false where its shaft holds too many
  // polygons to list (the caller traces instead).
  bool estimate(const Vec3& p, const Vec3& n, const Vec3& origin, std::int32_t at,
                bool centre_hidden, double form_factor, PenumbraSample& sample,
                PairSample& out) const {
    // The blockers: the tile's candidates as they are (the estimator cuts what lies beyond the
    // light or behind the origin, and ignores what projects outside the light), or, for a tile
    // without a list, the texel's own shaft's polygons from the whole hierarchy.
    thread_local std::vector<BlockerPolygon> blockers;
    thread_local std::vector<ShaftPolygon> polygons;
    blockers.clear();
    if (at >= 0) {
      const TileBlockers& prepared = prepared_[std::size_t(at)];
      sample = estimator_.visibility(
          p, n, origin,
          Blockers{&prepared.polygons, &prepared.solids, &prepared.outlines, centre_hidden},
          form_factor, &out.triangles);
    } else {
      const ShaftCuller::Polygons listed = in_.culler->shaft_polygons(
          origin, p, n, light_, nullptr, std::size_t(in_.max_polygons), polygons);
      if (listed == ShaftCuller::Polygons::too_many) return false;
      // The union of what samples see is kept by key (a solid's triangles as the solid); a
      // triangle through the light's ball goes as its parts outside it.
      for (const ShaftPolygon& poly : polygons) {
        const std::uint32_t key = in_.culler->blocker_key(poly.triangle);
        if (piercing_.pierces(poly.triangle))
          add_parts(piercing_, poly.triangle, key, poly.normal, blockers);
        else
          blockers.push_back({poly.v.data(), poly.count, poly.normal, key, poly.triangle});
      }
      sample = estimator_.visibility(p, n, origin, Blockers{&blockers, nullptr, nullptr},
                                     form_factor, &out.triangles);
    }
    return true;
  }

  // Whether every one of the texels' ray origins lies on the convex solid `key` (or in it): in
  // front of none of its face planes by more than the rays' offset, four times over, or a
  // five-hundredth of its size (a curved surface's shadow origins lie on the smooth surface,
  // outside its flat faces by their sagitta).
  // `box` bounds the origins.
  bool on_solid(std::uint32_t key, const std::vector<Vec3>& origins, const Bounds3& box) const {
    const BlockerSolid& solid = in_.culler->solid_of_key(key);
    const double tolerance = std::max(4 * offset_, 2e-3 * solid.bounds.diagonal());
    // First the boxes, cheaply.
    if (((solid.bounds.lo.array() - tolerance) > box.lo.array()).any() ||
        ((solid.bounds.hi.array() + tolerance) < box.hi.array()).any())
      return false;
    for (const Vec3& origin : origins) {
      for (std::size_t f = 0; f < solid.faces.size(); ++f)
        if (solid.normals[f].dot(origin - solid.corners[std::size_t(solid.faces[f][0])]) >
            tolerance)
          return false;
    }
    return true;
  }

  const TexelSpace& space_;
  const Light& light_;
  const BackprojectionInputs& in_;
  // The index in tiles_.patches of the patch of the texel at pixel (x, y).
  std::size_t patch_index(int x, int y) const {
    return std::size_t(&tiles_.patch(x, y) - tiles_.patches.data());
  }

  const TileShafts& tiles_;
  double offset_;
  PenumbraEstimator estimator_;
  PiercingBlockers piercing_;  // the triangles through a sphere light's ball
  // The listed patches' blockers, and some umbrae's (above); per patch, its place among them or
  // -1.
  std::vector<TileBlockers> prepared_;
  std::vector<std::int32_t> prepared_of_;
};

}  // namespace

std::unique_ptr<PairSource> light_pairs(const TexelSpace& space, const Light& light,
                                        const BackprojectionInputs& in, const TileShafts& tiles) {
  return std::make_unique<LightPairs>(space, light, in, tiles);
}

}  // namespace sb
