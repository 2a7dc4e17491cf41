// Blobs (Stam ch. 4.1-4.2, 5.3-5.4, App. 5.C; seed notes T7, T8, T13, T14):
//  - the closed-form line integral of a Gaussian blob (eq. 5.17) against quadrature of rho;
//  - a blob's transparency exp(-sigma_t Gamma) and the telescoping of a constant source over the
//    App. 5.C intervals, I = T I_b + (1 - T) J;
//  - the mass of the field (eq. 4.7) on a grid;
//  - a lit blob against the grid volume renderer fed the blob's density;
//  - the time of a few thousand blobs at 320 x 240; input validation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include "expect_invalid.hpp"
#include "pixel.hpp"
#include "msim/core/grid.hpp"
#include "msim/core/rng.hpp"
#include "msim/render/blobs.hpp"

using namespace msim;
using namespace msim::render;
using msim::render::test::pixel;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Composite Simpson's rule of f over [a, b] with n (even) intervals.
template <typename F>
double simpson(F&& f, double a, double b, int n) {
  const double h = (b - a) / n;
  double s = f(a) + f(b);
  for (int i = 1; i < n; ++i) s += (i % 2 ? 4.0 : 2.0) * f(a + i * h);
  return s * h / 3.0;
}

VolumeRenderSettings dark() {
  VolumeRenderSettings s;
  s.background = Vec3::Zero();
  s.ambient = Vec3::Zero();
  return s;
}

Camera view(int size, const Vec3& position = Vec3(0.0, 0.0, 5.0)) {
  Camera c;
  c.position = position;
  c.target = Vec3::Zero();
  c.width = c.height = size;  // odd: the middle pixel's ray passes through the target
  return c;
}

}  // namespace

TEST(Blobs, LineIntegralIsTheQuadratureOfTheDensity) {
  const Blob blob{Vec3(0.1, 0.2, 0.5), 2.0, 0.3};
  const BlobSet set({blob});
  const Ray ray{Vec3(-2.0, 0.0, 0.0), Vec3(1.0, 0.1, 0.2).normalized()};
  const auto rho = [&](double u) { return set.density(ray.origin + u * ray.direction); };
  double worst = 0.0;
  for (const auto& [a, b] : {std::pair{0.5, 3.0}, std::pair{-1.0, 1.5}, std::pair{2.2, 2.4}}) {
    const double exact = blobLineIntegral(blob, ray, a, b), quad = simpson(rho, a, b, 4000);
    worst = std::max(worst, std::abs(exact - quad) / quad);
  }
  // The whole line: m g2(d), quadrature over 12 sigma either side of the closest approach.
  const double c = (blob.centre - ray.origin).dot(ray.direction);
  const double whole = blobLineIntegral(blob, ray, -kInf, kInf), quad = simpson(rho, c - 3.6, c + 3.6, 8000);
  worst = std::max(worst, std::abs(whole - quad) / quad);
  EXPECT_LT(worst, 1e-6);
  EXPECT_NEAR(set.opticalDepth(ray, -kInf, kInf), whole, 1e-15);
  std::printf("blob line integral vs Simpson: worst relative difference %.2e\n", worst);
}

TEST(Blobs, KernelIsNormalisedAndTheFieldHoldsTheMass) {
  const BlobSet set({{Vec3(0.0, 0.0, 0.0), 1.0, 0.2}, {Vec3(0.3, -0.1, 0.2), 0.5, 0.15}, {Vec3(-0.2, 0.25, -0.1), 2.0, 0.25}});
  // Midpoint rule on a grid of 0.04 m over [-1.5, 1.5]^3 (6 sigma beyond every blob).
  const double h = 0.04;
  const int n = 75;
  double mass = 0.0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) mass += set.density(Vec3(-1.5 + (i + 0.5) * h, -1.5 + (j + 0.5) * h, -1.5 + (k + 0.5) * h));
  mass *= h * h * h;
  EXPECT_NEAR(mass / set.totalMass(), 1.0, 1e-3);
  EXPECT_DOUBLE_EQ(set.totalMass(), 3.5);
  std::printf("blob field mass on a grid: %.8f of sum m_k = %.1f (relative %.1e)\n", mass, set.totalMass(),
              mass / set.totalMass() - 1.0);
}

TEST(Blobs, TransparencyOfOneBlobIsBeerLambert) {
  const Blob blob{Vec3(0.05, -0.03, 0.0), 0.2, 0.3};
  Medium m;
  m.extinction = 6.0;
  VolumeRenderSettings s = dark();
  s.background = Vec3::Ones();
  BlobRenderSettings bs;
  bs.cutoffWidths = 8.0;  // erfc(8 / sqrt 2) ~ 1e-15 of the line integral outside
  const Camera cam = view(1);
  const BlobRenderResult r = renderBlobs(BlobSet({blob}), cam, {}, m, s, bs);
  const Ray ray{cam.position, (cam.target - cam.position).normalized()};
  const double expected = std::exp(-m.extinction * blobLineIntegral(blob, ray, -kInf, kInf));
  EXPECT_NEAR(pixel(r.radiance, 0, 0)[0], expected, 1e-6);
  std::printf("one blob: transparency %.7f, exp(-sigma_t Gamma) %.7f\n", pixel(r.radiance, 0, 0)[0], expected);
}

TEST(Blobs, ConstantSourceTelescopesOverOverlappingBlobs) {
  // Sky light only: every blob has J = Omega I_sky, so the App. 5.C sum is (1 - T) J with T the
  // transparency of all chords together, whatever their overlap.
  const BlobSet set({{Vec3(0.0, 0.0, 0.3), 0.05, 0.2}, {Vec3(0.1, 0.05, 0.0), 0.1, 0.3}, {Vec3(-0.05, 0.0, -0.4), 0.05, 0.25}});
  Medium m;
  m.extinction = 8.0;
  m.albedo = 0.7;
  VolumeRenderSettings s = dark();
  s.background = Vec3(0.2, 0.3, 0.4);
  s.ambient = Vec3(1.0, 0.5, 0.25);
  BlobRenderSettings bs;
  bs.cutoffWidths = 8.0;
  const Camera cam = view(1);
  const Vec3 got = pixel(renderBlobs(set, cam, {}, m, s, bs).radiance, 0, 0);
  const Ray ray{cam.position, (cam.target - cam.position).normalized()};
  const double T = std::exp(-m.extinction * set.opticalDepth(ray, -kInf, kInf));
  const Vec3 expected = T * s.background + (1.0 - T) * m.albedo * s.ambient;
  EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 1e-6);
  std::printf("constant source: T = %.5f, pixel %.6f %.6f %.6f, expected %.6f %.6f %.6f\n", T, got[0], got[1], got[2],
              expected[0], expected[1], expected[2]);
}

TEST(Blobs, LitBlobAgreesWithTheGridVolumeRenderer) {
  // One blob, optical depth 0.3 through its centre, lit from the side; its density rasterised on a
  // 64^3 grid and rendered by renderVolume (which self-shadows exactly, cell by cell).
  const double sigma = 0.25, sigmaT = 10.0;
  const Blob blob{Vec3::Zero(), 0.3 * 2.0 * std::numbers::pi * sigma * sigma / sigmaT, sigma};
  const BlobSet set({blob});
  Grid<float, 3> rho(GridSpec<3>(Vec3::Constant(-1.2), 2.4 / 64, IVec3(64, 64, 64)));
  for (std::size_t i = 0; i < rho.count(); ++i) rho[i] = static_cast<float>(set.density(rho.position(rho.coord(i))));
  Medium m;
  m.extinction = sigmaT;
  m.albedo = 0.9;
  m.phaseG = 0.3;
  VolumeRenderSettings s = dark();
  s.ambient = Vec3::Constant(0.1);
  Light light;
  light.direction = Vec3(1.0, -1.0, -0.5);
  light.intensity = 2.0;
  const Camera cam = view(33);
  VolumeInput in;
  in.density = &rho;
  const double grid = pixel(renderVolume(in, cam, {light}, m, s).radiance, 16, 16)[0];
  BlobRenderSettings bs;
  const double withSelf = pixel(renderBlobs(set, cam, {light}, m, s, bs).radiance, 16, 16)[0];
  bs.selfShadowing = false;
  const double without = pixel(renderBlobs(set, cam, {light}, m, s, bs).radiance, 16, 16)[0];
  EXPECT_NEAR(withSelf / grid, 1.0, 0.03);
  std::printf("lit blob, centre pixel: grid %.6f, blobs %.6f (%+.2f%%), without self-shadowing %.6f (%+.2f%%)\n", grid,
              withSelf, 100.0 * (withSelf / grid - 1.0), without, 100.0 * (without / grid - 1.0));
}

TEST(Blobs, AThousandOverlappingBlobsRenderFiniteAndVisible) {
  // A cloud of 1000 blobs in a ball of radius 1, one light, sky and background; the time this
  // takes is measured in bench/blob_bench.cpp.
  Rng rng(7);
  std::vector<Blob> blobs;
  while (blobs.size() < 1000) {
    const Vec3 p(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
    if (p.norm() < 1.0) blobs.push_back({p, 0.006, rng.uniform(0.04, 0.1)});
  }
  const BlobSet set(std::move(blobs));
  Camera cam = view(1, Vec3(0.0, 0.5, 4.0));
  cam.width = 160;
  cam.height = 120;
  Light light;
  light.direction = Vec3(-1.0, -1.0, -0.3);
  light.intensity = 3.0;
  Medium m;
  m.extinction = 10.0;
  const BlobRenderResult r = renderBlobs(set, cam, {light}, m, VolumeRenderSettings{});
  double mn = 1e9, mx = 0.0;
  for (float v : r.radiance.rgb) {
    ASSERT_TRUE(std::isfinite(v));
    mn = std::min(mn, double(v)), mx = std::max(mx, double(v));
  }
  EXPECT_GT(mx, 2.0 * mn);  // the cloud shows against the background
}

TEST(Blobs, BadInputIsRefused) {
  expectInvalidArgument([] { BlobSet({{Vec3::Zero(), 1.0, -0.1}}); }, "width");
  expectInvalidArgument([] { BlobSet({{Vec3::Zero(), 1.0, 0.1}, {Vec3::Zero(), std::nan(""), 0.1}}); }, "blob 1: mass");
  expectInvalidArgument([] { BlobSet({{Vec3(kInf, 0.0, 0.0), 1.0, 0.1}}); }, "centre");
  expectInvalidArgument([] { BlobSet({{Vec3::Zero(), 1.0, 0.1, Vec3(-1.0, 0.0, 0.0)}}); }, "emission");
  expectInvalidArgument([] { gaussianKernel(0.0, 0.0); }, "sigma");
  expectInvalidArgument([] { blobLineIntegral({}, Ray{Vec3::Zero(), Vec3::UnitX()}, 1.0, 0.0); }, "a <= b");
  BlobRenderSettings bs;
  bs.cutoffWidths = 0.5;
  expectInvalidArgument([&] { renderBlobs(BlobSet({}), view(8), {}, Medium{}, VolumeRenderSettings{}, bs); }, "cutoffWidths");
}
