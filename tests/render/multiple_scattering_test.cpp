// Multiple scattering by the diffusion approximation (Stam 1995, ch. 5.5) against independent
// references: the energy balance recomputed from the solution, the Green's function of the
// screened Poisson equation in an infinite medium, the closed form of Stam's slab problem
// (Fig. 5.15) with Marshak boundaries, and the properties of the multigrid solver.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <utility>

#include "msim/core/rng.hpp"
#include "msim/render/multiple_scattering.hpp"

using namespace msim;
using namespace msim::render;

namespace {

// A smoke-like puff: a ball whose density falls to 0 at radius 0.4 of the box, times per-cell noise
// in [0.2, 1], so the medium has a ragged, thin boundary. Empty outside the ball.
template <int D>
Grid<float, D> noisyBall(int n, std::uint64_t seed) {
  Grid<float, D> rho(GridSpec<D>(Vec<D>::Zero(), 1.0 / n, IVec<D>::Constant(n)));
  Rng rng(seed);
  for (std::size_t i = 0; i < rho.count(); ++i) {
    const double r = (rho.position(rho.coord(i)) - Vec<D>::Constant(0.5)).norm();
    const double profile = std::max(0.0, 1.0 - r / 0.4);
    rho[i] = static_cast<float>(std::sqrt(profile) * rng.uniform(0.2, 1.0));
  }
  return rho;
}

// First-scatter source of a directional light of irradiance E0 travelling along -axis 1 (down),
// with the Beer-Lambert transmittance to each cell centre: q0 = Omega sigma_t rho E0 tau.
template <int D>
Grid<float, D> lightFromAbove(const Grid<float, D>& rho, const DiffusionMedium& m, double E0) {
  Grid<float, D> q(rho.spec());
  const double h = rho.spec().dx;
  const int n = rho.size()[1];
  for (std::size_t i = 0; i < rho.count(); ++i) {
    IVec<D> c = rho.coord(i);
    if (c[1] != n - 1) continue;
    double depth = 0.0;  // optical depth to the top of the current cell
    for (int j = n - 1; j >= 0; --j) {
      c[1] = j;
      const double tau = m.extinction * rho(c) * h;
      q(c) = static_cast<float>(m.albedo * m.extinction * rho(c) * E0 * std::exp(-depth - 0.5 * tau));
      depth += tau;
    }
  }
  return q;
}

double total(const Grid<float, 3>& g) {
  double s = 0.0;
  for (float v : g.data()) s += v;
  return s;
}

// Closed form of the 1D slab [0, l] lit at y = 0 by a beam travelling +y (Stam Fig. 5.15 with a
// uniform beam): kappa phi'' - alpha phi + S0 exp(-beta y) = 0 with S = q0 - w', w = q1 / sigma_tr
// rho = w0 exp(-beta y), and the Marshak conditions (5.24) phi - 2 kappa phi' + 2 w = 0 at y = 0,
// phi + 2 kappa phi' - 2 w = 0 at y = l.
struct Slab {
  double kappa, alpha, beta, q0, w0, l;
  double A = 0, B = 0, C = 0, L = 0;  // phi = A e^{(y-l)/L} + B e^{-y/L} + C e^{-beta y}
  void solve() {
    L = std::sqrt(kappa / alpha);
    C = (q0 + beta * w0) / (alpha - kappa * beta * beta);
    const double El = std::exp(-l / L), Eb = std::exp(-beta * l);
    // y = 0: phi(0) - 2 kappa phi'(0) = -2 w0
    const double a11 = El * (1 - 2 * kappa / L), a12 = 1 + 2 * kappa / L;
    const double r1 = -2 * w0 - C * (1 + 2 * kappa * beta);
    // y = l: phi(l) + 2 kappa phi'(l) = 2 w0 e^{-beta l}
    const double a21 = 1 + 2 * kappa / L, a22 = El * (1 - 2 * kappa / L);
    const double r2 = 2 * w0 * Eb - C * Eb * (1 - 2 * kappa * beta);
    const double det = a11 * a22 - a12 * a21;
    A = (r1 * a22 - a12 * r2) / det;
    B = (a11 * r2 - a21 * r1) / det;
  }
  double operator()(double y) const { return A * std::exp((y - l) / L) + B * std::exp(-y / L) + C * std::exp(-beta * y); }
};

// Grid solution of the slab [0, 1] (rho = 1, optical thickness = extinction) lit at y = 0 by a
// unit beam travelling +y, on N cells across it: q0 = Omega sigma_t exp(-sigma_t y), q1 = g q0 e_y.
// The 2D grid is 2 cells wide with mirror sides, so the problem is exactly one-dimensional.
Grid<float, 2> solveSlab(int N, const DiffusionMedium& m) {
  const GridSpec<2> spec(Vec2::Zero(), 1.0 / N, IVec2(2, N));
  Grid<float, 2> rho(spec, 1.0f), q(spec);
  Grid<Vecf<2>, 2> q1(spec);
  for (std::size_t i = 0; i < q.count(); ++i) {
    const double y = q.position(q.coord(i)).y();
    q[i] = static_cast<float>(m.albedo * m.extinction * std::exp(-m.extinction * y));
    q1[i] = Vecf<2>(0.0f, static_cast<float>(m.phaseG * q[i]));
  }
  DiffusionSettings s;
  s.tolerance = 1e-9;
  s.maxCycles = 100;
  s.reflectingAxes = {true, false, false};
  return solveMultipleScattering<2>(rho, q, m, s, nullptr, &q1);
}

// Max error of the grid slab on N cells against the closed form, relative to the max of phi.
double slabError(int N, double g) {
  const DiffusionMedium m{4.0, 0.9, g};
  Slab slab;
  slab.l = 1.0;
  slab.kappa = 1.0 / (3.0 * m.extinction * (1.0 - m.albedo * g));
  slab.alpha = (1.0 - m.albedo) * m.extinction;
  slab.beta = m.extinction;
  slab.q0 = m.albedo * m.extinction;
  slab.w0 = g * slab.q0 / (m.extinction * (1.0 - m.albedo * g));
  slab.solve();
  const auto phi = solveSlab(N, m);
  double err = 0.0, peak = 0.0;
  for (int j = 0; j < N; ++j) {
    const double exact = slab((j + 0.5) / N);
    err = std::max(err, std::abs(phi(IVec2(0, j)) - exact));
    peak = std::max(peak, exact);
  }
  return err / peak;
}

// Analogue Monte Carlo of the same slab (optical thickness T, unit beam at normal incidence,
// Henyey-Greenstein scattering): the fractions of the beam leaving diffusely back through y = 0
// (reflected) and through y = T (transmitted after at least one scattering).
std::pair<double, double> monteCarloSlab(double T, double albedo, double g, int photons, std::uint64_t seed) {
  Rng rng(seed);
  int reflected = 0, transmitted = 0;
  for (int n = 0; n < photons; ++n) {
    double y = -std::log(1.0 - rng.uniform()), mu = 1.0;  // mu: direction cosine with +y
    if (y > T) continue;                                   // unscattered: not diffuse light
    while (rng.uniform() < albedo) {
      double cosTheta = 2.0 * rng.uniform() - 1.0;
      if (g != 0.0) {
        const double s = (1.0 - g * g) / (1.0 - g + 2.0 * g * rng.uniform());
        cosTheta = (1.0 + g * g - s * s) / (2.0 * g);
      }
      const double azimuth = 2.0 * std::numbers::pi * rng.uniform();
      const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
      mu = mu * cosTheta + std::sqrt(std::max(0.0, 1.0 - mu * mu)) * sinTheta * std::cos(azimuth);
      y -= std::log(1.0 - rng.uniform()) * mu;
      if (y < 0.0 || y > T) {
        (y < 0.0 ? reflected : transmitted) += 1;
        break;
      }
    }
  }
  return {double(reflected) / photons, double(transmitted) / photons};
}

}  // namespace

TEST(MultipleScattering, SourcePowerIsAbsorbedOrEscapes) {
  const DiffusionMedium m{30.0, 0.95, 0.6};
  const auto rho = noisyBall<3>(40, 7);
  const auto q = lightFromAbove(rho, m, 1.0);
  Grid<Vecf<3>, 3> q1(rho.spec());  // forward-peaked first scatter: q1 = g q0 along the light
  for (std::size_t i = 0; i < q.count(); ++i) q1[i] = Vecf<3>(0.0f, -static_cast<float>(m.phaseG) * q[i], 0.0f);
  DiffusionStats st;
  const auto phi = solveMultipleScattering<3>(rho, q, m, DiffusionSettings{}, &st, &q1);
  EXPECT_LE(st.relativeResidual, 1e-4);
  EXPECT_GT(st.absorbedPower, 0.05 * st.sourcePower);
  EXPECT_GT(st.escapedPower, 0.05 * st.sourcePower);
  const double imbalance = std::abs(st.sourcePower - st.absorbedPower - st.escapedPower) / st.sourcePower;
  EXPECT_LT(imbalance, 0.01);
  RecordProperty("imbalance", std::to_string(imbalance));
  std::printf("3D: source %.6g absorbed %.6g escaped %.6g imbalance %.2e, %d cycles\n", st.sourcePower,
              st.absorbedPower, st.escapedPower, imbalance, st.cycles);

  // 2D, isotropic, mirror sides on x.
  const auto rho2 = noisyBall<2>(96, 8);
  const auto q2 = lightFromAbove(rho2, m, 1.0);
  DiffusionSettings s2;
  s2.reflectingAxes = {true, false, false};
  DiffusionStats st2;
  solveMultipleScattering<2>(rho2, q2, DiffusionMedium{30.0, 0.95, 0.0}, s2, &st2);
  const double imbalance2 = std::abs(st2.sourcePower - st2.absorbedPower - st2.escapedPower) / st2.sourcePower;
  EXPECT_LT(imbalance2, 0.01);
  std::printf("2D: source %.6g absorbed %.6g escaped %.6g imbalance %.2e, %d cycles\n", st2.sourcePower,
              st2.absorbedPower, st2.escapedPower, imbalance2, st2.cycles);
}

// A point source of power P in an infinite homogeneous medium: phi(r) = P exp(-r/L) / (4 pi kappa r),
// L = sqrt(kappa / alpha), the Green's function of kappa lap(phi) - alpha phi = -P delta.
TEST(MultipleScattering, PointSourceMatchesTheInfiniteMediumGreensFunction) {
  const int n = 96;
  const DiffusionMedium m{0.25, 0.9, 0.5};  // rho = 1, dx = 1 m: L = 9.9 cells, boundary 48 cells away
  const GridSpec<3> spec(Vec3::Zero(), 1.0, IVec3::Constant(n));
  Grid<float, 3> rho(spec, 1.0f), q(spec);
  const IVec3 centre = IVec3::Constant(n / 2);
  q(centre) = 1.0f;  // P = 1 W in one cell of 1 m^3
  DiffusionSettings s;
  s.tolerance = 1e-7;
  DiffusionStats st;
  const auto phi = solveMultipleScattering<3>(rho, q, m, s, &st);
  const double kappa = 1.0 / (3.0 * m.extinction * (1.0 - m.albedo * m.phaseG));
  const double L = std::sqrt(kappa / ((1.0 - m.albedo) * m.extinction));
  double worst = 0.0;
  for (const IVec3& dir : {IVec3(1, 0, 0), IVec3(0, 1, 1), IVec3(1, 1, 1), IVec3(2, 1, 0)})
    for (int k = 1; k <= 12; ++k) {
      const IVec3 c = centre + k * dir;
      const double r = (c - centre).cast<double>().norm();
      // From 4 cells out to ~L: at 3 cells the 7-point stencil's own anisotropy (its lattice Green's
      // function) is 5% off on the axes, 2% on the diagonals; it falls as 1 / r^2.
      if (r < 4.0 || r > L + 2.0) continue;
      const double exact = std::exp(-r / L) / (4.0 * std::numbers::pi * kappa * r);
      const double err = std::abs(phi(c) / exact - 1.0);
      worst = std::max(worst, err);
      EXPECT_LT(err, 0.05) << "r = " << r;
    }
  std::printf("point source: L = %.2f cells, worst relative error %.4f, %d cycles\n", L, worst, st.cycles);
}

// Stam's slab (Fig. 5.15), uniform beam: within 0.5% at 512 cells, second order under refinement.
TEST(MultipleScattering, SlabMatchesTheClosedFormAtSecondOrder) {
  for (const double g : {0.0, 0.5}) {
    const double e512 = slabError(512, g);
    EXPECT_LT(e512, 0.005) << "g = " << g;
    double coarse = slabError(32, g);
    std::printf("slab g = %.1f: error(32) %.3e", g, coarse);
    for (const int N : {64, 128, 256}) {
      const double fine = slabError(N, g);
      const double order = std::log2(coarse / fine);
      std::printf(", error(%d) %.3e (order %.2f)", N, fine, order);
      EXPECT_NEAR(order, 2.0, 0.2) << "g = " << g << ", N = " << N;
      coarse = fine;
    }
    std::printf(", error(512) %.3e\n", e512);
  }
}

// The diffusion approximation against transport itself: diffuse reflectance and transmittance of a
// thick, high-albedo slab from Monte Carlo (40000 photons, ~1-2% noise). This pins the diffusion
// constant kappa = 1 / (3 sigma_tr rho): Stam's printed 1 / (sigma_tr rho) transmits 0.205 instead
// of 0.12 for g = 0. With g = 0.5 it also checks sigma_tr and the first-scatter flux q1.
TEST(MultipleScattering, SlabReflectanceAndTransmittanceMatchMonteCarloTransport) {
  const int N = 256;
  for (const double g : {0.0, 0.5}) {
    const DiffusionMedium m{8.0, 0.99, g};
    const auto [mcR, mcT] = monteCarloSlab(m.extinction, m.albedo, g, 40000, 17);
    const auto phi = solveSlab(N, m);
    // Outgoing flux through the Marshak faces, (2 kappa phi_c + h w.n) / (h + 4 kappa).
    const double h = 1.0 / N, kappa = 1.0 / (3.0 * m.extinction * (1.0 - m.albedo * g));
    const double w0 = g * m.albedo / (1.0 - m.albedo * g);  // w = q1 / (sigma_tr rho) at y = 0
    const double wBottom = w0 * std::exp(-m.extinction * 0.5 * h), wTop = w0 * std::exp(-m.extinction * (1 - 0.5 * h));
    const double R = (2 * kappa * phi(IVec2(0, 0)) - h * wBottom) / (h + 4 * kappa);
    const double T = (2 * kappa * phi(IVec2(0, N - 1)) + h * wTop) / (h + 4 * kappa);
    std::printf("slab g = %.1f: reflectance %.4f (Monte Carlo %.4f), transmittance %.4f (Monte Carlo %.4f)\n", g, R,
                mcR, T, mcT);
    EXPECT_NEAR(R / mcR, 1.0, 0.05) << "g = " << g;
    EXPECT_NEAR(T / mcT, 1.0, 0.06) << "g = " << g;
  }
}

// Mean residual reduction per V-cycle, from the residuals after 1 and 6 cycles.
template <int D>
double reductionPerCycle(const Grid<float, D>& rho, const Grid<float, D>& q, const DiffusionMedium& m) {
  DiffusionSettings s;
  s.tolerance = 0.0;
  DiffusionStats one, six;
  s.maxCycles = 1;
  solveMultipleScattering<D>(rho, q, m, s, &one);
  s.maxCycles = 6;
  solveMultipleScattering<D>(rho, q, m, s, &six);
  return std::pow(six.relativeResidual / one.relativeResidual, 1.0 / 5.0);
}

TEST(MultipleScattering, VCycleReducesTheResidualFivefold) {
  const DiffusionMedium m{30.0, 0.95, 0.3};
  const int n = 64;
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / n, IVec3::Constant(n));
  Grid<float, 3> ball(spec);  // constant density in a ball, Marshak boundary on its surface
  for (std::size_t i = 0; i < ball.count(); ++i)
    ball[i] = (ball.position(ball.coord(i)) - Vec3::Constant(0.5)).norm() < 0.4 ? 1.0f : 0.0f;
  const double homogeneous = reductionPerCycle<3>(ball, lightFromAbove(ball, m, 1.0), m);
  const auto puff = noisyBall<3>(n, 3);
  const double noisy = reductionPerCycle<3>(puff, lightFromAbove(puff, m, 1.0), m);
  const auto puff2 = noisyBall<2>(256, 4);
  const double noisy2 = reductionPerCycle<2>(puff2, lightFromAbove(puff2, m, 1.0), m);
  std::printf("reduction per V-cycle: 3D ball %.3f, 3D noisy puff %.3f, 2D noisy puff %.3f\n", homogeneous, noisy,
              noisy2);
  EXPECT_LT(homogeneous, 0.2);
  EXPECT_LT(noisy, 0.2);
  EXPECT_LT(noisy2, 0.2);
}

TEST(MultipleScattering, NonNegativeSourcesGiveNonNegativeFluence) {
  const auto rho = noisyBall<2>(128, 11);
  Grid<float, 2> q(rho.spec());
  Rng rng(12);
  for (float& v : q.data()) v = rng.uniform() < 0.3 ? static_cast<float>(rng.uniform(0.0, 100.0)) : 0.0f;
  for (const double g : {-0.5, 0.0, 0.8}) {
    const auto phi = solveMultipleScattering<2>(rho, q, DiffusionMedium{50.0, 0.99, g}, DiffusionSettings{});
    for (std::size_t i = 0; i < phi.count(); ++i) ASSERT_GE(phi[i], 0.0f) << "g = " << g;
  }
}

// Fig. 5.21's trend: with sigma_t fixed, more albedo means more diffuse light, whether the
// first-scatter source grows with the albedo (a lit puff) or is held fixed.
TEST(MultipleScattering, MoreAlbedoMoreDiffuseLight) {
  const auto rho = noisyBall<3>(32, 5);
  const auto fixedSource = lightFromAbove(rho, DiffusionMedium{20.0, 0.5, 0.0}, 1.0);
  double lastLit = 0.0, lastFixed = 0.0, lastEscaped = 0.0;
  for (const double albedo : {0.3, 0.6, 0.9, 0.99}) {
    const DiffusionMedium m{20.0, albedo, 0.0};
    DiffusionStats st;
    const double lit = total(solveMultipleScattering<3>(rho, lightFromAbove(rho, m, 1.0), m, {}, &st));
    const double fixed = total(solveMultipleScattering<3>(rho, fixedSource, m, {}));
    EXPECT_GT(lit, lastLit) << albedo;
    EXPECT_GT(fixed, lastFixed) << albedo;
    EXPECT_GT(st.escapedPower, lastEscaped) << albedo;
    lastLit = lit;
    lastFixed = fixed;
    lastEscaped = st.escapedPower;
  }
}

TEST(MultipleScattering, RejectsMismatchedGridsAndBadMedia) {
  const Grid<float, 2> rho(GridSpec<2>(Vec2::Zero(), 0.1, IVec2(8, 8)), 1.0f);
  const Grid<float, 2> other(GridSpec<2>(Vec2::Zero(), 0.1, IVec2(8, 4)));
  EXPECT_THROW(solveMultipleScattering<2>(rho, other, {}, {}), std::invalid_argument);
  EXPECT_THROW(solveMultipleScattering<2>(rho, rho, DiffusionMedium{10.0, 1.5, 0.0}, {}), std::invalid_argument);
  EXPECT_THROW(solveMultipleScattering<2>(rho, rho, DiffusionMedium{0.0, 0.5, 0.0}, {}), std::invalid_argument);
}
