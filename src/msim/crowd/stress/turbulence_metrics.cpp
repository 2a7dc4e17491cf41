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

std::size_t SamplesByDensity::bin(double density) {
  return static_cast<std::size_t>(std::clamp(static_cast<int>(density / kBinWidth), 0, kBins - 1));
}

void SamplesByDensity::addCell(double density, bool isTurbulent) {
  const std::size_t b = bin(density);
  ++cells[b];
  turbulentCells[b] += isTurbulent;
}

void SamplesByDensity::addAgent(double density, const Vec2f& velocity, const Vec2f& preferred) {
  const std::size_t b = bin(density);
  const Vec2f e = preferred.normalized();
  const double forward = velocity.dot(e), sideways = e.x() * velocity.y() - e.y() * velocity.x();
  ++agents[b];
  backward[b] += forward < 0.0;
  forward2[b] += forward * forward;
  sideways2[b] += sideways * sideways;
}

TurbulenceMetrics::TurbulenceMetrics(const GridSpec<2>& grid)
    : windows_(grid, kWindowCells), sampler_(grid, kWindowSeconds), standstills_(grid), spatial_(grid), temporal_(grid), strain_(grid), peak_(grid) {}

void TurbulenceMetrics::sample(const Agents& agents, double dt) {
  windows_.gather(agents.position, agents.velocity);
  sampler_.add(windows_, dt);
  standstills_.sample(agents, dt);
}

TurbulenceFrame TurbulenceMetrics::measure(const Agents& agents, bool summarize) {
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
  if (summarize) {
    for (std::size_t c = 0; c < temporal_.count(); ++c) peak_[c] = std::max(peak_[c], temporal_[c]);
    for (const std::uint32_t c : windows_.cells())
      byDensity_.addCell(windows_.density(c), temporal_[c] > kTurbulentPressure);
    for (std::size_t i = 0; i < agents.size(); ++i)
      if (agents.preferredVelocity[i].squaredNorm() > 0.0f)  // not arrived, nor standing by choice
        byDensity_.addAgent(windows_.density(windows_.spec().clampedCellIndex(agents.position[i])), agents.velocity[i],
                            agents.preferredVelocity[i]);
  }
  f.temporalPressureMean = sampler_.meanWhereOccupied(temporal_);
  f.strainRate = stress::strainRate(windows_, strain_);
  f.localSpeed = stress::meanLocalSpeed(windows_);
  f.standing = standstills_.standing();
  f.standstillEpisodes = standstills_.episodes();
  return f;
}

}  // namespace msim::crowd::stress
