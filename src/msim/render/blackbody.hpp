#pragma once
// Colour and brightness of a black body, for fire (Stam ch. 5.1: the gas emits like a black body,
// with a radiance that grows as T^4 by the Stefan-Boltzmann law). Planck's spectrum is integrated
// against the CIE 1931 2-degree colour-matching functions (the multi-lobe Gaussian fit of Wyman,
// Sloan and Shirley, JCGT 2013) and converted to linear sRGB (D65 white).
#include <array>
#include <vector>

#include "msim/core/vec.hpp"

namespace msim::render {

// CIE XYZ of Planck's spectrum at temperature T [K], scaled to Y = 1.
Vec3 blackbodyXyz(double temperature);
// (x, y) chromaticity of a black body.
Vec2 blackbodyChromaticity(double temperature);
// Linear sRGB of a black body with luminance 1; components outside the sRGB gamut are clipped to 0.
std::array<float, 3> blackbodyLinearSrgb(double temperature);

// Linear sRGB emission colour times the T^4 brightness relative to `reference` [K], tabulated:
// evaluating Planck's integral per voxel would cost more than the whole preview.
class BlackbodyTable {
 public:
  explicit BlackbodyTable(double reference = 1500.0, double maxTemperature = 6000.0);
  // Zero below 400 K (nothing visible), clamped at maxTemperature.
  std::array<float, 3> operator()(double temperature) const;

 private:
  double step_, maxTemperature_;
  std::vector<std::array<float, 3>> table_;
};

}  // namespace msim::render
