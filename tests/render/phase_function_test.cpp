// Henyey-Greenstein with Stam's 4 pi normalisation (eq. 5.2): (1/4pi) integral over the sphere is 1
// and the mean cosine is g, by an independent quadrature over the sphere.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "expect_invalid.hpp"
#include "msim/render/phase_function.hpp"

using namespace msim::render;

namespace {

// (1/4pi) integral over the sphere of f(mu) dOmega = (1/2) integral_{-1}^{1} f(mu) dmu, by composite
// Simpson in the variable v = log(1 + g^2 - 2 g mu) for g != 0, in which the forward peak of a
// strongly anisotropic p is smooth (p dmu = -(1-g^2)/(2g) e^(-v/2) dv), and in mu for g = 0.
template <typename F>
double sphereMean(double g, F&& f) {
  const int n = 20000;  // even
  if (g == 0.0) {
    double s = 0.0;
    for (int i = 0; i <= n; ++i) s += (i == 0 || i == n ? 1 : (i % 2 ? 4 : 2)) * f(-1.0 + 2.0 * i / n);
    return 0.5 * s * (2.0 / n) / 3.0;
  }
  const double v0 = std::log((1 + g) * (1 + g)), v1 = std::log((1 - g) * (1 - g));  // mu = -1 .. 1
  const double h = (v1 - v0) / n;
  double s = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double v = v0 + i * h;
    const double mu = (1 + g * g - std::exp(v)) / (2 * g);
    const double dmuDv = -std::exp(v) / (2 * g);
    s += (i == 0 || i == n ? 1 : (i % 2 ? 4 : 2)) * f(mu) * dmuDv;
  }
  return 0.5 * s * h / 3.0;
}

}  // namespace

TEST(HenyeyGreenstein, IntegratesToFourPiAndHasMeanCosineG) {
  for (double g : {-0.9, -0.5, 0.0, 0.3, 0.76, 0.95}) {
    const HenyeyGreenstein p(g);
    EXPECT_NEAR(sphereMean(g, [&](double mu) { return p(mu); }), 1.0, 1e-9) << "g = " << g;
    EXPECT_NEAR(sphereMean(g, [&](double mu) { return mu * p(mu); }), g, 1e-9) << "g = " << g;
    // Stam's first moment mu_bar = (3/2) integral mu p dmu = 3 (1/2) integral mu p dmu = 3 g.
    EXPECT_NEAR(asymmetryFromStamMoment(3.0 * sphereMean(g, [&](double mu) { return mu * p(mu); })), g, 1e-9);
  }
}

TEST(HenyeyGreenstein, IntegratesToFourPiOverDirectionsAroundAnArbitraryAxis) {
  // A plain (theta, phi) midpoint quadrature over the sphere with the incident direction off the
  // pole, evaluating p at the dot product of unit vectors as the renderer does.
  const double g = 0.6;
  const HenyeyGreenstein p(g);
  const double in[3] = {0.48, -0.6, 0.64};  // unit
  const int nt = 2000, np = 400;
  double integral = 0.0, meanCos = 0.0;
  for (int i = 0; i < nt; ++i) {
    const double theta = (i + 0.5) * std::numbers::pi / nt;
    for (int j = 0; j < np; ++j) {
      const double phi = (j + 0.5) * 2.0 * std::numbers::pi / np;
      const double s[3] = {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
      const double mu = in[0] * s[0] + in[1] * s[1] + in[2] * s[2];
      const double w = std::sin(theta) * (std::numbers::pi / nt) * (2.0 * std::numbers::pi / np);
      integral += p(mu) * w;
      meanCos += mu * p(mu) * w;
    }
  }
  EXPECT_NEAR(integral / (4.0 * std::numbers::pi), 1.0, 1e-4);
  EXPECT_NEAR(meanCos / (4.0 * std::numbers::pi), g, 1e-4);
}

TEST(HenyeyGreenstein, IsotropicForZeroAndPeaksForward) {
  const HenyeyGreenstein iso(0.0);
  for (double mu : {-1.0, -0.3, 0.0, 0.7, 1.0}) EXPECT_DOUBLE_EQ(iso(mu), 1.0);
  const HenyeyGreenstein forward(0.8);
  EXPECT_NEAR(forward(1.0), 1.8 / (0.2 * 0.2), 1e-12);  // (1 + g) / (1 - g)^2
  EXPECT_GT(forward(1.0), forward(0.0));
  EXPECT_GT(forward(0.0), forward(-1.0));
}

TEST(HenyeyGreenstein, RejectsAsymmetryOutsideTheOpenInterval) {
  for (double g : {-1.0, 1.0, 1.5, std::nan("")}) expectInvalidArgument([&] { HenyeyGreenstein{g}; }, "(-1, 1)");
  expectInvalidArgument([] { asymmetryFromStamMoment(3.0); }, "mu_bar");
  EXPECT_DOUBLE_EQ(asymmetryFromStamMoment(2.25), 0.75);
}
