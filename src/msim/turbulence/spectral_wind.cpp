#include "msim/turbulence/spectral_wind.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/core/linear_taps.hpp"
#include "msim/core/parallel.hpp"
#include "msim/core/rng.hpp"
#include "msim/numerics/fft.hpp"

namespace msim::turbulence {

using numerics::isNyquist;
using numerics::signedFrequency;

template <int D>
void SpectralWind<D>::validate(const SpectralWindParams& p, const std::string& where) {
  p.spectrum.validate(where);
  if (p.resolution < 4)
    throw InputError(fmt::format("{}: the lattice needs at least 4 samples per axis, got {}", where, p.resolution));
  if (p.timeSamples < 1)
    throw InputError(fmt::format("{}: the lattice needs at least 1 time sample, got {}", where, p.timeSamples));
  if (!(std::isfinite(p.size) && p.size > 0.0))
    throw InputError(fmt::format("{}: the tile size must be positive, got {} m", where, p.size));
  if (!(std::isfinite(p.period) && p.period > 0.0))
    throw InputError(fmt::format("{}: the time period must be positive, got {} s", where, p.period));
  if (!std::isfinite(p.sweep)) throw InputError(fmt::format("{}: the sweep speed must be finite", where));
  if (p.spectrum.largestEddy > p.size * (1.0 + 1e-12))
    throw InputError(fmt::format("{}: the largest eddy ({} m) is larger than the periodic tile ({} m), whose longest "
                                 "wave is the tile itself",
                                 where, p.spectrum.largestEddy, p.size));
  const double nyquistWavelength = 2.0 * p.size / p.resolution;
  if (p.spectrum.smallestEddy < nyquistWavelength * (1.0 - 1e-12))
    throw InputError(fmt::format("{}: the smallest eddy ({} m) is finer than the lattice resolves: {} samples over "
                                 "{} m hold waves down to {} m (two cells)",
                                 where, p.spectrum.smallestEddy, p.resolution, p.size, nyquistWavelength));
}

template <int D>
SpectralWind<D>::SpectralWind(const SpectralWindParams& params, const std::string& where) : params_(params) {
  validate(params, where);
  const int m = params.resolution, mt = params.timeSamples;
  const double dk = 2.0 * std::numbers::pi / params.size, dkappa = 2.0 * std::numbers::pi / params.period;
  sweep_ = params.sweep < 0.0 ? params.spectrum.speedRms() : params.sweep;
  std::size_t spatial = 1;
  for (int d = 0; d < D; ++d) spatial *= static_cast<std::size_t>(m);
  const std::size_t n = spatial * static_cast<std::size_t>(mt);

  // Temporal weights w_k(kappa_l) (eq. 3.28, normalised on the lattice), by q = |n|^2: k = dk sqrt(q).
  const int maxQ = D * (m / 2) * (m / 2);
  std::vector<double> weight(static_cast<std::size_t>(maxQ + 1) * mt, 0.0);
  for (int q = 1; q <= maxQ; ++q) {
    double* w = &weight[static_cast<std::size_t>(q) * mt];
    const double spread = dk * std::sqrt(double(q)) * sweep_;  // k sigma [rad/s]
    if (mt == 1 || !(spread > 0.0)) {
      w[0] = 1.0;
      continue;
    }
    double sum = 0.0;
    for (int l = 0; l < mt; ++l) {
      if (isNyquist(l, mt)) continue;
      const double kappa = dkappa * signedFrequency(l, mt);
      w[l] = std::exp(-0.5 * kappa * kappa / (spread * spread));
      sum += w[l];
    }
    for (int l = 0; l < mt; ++l) w[l] /= sum;
  }

  // Gamma(m/2) / pi^(m/2): 1 / pi in 2D, 1 / (2 pi) in 3D (eq. 3.13).
  const double gammaOverPi = D == 2 ? 1.0 / std::numbers::pi : 0.5 / std::numbers::pi;
  const double cellVolume = std::pow(dk, D);
  std::array<std::vector<std::complex<float>>, D> modes;
  for (auto& c : modes) c.assign(n, std::complex<float>(0.0f, 0.0f));
  const Rng noise(params.seed);
  std::vector<int> dims(D, m);
  dims.push_back(mt);
  // The variance a mode carries (0 for the empty ones): tr S w dk^m = (m - 1) Phi^2 w dk^m.
  auto modeVariance = [&](const auto& s) {
    int q = 0;
    for (int d = 0; d < D; ++d) {
      if (2 * std::abs(s[d]) == m) return 0.0;  // Nyquist plane
      q += s[d] * s[d];
    }
    if (q == 0 || (mt > 1 && 2 * std::abs(s[D]) == mt)) return 0.0;
    const double k = dk * std::sqrt(double(q));
    const int l = s[D] < 0 ? s[D] + mt : s[D];
    return (D - 1) * params.spectrum.energy(k) * gammaOverPi / ((D - 1) * std::pow(k, D - 1)) * cellVolume *
           weight[static_cast<std::size_t>(q) * mt + l];
  };
  // Each pair of mirror modes is drawn from the lower index's stream and written by it alone.
  numerics::forEachMirrorPair(dims, [&](std::size_t a, std::size_t mirror, const auto& s) {
    const double variance = modeVariance(s);
    if (variance == 0.0) return;
    const double amplitude = std::sqrt(variance / (D - 1));  // sqrt(Phi^2 w dk^m)
    Rng r = noise.split(a);
    std::array<std::complex<double>, D> v;
    for (auto& c : v) {
      const double size = r.normal();
      c = std::polar(size, 2.0 * std::numbers::pi * r.uniform());
    }
    // P(k) v: the part of v normal to k.
    double q = 0.0;
    std::complex<double> along = 0.0;
    for (int d = 0; d < D; ++d) {
      along += double(s[d]) * v[d];
      q += double(s[d]) * s[d];
    }
    along /= q;
    for (int d = 0; d < D; ++d) {
      const std::complex<double> u = amplitude * (v[d] - along * double(s[d]));
      modes[d][a] = std::complex<float>(u);
      modes[d][mirror] = std::conj(std::complex<float>(u));
    }
  });
  // Every mode but the empty ones, mirrors included.
  latticeVariance_ = parallelSum(n, [&](std::size_t a) {
    std::array<int, D + 1> s;
    std::size_t rest = a;
    for (int d = 0; d <= D; ++d) {
      const int count = d < D ? m : mt;
      s[d] = signedFrequency(static_cast<int>(rest % count), count);
      rest /= count;
    }
    return modeVariance(s);
  });

  const numerics::FftNd fft(dims);
  samples_.assign(n, Vecf<D>::Zero());
  double largestReal = 0.0, largestImaginary = 0.0;
  for (int d = 0; d < D; ++d) {
    fft.inverse(modes[d]);
    parallelFor(0, n, [&](std::size_t a) { samples_[a][d] = modes[d][a].real(); }, 1 << 14);
    largestReal = std::max(largestReal, parallelMax(n, [&](std::size_t a) { return std::abs(modes[d][a].real()); }));
    largestImaginary =
        std::max(largestImaginary, parallelMax(n, [&](std::size_t a) { return std::abs(modes[d][a].imag()); }));
  }
  imaginaryResidue_ = largestReal > 0.0 ? largestImaginary / largestReal : 0.0;
}

template <int D>
std::span<const Vecf<D>> SpectralWind<D>::timeSlice(int l) const {
  std::size_t spatial = 1;
  for (int d = 0; d < D; ++d) spatial *= static_cast<std::size_t>(params_.resolution);
  const int mt = params_.timeSamples;
  const int wrapped = ((l % mt) + mt) % mt;
  return std::span<const Vecf<D>>(samples_).subspan(static_cast<std::size_t>(wrapped) * spatial, spatial);
}

template <int D>
void SpectralWind<D>::componentAt(int axis, double t, std::vector<float>& slice) const {
  const int mt = params_.timeSamples;
  const LinearTap time = periodicTap(t * (mt / params_.period), mt, 1);
  const auto a = timeSlice(static_cast<int>(time.lower)), b = timeSlice(static_cast<int>(time.upper));
  slice.resize(a.size());
  parallelFor(0, a.size(), [&](std::size_t i) { slice[i] = (1.0f - time.fraction) * a[i][axis] + time.fraction * b[i][axis]; }, 1 << 14);
}

template <int D>
Vec<D> SpectralWind<D>::velocity(const Vec<D>& x, double t) const {
  const int m = params_.resolution, mt = params_.timeSamples;
  std::array<LinearTap, D + 1> taps;
  std::size_t stride = 1;
  for (int d = 0; d < D; ++d) {
    taps[d] = periodicTap(x[d] * (m / params_.size), m, stride);
    stride *= static_cast<std::size_t>(m);
  }
  taps[D] = periodicTap(t * (mt / params_.period), mt, stride);
  return blendCorners<D + 1>(taps, samples_.data()).template cast<double>();
}

template class SpectralWind<2>;
template class SpectralWind<3>;

}  // namespace msim::turbulence
