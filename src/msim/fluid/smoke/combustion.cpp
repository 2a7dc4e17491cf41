#include "msim/fluid/smoke/combustion.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <tbb/parallel_for.h>

namespace msim::fluid {

namespace {
constexpr double kStefanBoltzmann = 5.670374419e-8;  // W/(m^2 K^4)
}  // namespace

double flameCreationRate(const CombustionParams& p, double fuel, double temperature) {
  if (temperature <= 0.0 || temperature < p.ignitionTemperature) return 0.0;
  return p.reactionFrequency * std::exp(-p.activationTemperature / temperature) * fuel;
}

double smokeCreationRate(const CombustionParams& p, double flame, double temperature) {
  return p.smokeFrequency * std::exp(-temperature / p.smokeTemperature) * flame;
}

double radiativeCooling(double temperature, double C, double t) {
  return 1.0 / std::cbrt(3.0 * C * t + 1.0 / (temperature * temperature * temperature));
}

template <int D>
CombustionTotals react(const CombustionParams& p, double dt, Grid<float, D>& fuel, Grid<float, D>& flame,
                       Grid<float, D>& smoke, Grid<float, D>& temperature, const Grid<float, D>* solid) {
  const double radiation = 4.0 * std::numbers::pi * p.absorption * kStefanBoltzmann / p.airHeatCapacity;
  // Fixed blocks reduced in order: the totals do not depend on the thread count.
  constexpr std::size_t kBlock = 4096;
  const std::size_t n = fuel.count(), blocks = (n + kBlock - 1) / kBlock;
  std::vector<CombustionTotals> partial(blocks);
  tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t b) {
    CombustionTotals sum;
    for (std::size_t i = b * kBlock; i < std::min(n, (b + 1) * kBlock); ++i) {
      if (solid && (*solid)[i] > 0.5f) continue;
      const double T = temperature[i];
      // Fuel decays at the Arrhenius frequency of the step's start temperature: exact exponential.
      const double burnt = fuel[i] * -std::expm1(-flameCreationRate(p, 1.0, T) * dt);
      const double flameNow = flame[i] + burnt;
      const double toSmoke = flameNow * -std::expm1(-smokeCreationRate(p, 1.0, T) * dt);
      double Tnew = T + p.heatRelease * burnt;
      if (flameNow > 0.0 && Tnew > p.ambientTemperature)
        Tnew = std::max(p.ambientTemperature, radiativeCooling(Tnew, radiation * flameNow, dt));
      fuel[i] = static_cast<float>(fuel[i] - burnt);
      flame[i] = static_cast<float>(flameNow - toSmoke);
      smoke[i] = static_cast<float>(smoke[i] + toSmoke);
      temperature[i] = static_cast<float>(Tnew);
      sum.fuelBurnt += burnt;
      sum.smokeCreated += toSmoke;
    }
    partial[b] = sum;
  });
  CombustionTotals totals;
  for (const auto& s : partial) {
    totals.fuelBurnt += s.fuelBurnt;
    totals.smokeCreated += s.smokeCreated;
  }
  return totals;
}

template CombustionTotals react<2>(const CombustionParams&, double, Grid<float, 2>&, Grid<float, 2>&, Grid<float, 2>&,
                                   Grid<float, 2>&, const Grid<float, 2>*);
template CombustionTotals react<3>(const CombustionParams&, double, Grid<float, 3>&, Grid<float, 3>&, Grid<float, 3>&,
                                   Grid<float, 3>&, const Grid<float, 3>*);

}  // namespace msim::fluid
