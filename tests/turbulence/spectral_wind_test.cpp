// Spectral synthesis of turbulent wind (Stam 1995, ch. 3.3-3.4) against the properties the seed
// builds in: incompressible (eq. 3.10), the Kolmogorov k^(-5/3) spectrum over the inertial range,
// the variance the spectrum prescribes, real output from the mirror symmetry (Fig. 3.6), periodic
// in space and time (App. 6.B), and the temporal spread of eq. 3.28.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <tbb/global_control.h>

#include "msim/core/error.hpp"
#include "msim/core/rng.hpp"
#include "msim/numerics/fft.hpp"
#include "msim/turbulence/energy_spectrum.hpp"
#include "msim/turbulence/spectral_wind.hpp"

#include "input_error_message.hpp"

using namespace msim;
using namespace msim::turbulence;

namespace {

// A 1 m tile whose inertial range runs from P / 4 (the seed's "1/L = 4") down to the lattice's
// Nyquist wavelength (two cells).
SpectralWindParams tile(int resolution, int timeSamples, std::uint64_t seed = 7) {
  SpectralWindParams p;
  p.resolution = resolution;
  p.timeSamples = timeSamples;
  p.size = 1.0;
  p.period = 2.0;
  p.spectrum.dissipation = 0.5;
  p.spectrum.largestEddy = 0.25;
  p.spectrum.smallestEddy = 2.0 / resolution;
  p.seed = seed;
  return p;
}

template <int D>
double meanSquare(std::span<const Vecf<D>> v) {
  double s = 0.0;
  for (const auto& u : v) s += u.template cast<double>().squaredNorm();
  return s / v.size();
}

}  // namespace

TEST(KolmogorovSpectrum, EnergyIntegratesToTheClosedForm) {
  KolmogorovSpectrum s;
  s.dissipation = 0.3;
  s.largestEddy = 2.0;
  s.smallestEddy = 0.05;
  // Midpoint rule in log k.
  const double a = std::log(s.lowWavenumber()), b = std::log(s.highWavenumber());
  const int n = 200000;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double k = std::exp(a + (i + 0.5) * (b - a) / n);
    sum += s.energy(k) * k * (b - a) / n;
  }
  EXPECT_NEAR(sum / s.kineticEnergy(), 1.0, 1e-8);
  EXPECT_EQ(s.energy(0.99 * s.lowWavenumber()), 0.0);
  EXPECT_EQ(s.energy(1.01 * s.highWavenumber()), 0.0);
  // E = C_K epsilon^(2/3) k^(-5/3) inside.
  const double k = 10.0;
  EXPECT_NEAR(s.energy(k), 1.5 * std::pow(0.3, 2.0 / 3.0) * std::pow(k, -5.0 / 3.0), 1e-15);
  KolmogorovSpectrum t = s;
  t.dissipation = s.dissipationForSpeedRms(2.5);
  EXPECT_NEAR(t.speedRms(), 2.5, 1e-12);
}

TEST(KolmogorovSpectrum, InconsistentParametersAreClearErrors) {
  auto message = [](const KolmogorovSpectrum& s) { return inputErrorMessage([&] { s.validate("wind.spectrum"); }); };
  KolmogorovSpectrum s;
  s.dissipation = -1.0;
  EXPECT_NE(message(s).find("wind.spectrum"), std::string::npos);
  EXPECT_NE(message(s).find("dissipation"), std::string::npos);
  s = KolmogorovSpectrum{};
  s.smallestEddy = 2.0;  // above the largest eddy (1 m)
  EXPECT_NE(message(s).find("below the largest scale"), std::string::npos);
  s = KolmogorovSpectrum{};
  s.kolmogorovConstant = 0.0;
  EXPECT_FALSE(message(s).empty());
  EXPECT_TRUE(message(KolmogorovSpectrum{}).empty());
}

TEST(SpectralWind, FieldIsDivergenceFreeToRoundOff) {
  const SpectralWind<3> wind(tile(32, 4));
  const DivergenceMeasure m = spectralDivergence<3>(wind.timeSlice(1), 32, 1.0);
  std::printf("3D: rms div u / rms |grad u| = %.2e, imaginary residue %.2e\n", m.divergenceRms / m.gradientRms,
              wind.imaginaryResidue());
  EXPECT_LT(m.divergenceRms, 1e-5 * m.gradientRms);
  EXPECT_LT(wind.imaginaryResidue(), 1e-5);
  // The measure does see divergence: u = (sin 2 pi x, 0, 0) has rms div = rms |grad u|.
  std::vector<Vecf<3>> wave(32 * 32 * 32, Vecf<3>::Zero());
  for (std::size_t a = 0; a < wave.size(); ++a) wave[a].x() = std::sin(2.0f * std::numbers::pi_v<float> * (a % 32) / 32.0f);
  const DivergenceMeasure w = spectralDivergence<3>(wave, 32, 1.0);
  EXPECT_NEAR(w.divergenceRms / w.gradientRms, 1.0, 1e-5);

  const SpectralWind<2> flat(tile(128, 1));
  const DivergenceMeasure f = spectralDivergence<2>(flat.timeSlice(0), 128, 1.0);
  EXPECT_LT(f.divergenceRms, 1e-5 * f.gradientRms);
}

TEST(SpectralWind, ShellSpectrumFollowsKolmogorov) {
  // Shells from 1.5 x the largest eddy's wavenumber to 0.7 x the cutoff (seed notes T6).
  for (const int d : {2, 3}) {
    const int m = d == 3 ? 64 : 256;
    const SpectralWindParams p = tile(m, d == 3 ? 2 : 1);
    const double k0 = 1.5 * p.spectrum.lowWavenumber(), k1 = 0.7 * p.spectrum.highWavenumber();
    PowerLawFit fit;
    if (d == 3) {
      const SpectralWind<3> wind(p);
      fit = fitPowerLaw(shellSpectrum<3>(wind.timeSlice(0), m, 1.0), k0, k1);
    } else {
      const SpectralWind<2> wind(p);
      fit = fitPowerLaw(shellSpectrum<2>(wind.timeSlice(0), m, 1.0), k0, k1);
    }
    std::printf("%dD, %d^%d: E ~ k^%.3f over %d shells (target -5/3)\n", d, m, d, fit.exponent, fit.points);
    EXPECT_NEAR(fit.exponent, -5.0 / 3.0, 0.1);
    EXPECT_GE(fit.points, 15);
  }
}

TEST(SpectralWind, VarianceMatchesTheIntegralOfTheSpectrum) {
  // Ensemble of four seeds on a 48^3 x 4 lattice.
  double realised = 0.0, lattice = 0.0;
  const int seeds = 4;
  SpectralWindParams p = tile(48, 4);
  for (int s = 0; s < seeds; ++s) {
    p.seed = 100 + s;
    const SpectralWind<3> wind(p);
    realised += meanSquare<3>(wind.samples()) / seeds;
    lattice += wind.latticeVariance() / seeds;
  }
  const double prescribed = 2.0 * p.spectrum.kineticEnergy();
  std::printf("<|u|^2>: realised %.5f, lattice sum %.5f, 2 int E dk %.5f m^2/s^2\n", realised, lattice, prescribed);
  EXPECT_NEAR(realised / prescribed, 1.0, 0.05);
  EXPECT_NEAR(lattice / prescribed, 1.0, 0.05);
}

TEST(SpectralWind, PeriodicInSpaceAndTimeAndInterpolatesTheLattice) {
  const SpectralWind<3> wind(tile(16, 8));
  const double period = wind.params().period;
  Rng rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 x(rng.uniform(), rng.uniform(), rng.uniform());
    const double t = rng.uniform(0.0, period);
    const Vec3 u = wind.velocity(x, t);
    for (int d = 0; d < 3; ++d) {
      Vec3 shifted = x;
      shifted[d] += 3.0;  // three tiles over
      EXPECT_LT((wind.velocity(shifted, t) - u).norm(), 1e-5 * (1.0 + u.norm()));
      shifted[d] = x[d] - 1.0;
      EXPECT_LT((wind.velocity(shifted, t) - u).norm(), 1e-5 * (1.0 + u.norm()));
    }
    EXPECT_LT((wind.velocity(x, t + period) - u).norm(), 1e-5 * (1.0 + u.norm()));
  }
  // Lattice points give their samples.
  const double h = wind.cellSize(), dt = period / 8;
  for (int l : {0, 5})
    for (int i : {0, 7, 15}) {
      const Vec3 x(i * h, 3 * h, 15 * h);
      const Vecf<3> sample = wind.timeSlice(l)[i + 16 * (3 + 16 * 15)];
      EXPECT_LT((wind.velocity(x, l * dt) - sample.cast<double>()).norm(), 1e-5);
    }
  // Across the seam (x = 0 = P) neighbouring samples differ as much as neighbours inside do: the
  // field continues through it.
  const auto slice = wind.timeSlice(0);
  double seam = 0.0, inside = 0.0;
  for (int k = 0; k < 16; ++k)
    for (int j = 0; j < 16; ++j) {
      const std::size_t row = 16 * (j + 16 * k);
      seam += (slice[row + 15] - slice[row]).norm();
      for (int i = 0; i < 15; ++i) inside += (slice[row + i + 1] - slice[row + i]).norm() / 15;
    }
  std::printf("mean jump between neighbours: across the seam %.4f, inside %.4f m/s\n", seam / 256, inside / 256);
  EXPECT_NEAR(seam / inside, 1.0, 0.2);
}

TEST(SpectralWind, SmallEddiesDecorrelateFasterInTime) {
  // Eq. 3.28: the temporal spectrum of wavenumber k is a Gaussian of width k sigma, so the
  // correlation of a shell between times a lag tau apart is about exp(-(k sigma tau)^2 / 2).
  SpectralWindParams p = tile(32, 16);
  p.sweep = 0.05;
  p.period = 4.0;
  const SpectralWind<3> wind(p);
  const int m = 32;
  auto shellCorrelation = [&](int lag, int lo, int hi) {
    // Low-pass the two slices to shells [lo, hi] through their spectra: correlation of the
    // shell band = sum Re(u^_0 conj(u^_lag)) / sum |u^_0|^2, averaged over all start slices.
    double cross = 0.0, self = 0.0;
    for (int l = 0; l < 16; ++l) {
      const auto a = wind.timeSlice(l), b = wind.timeSlice(l + lag);
      for (int d = 0; d < 3; ++d) {
        std::vector<std::complex<float>> fa(a.size()), fb(b.size());
        for (std::size_t i = 0; i < a.size(); ++i) {
          fa[i] = a[i][d];
          fb[i] = b[i][d];
        }
        const numerics::FftNd fft({m, m, m});
        fft.forward(fa);
        fft.forward(fb);
        for (std::size_t i = 0; i < fa.size(); ++i) {
          std::size_t r = i;
          double q = 0.0;
          for (int e = 0; e < 3; ++e) {
            const int s = numerics::signedFrequency(static_cast<int>(r % m), m);
            q += s * s;
            r /= m;
          }
          const double n = std::sqrt(q);
          if (n < lo || n > hi) continue;
          cross += std::real(std::complex<double>(fa[i]) * std::conj(std::complex<double>(fb[i])));
          self += std::norm(std::complex<double>(fa[i]));
        }
      }
    }
    return cross / self;
  };
  const double tau = p.period / 16;
  const double large = shellCorrelation(1, 4, 6), small = shellCorrelation(1, 12, 15);
  auto predicted = [&](double n) {
    const double k = 2.0 * std::numbers::pi * n / p.size;
    return std::exp(-0.5 * std::pow(k * p.sweep * tau, 2));
  };
  std::printf("correlation at lag %.2f s: shells 4-6 %.3f (about %.3f), shells 12-15 %.3f (about %.3f)\n", tau, large,
              predicted(5), small, predicted(13.5));
  EXPECT_GT(large, small);
  EXPECT_NEAR(large, predicted(5), 0.05);
  EXPECT_NEAR(small, predicted(13.5), 0.05);
}

TEST(SpectralWind, SameSeedSameFieldOnAnyThreadCount) {
  std::vector<Vecf<3>> one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    const SpectralWind<3> w(tile(16, 4));
    one.assign(w.samples().begin(), w.samples().end());
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    const SpectralWind<3> w(tile(16, 4));
    two.assign(w.samples().begin(), w.samples().end());
  }
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) ASSERT_EQ(one[i], two[i]) << i;
  const SpectralWind<3> other(tile(16, 4, 8));
  EXPECT_NE(other.samples()[100], one[100]);
}

TEST(SpectralWind, LatticeThatCannotHoldTheSpectrumIsAClearError) {
  auto message = [](const SpectralWindParams& p) { return inputErrorMessage([&] { SpectralWind<3> w(p, "wind"); }); };
  SpectralWindParams p = tile(16, 4);
  p.spectrum.smallestEddy = 0.05;  // below two cells of 1/16 m
  EXPECT_NE(message(p).find("finer than the lattice"), std::string::npos);
  p = tile(16, 4);
  p.spectrum.largestEddy = 1.5;  // the tile is 1 m
  EXPECT_NE(message(p).find("larger than the periodic tile"), std::string::npos);
  p = tile(16, 4);
  p.period = 0.0;
  EXPECT_NE(message(p).find("wind: the time period"), std::string::npos);
  p = tile(16, 4);
  p.spectrum.dissipation = -2.0;
  EXPECT_NE(message(p).find("dissipation"), std::string::npos);
}
