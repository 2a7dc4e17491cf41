#include "msim/turbulence/kolmogorov_spectrum.hpp"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "msim/core/error.hpp"

namespace msim::turbulence {

double KolmogorovSpectrum::lowWavenumber() const { return 2.0 * std::numbers::pi / largestEddy; }
double KolmogorovSpectrum::highWavenumber() const { return 2.0 * std::numbers::pi / smallestEddy; }

double KolmogorovSpectrum::energy(double k) const {
  if (!(k >= lowWavenumber() && k <= highWavenumber())) return 0.0;
  return kolmogorovConstant * std::cbrt(dissipation * dissipation) * std::pow(k, -5.0 / 3.0);
}

double KolmogorovSpectrum::kineticEnergy() const {
  return 1.5 * kolmogorovConstant * std::cbrt(dissipation * dissipation) *
         (std::pow(lowWavenumber(), -2.0 / 3.0) - std::pow(highWavenumber(), -2.0 / 3.0));
}

double KolmogorovSpectrum::speedRms() const { return std::sqrt(2.0 * kineticEnergy()); }

double KolmogorovSpectrum::dissipationForSpeedRms(double u) const {
  // kineticEnergy() is proportional to epsilon^(2/3).
  const double range = 1.5 * kolmogorovConstant * (std::pow(lowWavenumber(), -2.0 / 3.0) - std::pow(highWavenumber(), -2.0 / 3.0));
  return std::pow(0.5 * u * u / range, 1.5);
}

void KolmogorovSpectrum::validate(const std::string& where) const {
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(kolmogorovConstant))
    throw InputError(fmt::format("{}: the Kolmogorov constant must be positive (about 1.5), got {}", where, kolmogorovConstant));
  if (!positive(dissipation))
    throw InputError(fmt::format("{}: the dissipation rate epsilon must be positive (E = C_K epsilon^(2/3) k^(-5/3) "
                                 "is an energy), got {}",
                                 where, dissipation));
  if (!positive(largestEddy) || !positive(smallestEddy))
    throw InputError(fmt::format("{}: eddy sizes must be positive, got largest {} m and smallest {} m", where,
                                 largestEddy, smallestEddy));
  if (smallestEddy >= largestEddy)
    throw InputError(fmt::format("{}: the cutoff (smallest eddy {} m) must lie below the largest scale (largest eddy "
                                 "{} m): the inertial range would be empty",
                                 where, smallestEddy, largestEddy));
}

}  // namespace msim::turbulence
