#include "scene/sky_models.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "scene/sky.h"

namespace sb {

namespace {

constexpr double pi = std::numbers::pi;

// Perez et al.'s sky distribution, F(θ, γ) = (1 + A e^(B / cos θ)) (1 + C e^(D γ) + E cos² γ),
// for θ the angle from the zenith and γ the angle from the sun.
using Perez = std::array<double, 5>;
double perez(const Perez& c, double theta, double gamma) {
  const double cg = std::cos(gamma);
  return (1 + c[0] * std::exp(c[1] / std::cos(theta))) *
         (1 + c[2] * std::exp(c[3] * gamma) + c[4] * cg * cg);
}

// The paper's fit (its appendix): each coefficient linear in the turbidity T, for the luminance
// Y and the chromaticities x and y.
Perez luminance_coefficients(double t) {
  return {0.1787 * t - 1.4630, -0.3554 * t + 0.4275, -0.0227 * t + 5.3251, 0.1206 * t - 2.5771,
          -0.0670 * t + 0.3703};
}
Perez x_coefficients(double t) {
  return {-0.0193 * t - 0.2592, -0.0665 * t + 0.0008, -0.0004 * t + 0.2125, -0.0641 * t - 0.8989,
          -0.0033 * t + 0.0452};
}
Perez y_coefficients(double t) {
  return {-0.0167 * t - 0.2608, -0.0950 * t + 0.0092, -0.0079 * t + 0.2102, -0.0441 * t - 1.6537,
          -0.0109 * t + 0.0529};
}

// The zenith's chromaticity: a cubic in the sun's zenith angle per power of T (the appendix's
// matrices, each row a polynomial in θs).
double zenith_chromaticity(const std::array<std::array<double, 4>, 3>& m, double t, double ts) {
  const std::array<double, 3> powers_t = {t * t, t, 1};
  double value = 0;
  for (std::size_t i = 0; i < 3; ++i)
    value += powers_t[i] * (((m[i][0] * ts + m[i][1]) * ts + m[i][2]) * ts + m[i][3]);
  return value;
}

// Blender's Preetham sky scales the zenith luminance (kcd/m² in the paper) by 0.06.
constexpr double kBlenderScale = 0.06;
// How far below the horizon the zenith angle is held (Blender's: θ ≤ π/2 − 0.001), so that
// 1 / cos θ stays finite and the sky below the horizon is the horizon's.
constexpr double kHorizonMargin = 1e-3;

// CIE XYZ to linear Rec.709 RGB (D65 white), the scene-linear space of the lightmaps.
Vec3 xyz_to_rec709(const Vec3& xyz) {
  Mat3 m;
  m << 3.2404542, -1.5371385, -0.4985314,  //
      -0.9692660, 1.8760108, 0.0415560,    //
      0.0556434, -0.2040259, 1.0572252;
  return m * xyz;
}

// The parts of the model that depend on the sun alone: the zenith's Y, x, y divided by F at the
// zenith (θ = 0, γ = θs), and the coefficients.
struct Zenith {
  Perez cy, cx, cyy;
  double y = 0, x = 0, yy = 0;  // Y, x and y over F(0, θs)
};

Zenith zenith(const Vec3& sun, double t) {
  const double ts = std::acos(std::clamp(sun.z(), 0.0, 1.0));
  const double chi = (4.0 / 9.0 - t / 120) * (pi - 2 * ts);
  Zenith z;
  z.cy = luminance_coefficients(t);
  z.cx = x_coefficients(t);
  z.cyy = y_coefficients(t);
  const double luminance =
      kBlenderScale * ((4.0453 * t - 4.9710) * std::tan(chi) - 0.2155 * t + 2.4192);
  const double x = zenith_chromaticity({{{0.00166, -0.00375, 0.00209, 0},
                                         {-0.02903, 0.06377, -0.03202, 0.00394},
                                         {0.11693, -0.21196, 0.06052, 0.25886}}},
                                       t, ts);
  const double y = zenith_chromaticity({{{0.00275, -0.00610, 0.00317, 0},
                                         {-0.04214, 0.08970, -0.04153, 0.00516},
                                         {0.15346, -0.26756, 0.06670, 0.26688}}},
                                       t, ts);
  z.y = luminance / perez(z.cy, 0, ts);
  z.x = x / perez(z.cx, 0, ts);
  z.yy = y / perez(z.cyy, 0, ts);
  return z;
}

Vec3 radiance(const Zenith& z, const Vec3& sun, const Vec3& d) {
  const double theta = std::min(std::acos(std::clamp(d.z(), -1.0, 1.0)), pi / 2 - kHorizonMargin);
  const double gamma = std::acos(std::clamp(d.dot(sun), -1.0, 1.0));
  const double luminance = z.y * perez(z.cy, theta, gamma);
  const double x = z.x * perez(z.cx, theta, gamma);
  const double y = z.yy * perez(z.cyy, theta, gamma);
  if (!(y > 0) || !(luminance > 0)) return Vec3::Zero();
  const Vec3 xyz(x * luminance / y, luminance, (1 - x - y) * luminance / y);
  return xyz_to_rec709(xyz).cwiseMax(0.0);
}

}  // namespace

Vec3 preetham_radiance(const Vec3& sun, double turbidity, const Vec3& d) {
  return radiance(zenith(sun, turbidity), sun, d);
}

Image preetham_map(const Vec3& sun, double turbidity, int width, int height) {
  const Zenith z = zenith(sun, turbidity);
  Image map(width, height, 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const Vec3 d = equirectangular_direction((x + 0.5) / width, 1 - (y + 0.5) / height);
      const Vec3 c = radiance(z, sun, d);
      float* p = map.at(x, y);
      for (int k = 0; k < 3; ++k) p[k] = float(c[k]);
    }
  return map;
}

}  // namespace sb
