// LightMix (baselines.h): the one place the baselines combine lights, as the reference does.
#include "methods/baselines.h"

namespace sb {

LightMix::LightMix(const TexelSpace& space, const std::vector<Light>& lights, Quantity quantity)
    : space_(space),
      lights_(lights),
      quantity_(quantity),
      weighted_(lights.size() > 1 || quantity == Quantity::irradiance),
      sum_(space.width, space.height, 3, 0.0f),
      weight_sum_(space.texels.size(), Vec3f::Zero()) {}

void LightMix::add(std::size_t light, std::size_t t, const Vec3& v) {
  const Texel& tx = space_.texels[t];
  const Light& l = lights_[light];
  // One light's visibility needs no closed form: its weight is its exitance where it reaches the
  // texel, so that a channel it does not emit stays 0.
  Vec3 w;
  if (weighted_) {
    w = l.unoccluded_irradiance(tx.position.cast<double>(), tx.normal.cast<double>());
  } else {
    w = l.reaches(tx.position.cast<double>(), tx.normal.cast<double>()) ? l.exitance()
                                                                         : Vec3::Zero();
  }
  float* px = sum_.at(tx.x, tx.y);
  for (int c = 0; c < 3; ++c) px[c] += float(w[c] * v[c]);
  weight_sum_[t] += w.cast<float>();
}

Image LightMix::finish() {
  if (quantity_ == Quantity::visibility) {
    for (std::size_t t = 0; t < space_.texels.size(); ++t) {
      float* px = sum_.at(space_.texels[t].x, space_.texels[t].y);
      for (int c = 0; c < 3; ++c)
        px[c] = weight_sum_[t][c] > 0 ? px[c] / weight_sum_[t][c] : 0.0f;
    }
  }
  return std::move(sum_);
}

}  // namespace sb
