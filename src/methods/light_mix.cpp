// LightMix (light_mix.h): the one rule by which methods combine lights.
#include "methods/light_mix.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <iterator>

#include "methods/terminator_fill.h"

namespace sb {

TiledImages per_light_values(std::size_t lights, int width, int height) {
  return TiledImages(lights, width, height, {0, 0, 0}, TiledImages::Spill::to_file);
}

TiledImages per_light_visibilities(std::size_t lights, int width, int height) {
  return TiledImages(lights, width, height, {1, 0}, TiledImages::Spill::to_file);
}

LightMix::LightMix(const TexelSpace& space, const std::vector<Light>& lights, Quantity quantity,
                   Order order, KeepPerLight keep, const LightLists* lists)
    : space_(space), lights_(lights), lists_(lists), quantity_(quantity), keep_(keep) {
  // Visibility: texels where no light counts hold kNoLightCounts until finish() fills the
  // terminators' (terminator_fill.h).
  out_.image = Image(space.width, space.height, 3, value_start()[0]);
  // One light's visibility, set light by light: its V is the texel's value wherever it reaches
  // (H0·V / H0), so set() writes it straight into the image and nothing waits for finish() (a
  // 4096² receiver's per-light buffer alone would be 260 MB).
  const bool by_light = order != Order::texel_major;
  direct_ = by_light && lights.size() == 1 && quantity == Quantity::visibility && !keep.any();
  if (by_light && !direct_) {
    set_sums_.resize(space.texels.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, set_sums_.size(), 1 << 14),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        std::fill(set_sums_.begin() + std::ptrdiff_t(range.begin()),
                                  set_sums_.begin() + std::ptrdiff_t(range.end()), Sum{});
                      });
  }
  const std::size_t outputs = output_count(lights);
  if (keep_.values) out_.per_light = per_light_values(outputs, space.width, space.height);
  if (keep_.visibility)
    out_.per_light_visibility = per_light_visibilities(outputs, space.width, space.height);
  if (keep_.any()) {
    // Each output's tiles: the blocks its parts' lists give them, or every one without lists. A
    // value image's start there is value_start(), as the combined image's; a visibility
    // image's (1, 0).
    std::vector<std::vector<std::uint32_t>> tiles(outputs);
    const TiledImages& shape = keep_.values ? out_.per_light : out_.per_light_visibility;
    const std::size_t all = std::size_t(shape.tiles_x()) * std::size_t(shape.tiles_y());
    for (std::size_t l = 0; l < lights.size(); ++l) {
      std::vector<std::uint32_t>& t = tiles[std::size_t(lights[l].output())];
      if (!lists) {
        t.resize(all);
        for (std::size_t k = 0; k < all; ++k) t[k] = std::uint32_t(k);
        continue;
      }
      const auto blocks = lists->blocks_of(l);
      std::vector<std::uint32_t> both;
      std::set_union(t.begin(), t.end(), blocks.begin(), blocks.end(), std::back_inserter(both));
      t.swap(both);
    }
    std::vector<int> parts(outputs, 0);
    for (const Light& l : lights) ++parts[std::size_t(l.output())];
    by_turn_ = order == Order::light_by_light &&
               std::all_of(parts.begin(), parts.end(), [](int p) { return p == 1; });
    if (by_turn_) {
      turn_tiles_ = std::move(tiles);
    } else {
      for (std::size_t o = 0; o < outputs; ++o) reserve(o, tiles[o]);
    }
    // A mesh light's parts are summed per texel until finish(): Σ H0·V and Σ H0.
    sums_.resize(outputs);
    for (std::size_t o = 0; o < outputs; ++o)
      if (parts[o] > 1) sums_[o].assign(space.texels.size(), Sum{});
  }
}

std::array<float, 3> LightMix::value_start() const {
  // The combined image's start, and a value image's over its tiles: kNoLightCounts for
  // visibility.
  const float unset = quantity_ == Quantity::visibility ? kNoLightCounts : 0.0f;
  return {unset, unset, unset};
}

void LightMix::reserve(std::size_t output, std::span<const std::uint32_t> tiles) {
  const float visibility_start[2] = {1, 0};
  if (keep_.values) out_.per_light.reserve(output, tiles, value_start());
  if (keep_.visibility) out_.per_light_visibility.reserve(output, tiles, visibility_start);
}

void LightMix::begin_light(std::size_t light) {
  if (!by_turn_) return;
  const std::size_t o = std::size_t(lights_[light].output());
  reserve(o, turn_tiles_[o]);
  turn_tiles_[o] = std::vector<std::uint32_t>();
}

void LightMix::end_light(std::size_t light) {
  if (by_turn_) finish_output(std::size_t(lights_[light].output()), {light});
}

void LightMix::finish_output(std::size_t o, const std::vector<std::size_t>& parts) {
  if (o < out_.per_light.size()) {
    if (quantity_ == Quantity::visibility) {
      const float uncounted[3] = {kNoLightCounts, kNoLightCounts, kNoLightCounts};
      Image image = out_.per_light.dense(o, uncounted);
      fill_terminators(space_, lights_, parts, UncountedMark::value, image, lists_,
                       out_.per_light.tiles(o));
      out_.per_light.assign(o, image);
    }
    out_.per_light.park(o);
  }
  if (o < out_.per_light_visibility.size()) {
    Image image = out_.per_light_visibility.dense(o);
    fill_terminators(space_, lights_, parts, UncountedMark::flag_off, image, lists_,
                     out_.per_light_visibility.tiles(o));
    out_.per_light_visibility.assign(o, image);
  }
}

Vec3 LightMix::unoccluded(std::size_t light, std::size_t texel) const {
  const Texel& t = space_.texels[texel];
  return lights_[light].unoccluded_irradiance(t.position.cast<double>(), t.normal.cast<double>());
}

void LightMix::keep(std::size_t light, std::size_t texel, const Vec3& h0, const Vec3& v) {
  if (!keep_.any()) return;
  const std::size_t output = std::size_t(lights_[light].output());
  if (!sums_[output].empty()) {
    sums_[output][texel].h += h0.cwiseProduct(v);
    sums_[output][texel].h0 += h0;
    return;
  }
  keep_output(output, texel, h0, v);
}

void LightMix::keep_output(std::size_t output, std::size_t texel, const Vec3& h0, const Vec3& v) {
  const Texel& t = space_.texels[texel];
  const bool counts = h0.maxCoeff() > 0;
  // A light's pairs lie in its lists' blocks, where its tiles are.
  float* px = keep_.values && (counts || quantity_ == Quantity::irradiance)
                  ? out_.per_light.at(output, t.x, t.y)
                  : nullptr;
  if (px) {
    for (int c = 0; c < 3; ++c) {
      const double value =
          quantity_ == Quantity::irradiance ? h0[c] * v[c] : (h0[c] > 0 ? v[c] : 0);
      px[c] = float(value);
    }
  }
  const double weight = h0.sum();
  if (float* mask = keep_.visibility && weight > 0 ? out_.per_light_visibility.at(output, t.x, t.y)
                                                   : nullptr) {
    mask[0] = float(h0.dot(v) / weight);
    mask[1] = 1.0f;
  }
}

void LightMix::add(Sum& sum, std::size_t light, std::size_t texel, const Vec3& h0, const Vec3& v) {
  sum.h += h0.cwiseProduct(v);
  sum.h0 += h0;
  sum.lights += h0.maxCoeff() > 0;
  keep(light, texel, h0, v);
}

void LightMix::write(std::size_t texel, const Sum& sum) {
  for (std::uint32_t most = most_lights_.load(std::memory_order_relaxed);
       sum.lights > most && !most_lights_.compare_exchange_weak(most, sum.lights);) {
  }
  const Texel& t = space_.texels[texel];
  float* px = out_.image.at(t.x, t.y);
  if (quantity_ == Quantity::visibility && !(sum.h0.maxCoeff() > 0)) return;  // kNoLightCounts
  for (int c = 0; c < 3; ++c) {
    double v = 0;
    if (quantity_ == Quantity::irradiance) {
      v = sum.h[c];
    } else if (sum.h0[c] > 0) {
      v = sum.h[c] / sum.h0[c];
    }
    px[c] = float(v);
  }
}

void LightMix::set(std::size_t light, std::size_t texel, const Vec3& v) {
  const Texel& tx = space_.texels[texel];
  set(light, texel, tx.x, tx.y, v);
}

void LightMix::set(std::size_t light, std::size_t texel, int x, int y, const Vec3& v) {
  if (direct_) {
    float* px = out_.image.at(x, y);
    for (int c = 0; c < 3; ++c) px[c] = lights_[0].exitance()[c] > 0 ? float(v[c]) : 0.0f;
    most_lights_.store(1, std::memory_order_relaxed);
    return;
  }
  // V as a light-by-light method hands it on, in single precision (its field's).
  add(set_sums_[texel], light, texel, unoccluded(light, texel), v.cast<float>().cast<double>());
}

MixedImages LightMix::finish() {
  if (!set_sums_.empty()) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, set_sums_.size(), 1024),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t t = range.begin(); t != range.end(); ++t)
                          write(t, set_sums_[t]);
                      });
    set_sums_ = FreshVector<Sum>();
  }
  // A mesh light's images from its parts' sums: V = Σ H0·V / Σ H0 per channel.
  for (std::size_t o = 0; o < sums_.size(); ++o) {
    for (std::size_t t = 0; t < sums_[o].size(); ++t) {
      const Sum& sum = sums_[o][t];
      if (!(sum.h0.maxCoeff() > 0)) continue;
      Vec3 v = Vec3::Zero();
      for (int c = 0; c < 3; ++c) v[c] = sum.h0[c] > 0 ? sum.h[c] / sum.h0[c] : 0.0;
      keep_output(o, t, sum.h0, v);
    }
  }
  out_.most_lights = most_lights_.load();
  // Visibility across curved receivers' terminators, in every image of V.
  std::vector<std::size_t> every(lights_.size());
  for (std::size_t l = 0; l < every.size(); ++l) every[l] = l;
  if (quantity_ == Quantity::visibility)
    fill_terminators(space_, lights_, every, UncountedMark::value, out_.image, lists_);
  // Each light's images made whole one at a time (beyond its tiles: no light counts), filled
  // over its tiles, and kept by tiles again.
  const std::size_t outputs = std::max(out_.per_light.size(), out_.per_light_visibility.size());
  std::vector<std::vector<std::size_t>> parts_of(outputs);
  for (std::size_t l = 0; l < lights_.size() && outputs > 0; ++l)
    parts_of[std::size_t(lights_[l].output())].push_back(l);
  tbb::parallel_for(std::size_t(0), outputs, [&](std::size_t o) {
    const std::vector<std::size_t>& parts = parts_of[o];
    if (!by_turn_) finish_output(o, parts);
  });
  return std::move(out_);
}

}  // namespace sb
