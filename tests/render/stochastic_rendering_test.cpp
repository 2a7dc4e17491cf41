// Stochastic rendering (Stam ch. 5.6, seed notes T16) against Monte Carlo:
//  - the variance of the line integral of a homogeneous Gaussian random field (eq. 5.27) and the
//    expected transparency exp(-sigma_t M + sigma_t^2 V / 2), over realisations of the field along
//    a ray (Gaussian correlation: eigen-decomposition square root of the covariance matrix;
//    exponential: the exact AR(1) recursion);
//  - Stam's per-blob variance (eq. 5.29) against realisations of a quasi-homogeneous blob (eq. 5.26)
//    with a short correlation; the clamped integral against quadrature; V = 0 is Beer-Lambert.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include "expect_invalid.hpp"
#include "msim/core/rng.hpp"
#include "msim/render/stochastic_rendering.hpp"

using namespace msim;
using namespace msim::render;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Trapezoid integral of samples at spacing h.
double trapezoid(const Eigen::VectorXd& f, double h) { return h * (f.sum() - 0.5 * (f[0] + f[f.size() - 1])); }

struct MonteCarlo {
  double meanTransparency = 0.0, varianceOfDepth = 0.0;
};

// Realisations of rho = meanDensity + q on [0, L], q of standard deviation sd and correlation c.
MonteCarlo sampleHomogeneous(const Correlation& c, double meanDensity, double sd, double L, double sigmaT, int n,
                             int realisations) {
  const double h = L / (n - 1);
  Rng rng(11);
  Eigen::MatrixXd root;  // covariance = root root^T (Gaussian correlation only)
  if (c.kind == Correlation::Kind::Gaussian) {
    Eigen::MatrixXd C(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) C(i, j) = sd * sd * c((i - j) * h);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(C);
    root = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
  }
  const double a = std::exp(-h / c.length);  // AR(1) step of the exponential correlation
  double sumT = 0.0, sumG = 0.0, sumG2 = 0.0;
  Eigen::VectorXd q(n), xi(n);
  for (int r = 0; r < realisations; ++r) {
    for (int i = 0; i < n; ++i) xi[i] = rng.normal();
    if (c.kind == Correlation::Kind::Gaussian) {
      q = root * xi;
    } else {
      q[0] = sd * xi[0];
      for (int i = 1; i < n; ++i) q[i] = a * q[i - 1] + sd * std::sqrt(1.0 - a * a) * xi[i];
    }
    const double gamma = meanDensity * L + trapezoid(q, h);
    sumT += std::exp(-sigmaT * gamma);
    sumG += gamma;
    sumG2 += gamma * gamma;
  }
  const double mean = sumG / realisations;
  return {sumT / realisations, sumG2 / realisations - mean * mean};
}

}  // namespace

TEST(StochasticRendering, ExpectedTransparencyMatchesMonteCarlo) {
  const double L = 1.0, rhoBar = 0.5, sd = 0.5, sigmaT = 2.0;
  for (const Correlation c : {Correlation{Correlation::Kind::Gaussian, 0.1}, Correlation{Correlation::Kind::Exponential, 0.1}}) {
    const OpticalDepthStatistics st = homogeneousSegmentStatistics(rhoBar, sd, c, L);
    const MonteCarlo mc = sampleHomogeneous(c, rhoBar, sd, L, sigmaT, c.kind == Correlation::Kind::Gaussian ? 101 : 1001, 20000);
    const double expected = expectedTransparency(sigmaT, st), beer = std::exp(-sigmaT * st.mean);
    EXPECT_NEAR(mc.varianceOfDepth / st.variance, 1.0, 0.04);
    EXPECT_NEAR(mc.meanTransparency / expected, 1.0, 0.01);
    EXPECT_GT(expected / beer, 1.05);  // the test tells the variance term from Beer-Lambert of the mean
    std::printf("%s correlation, l = %.2f: Var Gamma %.5f (Monte Carlo %.5f, %+.2f%%), E[tau] %.5f (Monte Carlo %.5f, "
                "%+.2f%%), Beer-Lambert of the mean %.5f\n",
                c.kind == Correlation::Kind::Gaussian ? "Gaussian" : "exponential", c.length, st.variance,
                mc.varianceOfDepth, 100.0 * (mc.varianceOfDepth / st.variance - 1.0), expected, mc.meanTransparency,
                100.0 * (mc.meanTransparency / expected - 1.0), beer);
  }
}

TEST(StochasticRendering, ZeroVarianceIsBeerLambert) {
  EXPECT_DOUBLE_EQ(expectedTransparency(3.0, {0.4, 0.0}), std::exp(-1.2));
  const OpticalDepthStatistics h = homogeneousSegmentStatistics(0.2, 0.0, Correlation{}, 2.0);
  EXPECT_DOUBLE_EQ(h.variance, 0.0);
  EXPECT_DOUBLE_EQ(expectedTransparency(5.0, h), std::exp(-5.0 * 0.4));
  const BlobSet set({{Vec3(0.1, 0.0, 0.0), 0.3, 0.2}, {Vec3(-0.2, 0.1, 0.3), 0.2, 0.1}});
  const Ray ray{Vec3(0.0, 0.0, -3.0), Vec3::UnitZ()};
  const OpticalDepthStatistics st = blobRayStatistics(set, ray, 0.0, kInf, StochasticBlobParameters{});
  EXPECT_EQ(st.variance, 0.0);
  EXPECT_DOUBLE_EQ(st.mean, set.opticalDepth(ray, 0.0, kInf));
  EXPECT_DOUBLE_EQ(realisedOpticalDepth(set, ray, 0.0, kInf, {}, [](const Vec3&) { return 1.0; }), st.mean);
}

TEST(StochasticRendering, ClampedIntegralSplitsWhereTheBlobReachesEta) {
  const Blob blob{Vec3(0.05, 0.02, 0.0), 0.5, 0.2};
  const BlobSet set({blob});
  const Ray ray{Vec3(0.0, 0.0, -2.0), Vec3::UnitZ()};
  const double peak = set.density(Vec3(0.0, 0.0, 0.0));
  double worst = 0.0;
  for (const double eta : {0.05 * peak, 0.5 * peak, 0.99 * peak, 2.0 * peak})
    for (const auto& [a, b] : {std::pair{0.0, 4.0}, std::pair{1.9, 2.1}, std::pair{2.05, 3.0}}) {
      const auto f = [&](double u) { return std::min(set.density(ray.origin + u * ray.direction), eta); };
      // Quadrature in pieces split at the kink points, so the rule sees smooth integrands.
      const double r2 = std::pow(blob.width, 2) * 2.0 *
                        std::log(blob.mass / (std::pow(2.0 * std::numbers::pi, 1.5) * std::pow(blob.width, 3) * eta));
      const double d2 = 0.05 * 0.05 + 0.02 * 0.02, du = r2 > d2 ? std::sqrt(r2 - d2) : 0.0;
      std::vector<double> cuts{a};
      for (double u : {2.0 - du, 2.0 + du})
        if (u > a && u < b) cuts.push_back(u);
      cuts.push_back(b);
      double quad = 0.0;
      for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
        const int n = 4000;
        const double h = (cuts[i + 1] - cuts[i]) / n;
        double s = f(cuts[i]) + f(cuts[i + 1]);
        for (int k = 1; k < n; ++k) s += (k % 2 ? 4.0 : 2.0) * f(cuts[i] + k * h);
        quad += s * h / 3.0;
      }
      worst = std::max(worst, std::abs(clampedBlobLineIntegral(blob, ray, a, b, eta) / quad - 1.0));
      if (du > 0.0) {
        EXPECT_NEAR(set.density(ray.origin + (2.0 + du) * ray.direction) / eta, 1.0, 1e-10);
      }
    }
  EXPECT_LT(worst, 1e-4);
  std::printf("clamped blob integral vs quadrature: worst relative difference %.2e\n", worst);
}

TEST(StochasticRendering, BlobVarianceMatchesQuasiHomogeneousRealisations) {
  // rho = rho_bar + sqrt(epsilon min(rho_bar, eta)) Q along the ray, Q exponential with l = sigma / 25.
  const Blob blob{Vec3(0.0, 0.1, 0.0), 0.5, 0.25};
  const BlobSet set({blob});
  const Ray ray{Vec3(0.0, 0.0, -2.0), Vec3::UnitZ()};
  StochasticBlobParameters p;
  p.epsilon = 0.4;
  p.eta = 0.5 * set.density(Vec3(0.0, 0.0, 0.0));
  p.correlation = {Correlation::Kind::Exponential, blob.width / 25.0};
  const OpticalDepthStatistics st = blobRayStatistics(set, ray, 0.0, 4.0, p);
  const int n = 4001;
  const double h = 4.0 / (n - 1), a = std::exp(-h / p.correlation.length);
  Eigen::VectorXd mean(n), sd(n), rho(n);
  for (int i = 0; i < n; ++i) {
    mean[i] = set.density(ray.origin + i * h * ray.direction);
    sd[i] = std::sqrt(p.epsilon * std::min(mean[i], p.eta));
  }
  Rng rng(3);
  const int R = 20000;
  double sum = 0.0, sum2 = 0.0;
  for (int r = 0; r < R; ++r) {
    double q = rng.normal();
    for (int i = 0; i < n; ++i) {
      if (i > 0) q = a * q + std::sqrt(1.0 - a * a) * rng.normal();
      rho[i] = mean[i] + sd[i] * q;
    }
    const double g = trapezoid(rho, h);
    sum += g, sum2 += g * g;
  }
  const double mcMean = sum / R, mcVar = sum2 / R - mcMean * mcMean;
  EXPECT_NEAR(mcMean / st.mean, 1.0, 3.0 * std::sqrt(st.variance / R) / st.mean + 1e-6);
  EXPECT_NEAR(mcVar / st.variance, 1.0, 0.05);
  std::printf("quasi-homogeneous blob: Var Gamma (eq. 5.29) %.4e, Monte Carlo %.4e (%+.2f%%); mean %.5f vs %.5f\n",
              st.variance, mcVar, 100.0 * (mcVar / st.variance - 1.0), st.mean, mcMean);
  // One realisation (eq. 5.30) follows Q at the closest point and is never negative.
  const auto constant = [](double v) { return [v](const Vec3&) { return v; }; };
  EXPECT_NEAR(realisedOpticalDepth(set, ray, 0.0, 4.0, p, constant(1.0)), st.mean + std::sqrt(st.variance), 1e-12);
  EXPECT_EQ(realisedOpticalDepth(set, ray, 0.0, 4.0, p, constant(-1e6)), 0.0);
}

TEST(StochasticRendering, BadInputIsRefused) {
  expectInvalidArgument([] { lineIntegralVariance({Correlation::Kind::Gaussian, -1.0}, 1.0, 1.0); }, "length");
  expectInvalidArgument([] { lineIntegralVariance({}, std::nan(""), 1.0); }, "stdDev");
  expectInvalidArgument([] { expectedTransparency(1.0, {0.0, -1.0}); }, "variance");
  expectInvalidArgument([] { expectedTransparency(1.0, {kInf, 0.0}); }, "mean");
  StochasticBlobParameters p;
  p.eta = 0.0;
  expectInvalidArgument([&] { blobRayStatistics(BlobSet({}), Ray{Vec3::Zero(), Vec3::UnitX()}, 0.0, 1.0, p); }, "eta");
}
