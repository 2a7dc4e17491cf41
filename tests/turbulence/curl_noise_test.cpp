// Curl noise (Narain ch. 3.5): octaves of an animated noise potential, A_i = sqrt(E_i) l_i with
// E_i = E_0 2^(-2i/3) (eq. 3.4), give the Kolmogorov spectrum (Fig. 3.5: five octaves, exponent
// close to -5/3) and an incompressible velocity.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include "msim/core/parallel.hpp"
#include "msim/core/rng.hpp"
#include "msim/numerics/fft.hpp"
#include "msim/turbulence/curl_noise.hpp"
#include "msim/turbulence/energy_spectrum.hpp"

using namespace msim;
using namespace msim::turbulence;

namespace {

// Octaves 0 .. count - 1 of curl noise on the periodic box [0, 1]^D of m cells: the noise tile
// spans 4 l_i, so with l_0 = 1/4 every octave repeats with the box.
template <int D>
std::vector<Vecf<D>> octaves(const NoiseTile<D>& tile, int m, int count, MacGrid<D>& u) {
  const GridSpec<D> spec(Vec<D>::Zero(), 1.0 / m, IVec<D>::Constant(m));
  std::size_t nodes = 1;
  for (int d = 0; d < D; ++d) nodes *= static_cast<std::size_t>(m + 1);
  std::vector<Vecf<3>> psi(nodes, Vecf<3>::Zero());
  parallelFor(0, nodes, [&](std::size_t a) {
    Vec<D> x;
    std::size_t rest = a;
    for (int d = 0; d < D; ++d) {
      x[d] = static_cast<double>(rest % (m + 1)) / m;
      rest /= (m + 1);
    }
    for (int i = 0; i < count; ++i) {
      const double l = 0.25 / std::ldexp(1.0, i);
      const double amplitude = std::sqrt(std::pow(2.0, -2.0 * i / 3.0)) * l;  // E_0 = 1
      psi[a] += static_cast<float>(amplitude) * tile.vector(x / l, 0.3);
    }
  }, 1024);
  u = MacGrid<D>(spec);
  curlOfNodalPotential<D>(spec, psi, u);
  // The periodic lattice of face values (staggering shifts phases only).
  std::size_t cells = 1;
  for (int d = 0; d < D; ++d) cells *= static_cast<std::size_t>(m);
  std::vector<Vecf<D>> field(cells);
  parallelForCells<D>(IVec<D>::Constant(m), [&](const IVec<D>& c, std::size_t lin) {
    for (int d = 0; d < D; ++d) field[lin][d] = u.component(d)(c);
  });
  return field;
}

template <int D>
double maxDivergence(const MacGrid<D>& u, double& largestFace) {
  const auto& spec = u.component(0).spec();
  double worst = 0.0;
  largestFace = 0.0;
  for (int d = 0; d < D; ++d)
    for (std::size_t i = 0; i < u.component(d).count(); ++i) largestFace = std::max(largestFace, double(std::abs(u.component(d)[i])));
  parallelForCells<D>(spec.res, [&](const IVec<D>& c, std::size_t) {});
  for (std::size_t lin = 0; lin < static_cast<std::size_t>(spec.res.prod()); ++lin) {
    IVec<D> c;
    std::size_t rest = lin;
    for (int d = 0; d < D; ++d) {
      c[d] = static_cast<int>(rest % spec.res[d]);
      rest /= spec.res[d];
    }
    double div = 0.0;
    for (int d = 0; d < D; ++d) {
      IVec<D> up = c;
      up[d] += 1;
      div += (double(u.component(d)(up)) - double(u.component(d)(c))) / spec.dx;
    }
    worst = std::max(worst, std::abs(div));
  }
  return worst;
}

// Octave i scales one periodic tile down by 2^i, so it repeats 2^i times across the box and holds
// only the wavenumbers that are multiples of 2^i: its spectrum is a set of lines, and shells fall
// between them. So the spectrum is taken per octave band [2 pi / l_i, 4 pi / l_i): the kinetic
// energy of the band's modes (Parseval) over the band's width, at the band's geometric centre.
template <int D>
ShellSpectrum octaveBands(const std::vector<Vecf<D>>& field, int m, int count) {
  std::size_t n = field.size();
  std::vector<double> energy(count, 0.0);
  const numerics::FftNd fft(std::vector<int>(D, m));
  for (int d = 0; d < D; ++d) {
    std::vector<std::complex<float>> c(n);
    for (std::size_t a = 0; a < n; ++a) c[a] = field[a][d];
    fft.forward(c);
    for (std::size_t a = 0; a < n; ++a) {
      double q = 0.0;
      std::size_t rest = a;
      for (int e = 0; e < D; ++e) {
        const int f = numerics::signedFrequency(static_cast<int>(rest % m), m);
        q += double(f) * f;
        rest /= m;
      }
      const double radius = std::sqrt(q);  // |n|: k = 2 pi |n| on the 1 m box
      for (int i = 0; i < count; ++i)
        if (radius >= 4.0 * std::ldexp(1.0, i) && radius < 8.0 * std::ldexp(1.0, i))
          energy[i] += 0.5 * std::norm(std::complex<double>(c[a])) / (double(n) * double(n));
    }
  }
  ShellSpectrum bands;
  for (int i = 0; i < count; ++i) {
    const double lo = 2.0 * std::numbers::pi * 4.0 * std::ldexp(1.0, i), hi = 2.0 * lo;
    bands.wavenumber.push_back(std::sqrt(lo * hi));
    bands.energy.push_back(energy[i] / (hi - lo));
    bands.modes.push_back(0);
  }
  return bands;
}

}  // namespace

TEST(CurlNoise, FiveOctavesFollowKolmogorov) {
  const NoiseTile<2> tile(3);
  MacGrid<2> u;
  const int m = 512;
  const auto field = octaves<2>(tile, m, 5, u);
  const ShellSpectrum bands = octaveBands<2>(field, m, 5);
  const PowerLawFit fit = fitPowerLaw(bands, 0.0, 1e30);
  std::printf("2D, five octaves on %d^2: E ~ k^%.3f over %d octave bands (Fig. 3.5: about -1.66)\n", m, fit.exponent,
              fit.points);
  EXPECT_NEAR(fit.exponent, -5.0 / 3.0, 0.1);
  double largest = 0.0;
  const double div = maxDivergence<2>(u, largest);
  EXPECT_LT(div * u.component(0).spec().dx, 1e-5 * largest);
}

TEST(CurlNoise, ThreeDimensionalOctavesAreIncompressibleAndKolmogorov) {
  const NoiseTile<3> tile(4);
  MacGrid<3> u;
  const int m = 128;
  const auto field = octaves<3>(tile, m, 3, u);
  const PowerLawFit fit = fitPowerLaw(octaveBands<3>(field, m, 3), 0.0, 1e30);
  double largest = 0.0;
  const double div = maxDivergence<3>(u, largest);
  double meanSquare = 0.0;
  for (const auto& v : field) meanSquare += double(v.squaredNorm()) / field.size();
  // <|u|^2> = sum E_i with E_0 = 1 (the tile's scale: eddies of speed sqrt(E_i)).
  const double expected = 1.0 + std::pow(2.0, -2.0 / 3.0) + std::pow(2.0, -4.0 / 3.0);
  std::printf("3D, three octaves on %d^3: E ~ k^%.3f over %d octave bands; max |div u| dx / max |u| = %.1e; <|u|^2> %.3f "
              "(sum E_i = %.3f)\n",
              m, fit.exponent, fit.points, div * u.component(0).spec().dx / largest, meanSquare, expected);
  // The finest octave has 4-8 cells per wavelength here, where the discrete curl loses 10-20% of
  // its energy: the fit comes out about 0.1 steep, the total about 5% low.
  EXPECT_NEAR(fit.exponent, -5.0 / 3.0, 0.15);
  EXPECT_LT(div * u.component(0).spec().dx, 1e-5 * largest);
  EXPECT_NEAR(meanSquare / expected, 1.0, 0.1);
}

TEST(CurlNoise, BlendInTimeKeepsTheVariance) {
  // The tile is read linearly between time samples; two samples of correlation c blended half and
  // half keep (1 + c) / 2 of the variance (0.87 here) unless the blend is rescaled. Mean |N|^2 over
  // the same points at every time sample against half-way between them, over the whole period.
  const NoiseTile<2> tile(5);
  Rng rng(11);
  std::vector<Vec2> points(4000);
  for (Vec2& y : points) y = Vec2(rng.uniform(0.0, NoiseTile<2>::kSide), rng.uniform(0.0, NoiseTile<2>::kSide));
  const double step = NoiseTile<2>::kPeriod / NoiseTile<2>::kTimeSamples;
  double onSamples = 0.0, halfWay = 0.0;
  for (int k = 0; k < NoiseTile<2>::kTimeSamples; ++k)
    for (const Vec2& y : points) {
      onSamples += double(tile.vector(y, k * step).squaredNorm());
      halfWay += double(tile.vector(y, (k + 0.5) * step).squaredNorm());
    }
  std::printf("<|N|^2> half-way between time samples / on them: %.4f (linear blend alone: about 0.87)\n",
              halfWay / onSamples);
  EXPECT_NEAR(halfWay / onSamples, 1.0, 0.03);
}
