#include "msim/crowd/fundamental_diagram.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace msim::crowd {

std::vector<FdSample> fdSamples(std::span<const double> density, std::span<const Vec2f> velocities) {
  if (density.size() != velocities.size()) throw std::invalid_argument("fdSamples: one density per velocity");
  std::vector<FdSample> out(density.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (!std::isfinite(density[i]) || !velocities[i].allFinite())
      throw std::invalid_argument("fdSamples: sample " + std::to_string(i) + " is not finite");
    out[i] = {density[i], velocities[i].cast<double>().norm()};
  }
  return out;
}

std::vector<FdBin> binByDensity(std::span<const FdSample> samples, double binWidth, double maxDensity) {
  if (!(binWidth > 0.0) || !std::isfinite(binWidth) || !(maxDensity > 0.0) || !std::isfinite(maxDensity))
    throw std::invalid_argument("binByDensity: binWidth and maxDensity must be > 0");
  const std::size_t nBins = static_cast<std::size_t>(std::ceil(maxDensity / binWidth));
  std::vector<FdBin> bins(nBins);
  // Welford's running mean and M2 per bin: stable for many samples of similar speed.
  std::vector<double> m2(nBins, 0.0);
  for (std::size_t k = 0; k < nBins; ++k) {
    bins[k].densityLo = static_cast<double>(k) * binWidth;
    bins[k].densityHi = static_cast<double>(k + 1) * binWidth;
  }
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const FdSample& s = samples[i];
    if (!std::isfinite(s.density) || !std::isfinite(s.speed) || s.density < 0.0)
      throw std::invalid_argument("binByDensity: sample " + std::to_string(i) + " is not finite or has density < 0");
    const std::size_t k = std::min(nBins - 1, static_cast<std::size_t>(std::floor(s.density / binWidth)));
    FdBin& b = bins[k];
    ++b.count;
    const double n = static_cast<double>(b.count);
    b.meanDensity += (s.density - b.meanDensity) / n;
    const double delta = s.speed - b.meanSpeed;
    b.meanSpeed += delta / n;
    m2[k] += delta * (s.speed - b.meanSpeed);
  }
  for (std::size_t k = 0; k < nBins; ++k)
    if (bins[k].count > 1) bins[k].stdSpeed = std::sqrt(m2[k] / static_cast<double>(bins[k].count - 1));
  return bins;
}

double weidmannSpeed(double density, const WeidmannParams& p) {
  if (density <= 0.0) return p.v0;
  if (density >= p.rhoJam) return 0.0;
  return p.v0 * (1.0 - std::exp(-p.gamma * (1.0 / density - 1.0 / p.rhoJam)));
}

}  // namespace msim::crowd
