#include "msim/turbulence/energy_spectrum.hpp"

#include <array>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>
#include <string>

#include "msim/core/parallel.hpp"
#include "msim/numerics/fft.hpp"

namespace msim::turbulence {

namespace {

template <int D>
std::size_t latticeSize(std::span<const Vecf<D>> field, int resolution) {
  std::size_t n = 1;
  for (int d = 0; d < D; ++d) n *= static_cast<std::size_t>(resolution);
  if (resolution < 2 || field.size() != n)
    throw std::invalid_argument("turbulence: a field of " + std::to_string(field.size()) + " samples is not a lattice of " +
                                std::to_string(resolution) + "^" + std::to_string(D));
  return n;
}

// The Fourier coefficients u^ = FFT(u_d) / N of each component.
template <int D>
std::array<std::vector<std::complex<float>>, D> coefficients(std::span<const Vecf<D>> field, int resolution) {
  const std::size_t n = latticeSize<D>(field, resolution);
  const numerics::FftNd fft(std::vector<int>(D, resolution));
  std::array<std::vector<std::complex<float>>, D> c;
  for (int d = 0; d < D; ++d) {
    c[d].resize(n);
    parallelFor(0, n, [&](std::size_t a) { c[d][a] = std::complex<float>(field[a][d], 0.0f); }, 1 << 14);
    fft.forward(c[d]);
    const float scale = 1.0f / static_cast<float>(n);
    parallelFor(0, n, [&](std::size_t a) { c[d][a] *= scale; }, 1 << 14);
  }
  return c;
}

// The signed frequencies of lattice mode a.
template <int D>
std::array<int, D> frequencies(std::size_t a, int resolution) {
  std::array<int, D> s;
  for (int d = 0; d < D; ++d) {
    s[d] = numerics::signedFrequency(static_cast<int>(a % resolution), resolution);
    a /= resolution;
  }
  return s;
}

}  // namespace

template <int D>
ShellSpectrum shellSpectrum(std::span<const Vecf<D>> field, int resolution, double size) {
  const auto c = coefficients<D>(field, resolution);
  const int shells = resolution / 2;
  const double dk = 2.0 * std::numbers::pi / size;
  ShellSpectrum out;
  out.energy.assign(shells, 0.0);
  out.wavenumber.assign(shells, 0.0);
  out.modes.assign(shells, 0);
  const double sphere = D == 2 ? 2.0 * std::numbers::pi : 4.0 * std::numbers::pi;  // unit sphere's surface
  for (std::size_t a = 0; a < c[0].size(); ++a) {
    const auto s = frequencies<D>(a, resolution);
    double q = 0.0;
    for (int d = 0; d < D; ++d) q += double(s[d]) * s[d];
    const double radius = std::sqrt(q);
    const long shell = std::lround(radius);
    if (shell < 1 || shell > shells) continue;
    double e = 0.0;
    for (int d = 0; d < D; ++d) e += 0.5 * std::norm(std::complex<double>(c[d][a]));
    out.energy[shell - 1] += sphere * std::pow(radius, D - 1) * e / dk;
    out.wavenumber[shell - 1] += radius * dk;
    ++out.modes[shell - 1];
  }
  for (int k = 1; k <= shells; ++k) {
    const std::size_t count = out.modes[k - 1];
    if (count == 0) {
      out.wavenumber[k - 1] = k * dk;
      continue;
    }
    out.energy[k - 1] /= double(count);
    out.wavenumber[k - 1] /= double(count);
  }
  return out;
}

PowerLawFit fitPowerLaw(const ShellSpectrum& spectrum, double kMin, double kMax) {
  double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < spectrum.wavenumber.size(); ++i) {
    const double k = spectrum.wavenumber[i], e = spectrum.energy[i];
    if (k < kMin || k > kMax || !(e > 0.0)) continue;
    const double x = std::log(k), y = std::log(e);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
    ++n;
  }
  if (n < 2) throw std::invalid_argument("fitPowerLaw: fewer than 2 shells with energy in the range");
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  return PowerLawFit{slope, std::exp((sy - slope * sx) / n), n};
}

template <int D>
DivergenceMeasure spectralDivergence(std::span<const Vecf<D>> field, int resolution, double size) {
  auto c = coefficients<D>(field, resolution);
  const std::size_t n = c[0].size();
  const double dk = 2.0 * std::numbers::pi / size;
  // Parseval: <f^2> = sum |f^|^2 for each derivative field.
  double divergence2 = 0.0, gradient2 = 0.0;
  for (std::size_t a = 0; a < n; ++a) {
    const auto s = frequencies<D>(a, resolution);
    bool nyquist = false;
    for (int d = 0; d < D; ++d) nyquist |= 2 * std::abs(s[d]) == resolution;
    if (nyquist) continue;
    std::complex<double> div = 0.0;
    for (int d = 0; d < D; ++d) {
      const std::complex<double> u(c[d][a]);
      div += std::complex<double>(0.0, dk * s[d]) * u;
      for (int e = 0; e < D; ++e) gradient2 += std::norm(dk * s[e] * u);
    }
    divergence2 += std::norm(div);
  }
  return DivergenceMeasure{std::sqrt(divergence2), std::sqrt(gradient2)};
}

template ShellSpectrum shellSpectrum<2>(std::span<const Vecf<2>>, int, double);
template ShellSpectrum shellSpectrum<3>(std::span<const Vecf<3>>, int, double);
template DivergenceMeasure spectralDivergence<2>(std::span<const Vecf<2>>, int, double);
template DivergenceMeasure spectralDivergence<3>(std::span<const Vecf<3>>, int, double);

}  // namespace msim::turbulence
