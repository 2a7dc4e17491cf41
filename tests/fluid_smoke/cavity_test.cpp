// Lid-driven cavity (unit square, lid u = 1 at y = 1, no-slip walls) against the centreline
// velocities of Ghia, Ghia & Shin, J. Comput. Phys. 48 (1982) 387-411, Tables I and II.
// Re = U L / nu with U = L = 1. The 128^2 runs (issue acceptance: max deviation < 0.02 at Re 100)
// take minutes, so they are disabled here and run by hand:
//   test_fluid_smoke --gtest_also_run_disabled_tests --gtest_filter='*Cavity128*'
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <tuple>

#include "msim/fluid/smoke/smoke_solver.hpp"

using namespace msim;
using namespace msim::fluid;

namespace {

constexpr int kPoints = 17;
struct GhiaTable {
  int re;
  std::array<double, kPoints> u;  // u(x = 0.5, y = kY[i])
  std::array<double, kPoints> v;  // v(x = kX[i], y = 0.5)
  int skipV = -1;                 // a v entry left out of the comparison
};
constexpr std::array<double, kPoints> kY = {1.0000, 0.9766, 0.9688, 0.9609, 0.9531, 0.8516, 0.7344, 0.6172, 0.5000,
                                            0.4531, 0.2813, 0.1719, 0.1016, 0.0703, 0.0625, 0.0547, 0.0000};
constexpr std::array<double, kPoints> kX = {1.0000, 0.9688, 0.9609, 0.9531, 0.9453, 0.9063, 0.8594, 0.8047, 0.5000,
                                            0.2344, 0.2266, 0.1563, 0.0938, 0.0781, 0.0703, 0.0625, 0.0000};
constexpr GhiaTable kRe100{100,
                           {1.00000, 0.84123, 0.78871, 0.73722, 0.68717, 0.23151, 0.00332, -0.13641, -0.20581,
                            -0.21090, -0.15662, -0.10150, -0.06434, -0.04775, -0.04192, -0.03717, 0.00000},
                           {0.00000, -0.05906, -0.07391, -0.08864, -0.10313, -0.16914, -0.22445, -0.24533, 0.05454,
                            0.17527, 0.17507, 0.16077, 0.12317, 0.10890, 0.10091, 0.09233, 0.00000}};
constexpr GhiaTable kRe400{400,
                           {1.00000, 0.75837, 0.68439, 0.61756, 0.55892, 0.29093, 0.16256, 0.02135, -0.11477,
                            -0.17119, -0.32726, -0.24299, -0.14612, -0.10338, -0.09266, -0.08186, 0.00000},
                           {0.00000, -0.12146, -0.15663, -0.19254, -0.22847, -0.23827, -0.44993, -0.38598, 0.05188,
                            0.30174, 0.30203, 0.28124, 0.22965, 0.20920, 0.19713, 0.18360, 0.00000},
                           // v(0.9063) = -0.23827 breaks the monotone run of its neighbours
                           // (-0.22847 at 0.9453, -0.44993 at 0.8594); left out as a misprint
                           // (in the table or in this transcription of it).
                           5};
constexpr GhiaTable kRe1000{1000,
                            {1.00000, 0.65928, 0.57492, 0.51117, 0.46604, 0.33304, 0.18719, 0.05702, -0.06080,
                             -0.10648, -0.27805, -0.38289, -0.29730, -0.22220, -0.20196, -0.18109, 0.00000},
                            {0.00000, -0.21388, -0.27669, -0.33714, -0.39188, -0.51550, -0.42665, -0.31966, 0.02526,
                             0.32235, 0.33075, 0.37095, 0.32627, 0.30353, 0.29012, 0.27485, 0.00000}};

// Linear interpolation of samples at (k + 0.5) h, k = 0..n-1, extended by the wall values at 0 and 1.
template <typename F>
double profile(int n, F sample, double lower, double upper, double s) {
  const double t = s * n - 0.5;
  if (t <= 0.0) return lower + (sample(0) - lower) * (s * n / 0.5);
  if (t >= n - 1) return sample(n - 1) + (upper - sample(n - 1)) * ((t - (n - 1)) / 0.5);
  const int k = static_cast<int>(t);
  return sample(k) + (sample(k + 1) - sample(k)) * (t - k);
}

struct CavityResult {
  double maxDeviation;  // max over both centrelines of |u - u_Ghia|
  double change;        // max |du| over the last 0.5 s (steadiness)
};

CavityResult runCavity(int n, const GhiaTable& ref, double endTime, numerics::AdvectionScheme scheme) {
  const GridSpec<2> spec(Vec2::Zero(), 1.0 / n, IVec2(n, n));
  SmokeParams<2> p;
  p.advection.scheme = scheme;
  p.viscosity = 1.0 / ref.re;
  p.wallVelocity[1][1] = Vec2(1.0, 0.0);  // the lid
  p.cfl = 1.0;
  SmokeSolver<2> s(spec, p);
  const auto& u = s.velocity().component(0);
  const auto& v = s.velocity().component(1);
  auto uCentre = [&](int j) { return static_cast<double>(u(IVec2(n / 2, j))); };
  auto vCentre = [&](int i) { return static_cast<double>(v(IVec2(i, n / 2))); };
  std::vector<float> before;
  double t = 0.0;
  const double maxDt = spec.dx;  // the lid drives at speed 1 before the interior moves
  while (t < endTime - 1e-12) {
    if (before.empty() && t >= endTime - 0.5) before = u.data();
    const double dt = std::min({maxDt, s.cflTimestep(), endTime - t});
    s.step(dt);
    t += dt;
  }
  CavityResult r{0.0, 0.0};
  for (std::size_t i = 0; i < before.size(); ++i) r.change = std::max(r.change, double(std::abs(u[i] - before[i])));
  const char* worst = "";
  double worstAt = 0.0;
  for (int k = 0; k < kPoints; ++k) {
    const double du = std::abs(profile(n, uCentre, 0.0, 1.0, kY[k]) - ref.u[k]);
    const double dv = k == ref.skipV ? 0.0 : std::abs(profile(n, vCentre, 0.0, 0.0, kX[k]) - ref.v[k]);
    if (du > r.maxDeviation) std::tie(r.maxDeviation, worst, worstAt) = std::tuple(du, "u at y", kY[k]);
    if (dv > r.maxDeviation) std::tie(r.maxDeviation, worst, worstAt) = std::tuple(dv, "v at x", kX[k]);
  }
  std::printf("cavity Re=%d n=%d t=%.0f: max deviation from Ghia %.4f (%s = %.4f), max |du| over last 0.5 s %.2e\n",
              ref.re, n, endTime, r.maxDeviation, worst, worstAt, r.change);
  return r;
}

}  // namespace

TEST(Cavity, Re100At64MatchesGhia) {
  const CavityResult r = runCavity(64, kRe100, 15.0, numerics::AdvectionScheme::MacCormack);
  EXPECT_LT(r.change, 1e-3);  // steady
  EXPECT_LT(r.maxDeviation, 0.015);  // measured 0.0057
}

TEST(Cavity, DISABLED_Cavity128Re100) {
  EXPECT_LT(runCavity(128, kRe100, 20.0, numerics::AdvectionScheme::MacCormack).maxDeviation, 0.02);
}

TEST(Cavity, DISABLED_Cavity128Re400) {
  EXPECT_LT(runCavity(128, kRe400, 30.0, numerics::AdvectionScheme::MacCormack).maxDeviation, 0.05);
}

TEST(Cavity, DISABLED_Cavity128Re1000) {
  EXPECT_LT(runCavity(128, kRe1000, 40.0, numerics::AdvectionScheme::MacCormack).maxDeviation, 0.08);
}
