#include "msim/crowd/stress/turbulence_metrics.hpp"

#include <algorithm>

namespace msim::crowd::stress {

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
  for (std::size_t c = 0; c < spatial_.count(); ++c) {
    f.pressureMax = std::max(f.pressureMax, double(spatial_[c]));
    f.pressureCellsOver += spatial_[c] > kTurbulentPressure;
    f.temporalPressureMax = std::max(f.temporalPressureMax, double(temporal_[c]));
    f.temporalCellsOver += temporal_[c] > kTurbulentPressure;
    peak_[c] = std::max(peak_[c], temporal_[c]);
  }
  f.temporalPressureMean = sampler_.meanWhereOccupied(temporal_);
  f.strainRate = stress::strainRate(windows_, strain_);
  f.localSpeed = stress::meanLocalSpeed(windows_);
  f.standing = standstills_.standing();
  f.standstillEpisodes = standstills_.episodes();
  return f;
}

}  // namespace msim::crowd::stress
