#pragma once
// What a crowd-safety engineer reads off a crowd for turbulence (Golas ch. 4.4): Helbing's crowd
// pressure with the variance over space (3 x 3 cells) and over time (a 3 s window, the seed's
// pressure maps of Fig. 4.6), the scene-mean temporal pressure of Fig. 4.10 and the strain-rate
// magnitude of Fig. 4.11, on the crowd's grid, and the standstill episodes of stop-and-go waves
// (standstill.hpp). The crowd is sampled every step (the temporal variance and the standstills
// need every step's velocities) and measured once per frame.
#include <array>

#include "msim/core/grid.hpp"
#include "msim/crowd/stress/crowd_pressure.hpp"
#include "msim/crowd/stress/standstill.hpp"

namespace msim::crowd::stress {

// A pressure field's largest value and the cells above the turbulent threshold.
struct PressureSummary {
  double max = 0.0;  // [1/s^2]
  long cellsOver = 0;
};
PressureSummary summarizePressure(const Grid<float, 2>& pressure, double threshold);

// At which densities the crowd turns turbulent, binned by the density of a cell's window now:
// - the (cell, frame) samples of the crowd's cells and how many had a temporal pressure above the
//   turbulent 0.02 /s^2 (checks T10 and T15: P > 0.02 only from 7 /m^2 in the Hajj, from
//   5.5 /m^2 at the Love Parade);
// - the (agent, frame) samples of the agents that want to walk, by their cell's window: those
//   moving away from their goal (backward: v . e < 0 with e the preferred direction) and the sums
//   of the squared forward and sideways speeds (check T12: at least 1% backward and a sideways
//   rms of at least 0.3 of the forward rms where the crowd is turbulent, under 0.1 in a laminar
//   flow; Fig. 4.4's v_x and v_y).
struct SamplesByDensity {
  static constexpr double kBinWidth = 0.5;  // [1/m^2]
  static constexpr int kBins = 24;          // the last bin holds everything from 11.5 /m^2 on
  std::array<long, kBins> cells{}, turbulentCells{};
  std::array<long, kBins> agents{}, backward{};
  std::array<double, kBins> forward2{}, sideways2{};  // [m^2/s^2]
  static std::size_t bin(double density);
  void addCell(double density, bool isTurbulent);
  // An agent walking at `velocity` that prefers `preferred` (nonzero).
  void addAgent(double density, const Vec2f& velocity, const Vec2f& preferred);
};

struct TurbulenceFrame {
  double pressureMax = 0.0;           // spatial variance [1/s^2]
  long pressureCellsOver = 0;         // cells above the turbulent 0.02 /s^2
  double temporalPressureMax = 0.0;   // temporal variance [1/s^2]
  double temporalPressureMean = 0.0;  // over the crowd's cells (Fig. 4.10)
  long temporalCellsOver = 0;
  StrainRateSummary strainRate;       // [1/s]
  double localSpeed = 0.0;            // the crowd's mean local speed (Helbing's) [m/s]
  long standing = 0;                  // agents in a standstill episode now
  long standstillEpisodes = 0;        // since the start
};

class TurbulenceMetrics {
 public:
  static constexpr double kTurbulentPressure = 0.02;  // [1/s^2] (Helbing et al. 2007)
  static constexpr int kWindowCells = 1;              // the spatial windows: 3 x 3 cells
  static constexpr double kWindowSeconds = 3.0;       // the temporal window (Fig. 4.6)

  explicit TurbulenceMetrics(const GridSpec<2>& grid);
  void sample(const Agents& agents, double dt);
  // This frame's figures; with `summarize` the frame also joins the run-long summaries below (a
  // run leaves out its start's transient by passing false until then).
  TurbulenceFrame measure(const Agents& agents, bool summarize = true);

  // The last measure()'s fields.
  const Grid<float, 2>& spatialPressure() const { return spatial_; }
  const Grid<float, 2>& temporalPressure() const { return temporal_; }
  const Grid<float, 2>& strainRate() const { return strain_; }
  // Each cell's largest temporal pressure over the summarized frames: where the crowd turned
  // turbulent during the run.
  const Grid<float, 2>& peakTemporalPressure() const { return peak_; }
  // The summarized frames' samples by density.
  const SamplesByDensity& samplesByDensity() const { return byDensity_; }

 private:
  CrowdWindows windows_;
  TemporalPressure sampler_;
  StandstillDetector standstills_;
  Grid<float, 2> spatial_, temporal_, strain_, peak_;
  SamplesByDensity byDensity_;
};

}  // namespace msim::crowd::stress
