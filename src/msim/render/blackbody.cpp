#include "msim/render/blackbody.hpp"

#include <algorithm>
#include <cmath>

namespace msim::render {

namespace {

// Piecewise Gaussian lobe of the Wyman-Sloan-Shirley fit (wavelength in nm).
double lobe(double lambda, double mean, double sigmaBelow, double sigmaAbove) {
  const double t = (lambda - mean) / (lambda < mean ? sigmaBelow : sigmaAbove);
  return std::exp(-0.5 * t * t);
}

Vec3 colourMatching(double lambda) {
  return {1.056 * lobe(lambda, 599.8, 37.9, 31.0) + 0.362 * lobe(lambda, 442.0, 16.0, 26.7) -
              0.065 * lobe(lambda, 501.1, 20.4, 26.2),
          0.821 * lobe(lambda, 568.8, 46.9, 40.5) + 0.286 * lobe(lambda, 530.9, 16.3, 31.1),
          1.217 * lobe(lambda, 437.0, 11.8, 36.0) + 0.681 * lobe(lambda, 459.0, 26.0, 13.8)};
}

// Planck's spectral radiance up to a constant factor (which the Y = 1 scaling removes).
double planck(double lambdaNm, double temperature) {
  constexpr double kSecondRadiation = 1.4387769e7;  // h c / k_B [nm K]
  const double l = lambdaNm * 1e-3;                 // micrometres keep the numbers tame
  return 1.0 / (l * l * l * l * l * std::expm1(kSecondRadiation / (lambdaNm * temperature)));
}

}  // namespace

Vec3 blackbodyXyz(double temperature) {
  Vec3 xyz = Vec3::Zero();
  for (double lambda = 360.0; lambda <= 830.0; lambda += 1.0) xyz += planck(lambda, temperature) * colourMatching(lambda);
  return xyz / xyz.y();
}

Vec2 blackbodyChromaticity(double temperature) {
  const Vec3 xyz = blackbodyXyz(temperature);
  return Vec2(xyz.x(), xyz.y()) / xyz.sum();
}

std::array<float, 3> blackbodyLinearSrgb(double temperature) {
  const Vec3 c = blackbodyXyz(temperature);
  const double r = 3.2406 * c.x() - 1.5372 * c.y() - 0.4986 * c.z();
  const double g = -0.9689 * c.x() + 1.8758 * c.y() + 0.0415 * c.z();
  const double b = 0.0557 * c.x() - 0.2040 * c.y() + 1.0570 * c.z();
  return {static_cast<float>(std::max(r, 0.0)), static_cast<float>(std::max(g, 0.0)),
          static_cast<float>(std::max(b, 0.0))};
}

BlackbodyTable::BlackbodyTable(double reference, double maxTemperature)
    : step_(10.0), maxTemperature_(maxTemperature) {
  const int n = static_cast<int>(maxTemperature / step_) + 1;
  table_.resize(n);
  for (int i = 0; i < n; ++i) {
    const double T = i * step_;
    if (T < 400.0) {
      table_[i] = {0.0f, 0.0f, 0.0f};
      continue;
    }
    const double brightness = std::pow(T / reference, 4.0);
    auto c = blackbodyLinearSrgb(T);
    for (float& v : c) v = static_cast<float>(v * brightness);
    table_[i] = c;
  }
}

std::array<float, 3> BlackbodyTable::operator()(double temperature) const {
  const double t = std::clamp(temperature, 0.0, maxTemperature_) / step_;
  const int i = std::min(static_cast<int>(t), static_cast<int>(table_.size()) - 2);
  const float f = static_cast<float>(t - i);
  std::array<float, 3> c;
  for (int ch = 0; ch < 3; ++ch) c[ch] = (1.0f - f) * table_[i][ch] + f * table_[i + 1][ch];
  return c;
}

}  // namespace msim::render
