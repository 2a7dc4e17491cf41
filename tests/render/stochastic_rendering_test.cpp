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
#include "pixel.hpp"
#include "msim/core/rng.hpp"
#include "msim/render/camera.hpp"
#include "msim/render/stochastic_rendering.hpp"

using namespace msim;
using namespace msim::render;
using msim::render::test::pixel;

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
  expectInvalidArgument([] { FourierNoise({}, 1, 0); }, "terms");
  StochasticRenderSettings r;
  r.noiseTerms = 0;
  expectInvalidArgument([&] { renderStochasticBlobs(BlobSet({}), Camera{}, {}, Medium{}, VolumeRenderSettings{}, r); },
                        "noiseTerms");
}

namespace {

// A small cloud: blobs of different sizes, one emitting, lit by a sun and the sky.
BlobSet cloud() {
  std::vector<Blob> blobs;
  Rng rng(3);
  for (int i = 0; i < 12; ++i)
    blobs.push_back({Vec3(rng.uniform(-0.6, 0.6), rng.uniform(-0.4, 0.4), rng.uniform(-0.3, 0.3)), rng.uniform(0.05, 0.3),
                     rng.uniform(0.12, 0.3), i == 0 ? Vec3(0.5, 0.3, 0.1) : Vec3::Zero()});
  return BlobSet(blobs);
}

Camera view(int size) {
  Camera c;
  c.width = c.height = size;  // odd: the middle pixel's ray passes through the target, the origin
  return c;
}

std::vector<Light> sun() {
  Light l;
  l.type = Light::Type::Directional;
  l.direction = Vec3(-1.0, -1.0, -0.5);
  return {l};
}

StochasticRenderSettings turbulent(StochasticImage image, std::uint64_t seed) {
  StochasticRenderSettings s;
  s.parameters.epsilon = 2.0;
  s.parameters.eta = 0.8;
  s.parameters.correlation.length = 0.05;
  s.image = image;
  s.seed = seed;
  return s;
}

}  // namespace

TEST(StochasticRendering, FourierNoiseHasUnitVarianceAndTheCorrelation) {
  // Over seeds, at two points a correlation length apart: mean 0, variance 1, correlation c(l).
  for (const Correlation::Kind kind : {Correlation::Kind::Gaussian, Correlation::Kind::Exponential}) {
    const Correlation c{kind, 0.05};
    const Vec3 x(0.3, -0.2, 0.1), y = x + c.length * Vec3(0.6, 0.0, 0.8);
    const int seeds = 4000;
    double sum = 0.0, sum2 = 0.0, product = 0.0;
    for (int seed = 0; seed < seeds; ++seed) {
      const FourierNoise q(c, static_cast<std::uint64_t>(seed));
      const double a = q(x), b = q(y);
      sum += a, sum2 += a * a, product += a * b;
    }
    std::printf("noise %s: mean %.4f variance %.4f correlation at l %.4f (c(l) = %.4f)\n",
                kind == Correlation::Kind::Gaussian ? "Gaussian" : "exponential", sum / seeds, sum2 / seeds,
                product / seeds, c(c.length));
    EXPECT_NEAR(sum / seeds, 0.0, 0.06);
    EXPECT_NEAR(sum2 / seeds, 1.0, 0.08);
    EXPECT_NEAR(product / seeds, c(c.length), 0.08);
  }
}

TEST(StochasticRendering, ZeroVarianceImageIsRenderBlobs) {
  const BlobSet blobs = cloud();
  const Camera camera = view(33);
  const Medium medium{5.0, 0.9, 0.3};
  const BlobRenderResult reference = renderBlobs(blobs, camera, sun(), medium, VolumeRenderSettings{});
  for (const StochasticImage image : {StochasticImage::Realisation, StochasticImage::Expected}) {
    StochasticRenderSettings s = turbulent(image, 7);
    s.parameters.epsilon = 0.0;
    const BlobRenderResult r = renderStochasticBlobs(blobs, camera, sun(), medium, VolumeRenderSettings{}, s);
    double worst = 0.0;
    for (std::size_t i = 0; i < r.radiance.rgb.size(); ++i)
      worst = std::max(worst, std::abs(r.radiance.rgb[i] - reference.radiance.rgb[i]) /
                                  std::max(1e-30, static_cast<double>(std::abs(reference.radiance.rgb[i]))));
    EXPECT_LE(worst, 1e-6);
  }
}

TEST(StochasticRendering, MeanOfRealisationsIsTheExpectedPicture) {
  // One blob (the blobs' perturbations are independent only when their closest points are more
  // than a correlation length apart), seen through its centre.
  const BlobSet blobs({Blob{Vec3::Zero(), 0.565, 0.3}});
  const Camera camera = view(5);
  const Medium medium{1.0, 0.9, 0.0};
  VolumeRenderSettings transparency;  // pixel = tau: background 1, nothing scattered
  transparency.background = Vec3::Ones();
  transparency.ambient = Vec3::Zero();
  VolumeRenderSettings lit;  // pixel = tau B + (1 - tau) J_avg
  lit.background = Vec3(0.2, 0.3, 0.5);
  lit.ambient = Vec3(0.6, 0.6, 0.7);
  const Ray centre = CameraRays(camera).ray(2.5, 2.5);
  const StochasticRenderSettings expectedSettings = turbulent(StochasticImage::Expected, 0);
  const double expectedTau =
      expectedTransparency(medium.extinction, blobRayStatistics(blobs, centre, 0.0, kInf, expectedSettings.parameters));
  const double expectedPixel = renderStochasticBlobs(blobs, camera, {}, medium, transparency, expectedSettings).radiance.pixel(2, 2)[0];
  const Vec3 expectedLit = pixel(renderStochasticBlobs(blobs, camera, sun(), medium, lit, expectedSettings).radiance, 2, 2);
  // The cut-off at 4 sigma leaves out 6e-5 of the line integral through the centre.
  EXPECT_NEAR(expectedPixel / expectedTau, 1.0, 1e-3);
  const int seeds = 2000;
  double sumTau = 0.0;
  Vec3 sumLit = Vec3::Zero();
  for (int seed = 1; seed <= seeds; ++seed) {
    const StochasticRenderSettings s = turbulent(StochasticImage::Realisation, static_cast<std::uint64_t>(seed));
    sumTau += renderStochasticBlobs(blobs, camera, {}, medium, transparency, s).radiance.pixel(2, 2)[0];
    sumLit += pixel(renderStochasticBlobs(blobs, camera, sun(), medium, lit, s).radiance, 2, 2);
  }
  const double meanTau = sumTau / seeds;
  const double beerLambert = std::exp(-medium.extinction * blobs.opticalDepth(centre, 0.0, kInf));
  std::printf("centre pixel: Beer-Lambert %.5f, E[tau] %.5f, mean of %d realisations %.5f (%+.2f%%)\n", beerLambert,
              expectedTau, seeds, meanTau, 100.0 * (meanTau / expectedTau - 1.0));
  EXPECT_NEAR(meanTau / expectedTau, 1.0, 0.03);
  EXPECT_GT(expectedTau, beerLambert * 1.05);  // Jensen: the average picture is visibly brighter
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(sumLit[ch] / seeds / expectedLit[ch], 1.0, 0.03);
}

TEST(StochasticRendering, RealisationIsFiniteDeterministicAndVariesWithTheSeed) {
  const BlobSet blobs = cloud();
  const Camera camera = view(33);
  const Medium medium{5.0, 0.9, 0.3};
  VolumeRenderSettings transparency;
  transparency.background = Vec3::Ones();
  transparency.ambient = Vec3::Zero();
  const BlobRenderResult a = renderStochasticBlobs(blobs, camera, sun(), medium, VolumeRenderSettings{}, turbulent(StochasticImage::Realisation, 5));
  const BlobRenderResult b = renderStochasticBlobs(blobs, camera, sun(), medium, VolumeRenderSettings{}, turbulent(StochasticImage::Realisation, 5));
  const BlobRenderResult c = renderStochasticBlobs(blobs, camera, sun(), medium, VolumeRenderSettings{}, turbulent(StochasticImage::Realisation, 6));
  EXPECT_EQ(a.radiance.rgb, b.radiance.rgb);
  EXPECT_EQ(a.image.rgb, b.image.rgb);
  double change = 0.0;
  for (std::size_t i = 0; i < a.radiance.rgb.size(); ++i) {
    EXPECT_TRUE(std::isfinite(a.radiance.rgb[i]));
    EXPECT_GE(a.radiance.rgb[i], 0.0f);
    change = std::max(change, static_cast<double>(std::abs(a.radiance.rgb[i] - c.radiance.rgb[i])));
  }
  EXPECT_GT(change, 1e-3);  // the detail is visible
  // Transparency alone, thick enough that renderBlobs stops some rays at T < 1e-4: tau in [0, 1]
  // (Gamma clamped at 0).
  const Medium thick{200.0, 0.9, 0.3};
  const BlobRenderResult t = renderStochasticBlobs(blobs, camera, {}, thick, transparency, turbulent(StochasticImage::Realisation, 5));
  int opaque = 0;
  for (float v : t.radiance.rgb) {
    EXPECT_GE(v, 0.0f);
    EXPECT_LE(v, 1.0f);
    opaque += v < 1e-4f;
  }
  EXPECT_GT(opaque, 0);
}
