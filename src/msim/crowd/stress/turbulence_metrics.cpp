#include "msim/crowd/stress/turbulence_metrics.hpp"

#include <algorithm>

namespace msim::crowd::stress {

PressureSummary summarizePressure(const Grid<float, 2>& pressure, double threshold) {
  PressureSummary s;
  for (std::size_t c = 0; c < pressure.count(); ++c) {
    s.max = std::max(s.max, double(pressure[c]));
    s.cellsOver += pressure[c] > threshold;
  }
  return s;
}

void PressureByDensity::add(double density, bool isTurbulent) {
  const int bin = std::clamp(static_cast<int>(density / kBinWidth), 0, kBins - 1);
  ++samples[static_cast<std::size_t>(bin)];
  turbulent[static_cast<std::size_t>(bin)] += isTurbulent;
}

TurbulenceMetrics::TurbulenceMetrics(const GridSpec<2>& grid)
    : windows_(grid, kWindowCells), sampler_(grid, kWindowSeconds), standstills_(grid), spatial_(grid), temporal_(grid), strain_(grid), peak_(grid) {}

void TurbulenceMetrics::sample(const Agents& agents, double dt) {
  windows_.gather(agents.position, agents.velocity);
  sampler_.add(windows_, dt);
  standstills_.sample(agents, dt);
}

TurbulenceFrame TurbulenceMetrics::measure(const Agents& agents) {
  TurbulenceFrame f;
  windows_.gather(agents.position, agents.velocity);
  stress::spatialPressure(windows_, spatial_);
  sampler_.pressure(temporal_);
  const PressureSummary spatial = summarizePressure(spatial_, kTurbulentPressure);
  const PressureSummary temporal = summarizePressure(temporal_, kTurbulentPressure);
  f.pressureMax = spatial.max;
  f.pressureCellsOver = spatial.cellsOver;
  f.temporalPressureMax = temporal.max;
  f.temporalCellsOver = temporal.cellsOver;
  for (std::size_t c = 0; c < temporal_.count(); ++c) peak_[c] = std::max(peak_[c], temporal_[c]);
  for (const std::uint32_t c : windows_.cells())
    byDensity_.add(windows_.sums(c).count / windows_.area(c), temporal_[c] > kTurbulentPressure);
  f.temporalPressureMean = sampler_.meanWhereOccupied(temporal_);
  f.strainRate = stress::strainRate(windows_, strain_);
  f.localSpeed = stress::meanLocalSpeed(windows_);
  f.standing = standstills_.standing();
  f.standstillEpisodes = standstills_.episodes();
  return f;
}

}  // namespace msim::crowd::stress
