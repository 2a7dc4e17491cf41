#pragma once
// Helbing et al.'s (2007) "crowd pressure" P = rho Var(v), the local density times the local
// variance of velocities, which rises above about 0.02 /s^2 where a crowd turns turbulent (Golas
// eq. 4.13), with the variance taken over space or over time, and the strain-rate magnitude that
// outlines the shear bands between clusters (Fig. 4.11). On each cell of a grid, the agents of the
// (2w+1)^2 cells around it give the local density (their number over the window's area) and the
// local velocity (their mean): CrowdWindows gathers them once for all three.
#include <cstdint>
#include <span>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/crowd/agents.hpp"

namespace msim::crowd::stress {

// The agents in each cell's window of (2w+1)^2 cells: their number, velocity sum and squared-speed
// sum, for the cells whose window holds someone. A gather costs O(agents + occupied cells (2w+1)^2)
// (each occupied cell's agents added to the windows around it, as dense crowds hold several agents
// a cell) and allocates nothing once the buffers have grown.
class CrowdWindows {
 public:
  struct Sums {
    double count = 0.0, vx = 0.0, vy = 0.0, v2 = 0.0;
  };
  // std::invalid_argument for w < 0.
  CrowdWindows(const GridSpec<2>& spec, int window);
  // std::invalid_argument when the spans differ in length.
  void gather(std::span<const Vec2f> positions, std::span<const Vec2f> velocities);

  const GridSpec<2>& spec() const { return spec_; }
  // The cells whose window held someone in the last gather (each once).
  std::span<const std::uint32_t> cells() const { return touched_; }
  // The window's sums of cell c (zero where it holds nobody).
  const Sums& sums(std::size_t c) const { return totals_[c]; }
  // The area of cell c's window inside the grid [m^2].
  double area(std::size_t c) const;
  // The local density of cell c: its window's agents over the window's area [1/m^2].
  double density(std::size_t c) const { return totals_[c].count / area(c); }

 private:
  GridSpec<2> spec_;
  int window_;
  std::vector<Sums> own_, totals_;                 // each cell's own agents and its window's
  std::vector<std::uint32_t> occupied_, touched_;  // cells holding someone, windows holding someone
};

// Spatial variant: P per cell [1/s^2], the window's agents' mean squared deviation from their mean
// velocity (0 where the window holds fewer than 2 agents).
void spatialPressure(const CrowdWindows& windows, Grid<float, 2>& pressure);

// Helbing et al.'s (2007) local speed, the magnitude of the window's mean velocity (a crowd whose
// people are pushed to and fro has fast individuals but a slow local flow), averaged over the
// windows with their agent counts as weights: the crowd's mean local speed [m/s] (0 for nobody).
double meanLocalSpeed(const CrowdWindows& windows);

// |grad v + grad v^T|_F per cell [1/s] of the window-mean velocity field, by central differences
// across the cell (one-sided next to a cell whose window holds nobody; 0 where neither side has
// anyone along an axis or the cell's own window is empty). The summary is over the cells whose
// window holds someone; its coefficient of variation (spread / mean) is what sets clusters with
// shear bands between them apart from a smoothly sheared crowd (the seed's check T14).
struct StrainRateSummary {
  double mean = 0.0, max = 0.0, variation = 0.0;
  std::size_t cells = 0;
};
StrainRateSummary strainRate(const CrowdWindows& windows, Grid<float, 2>& strain);

// Temporal variant (Fig. 4.10's P(t), Fig. 4.6's maps): each cell's window-mean velocity sampled at
// every call, its variance over time and the cell's mean density over time, both with weights that
// halve every `seconds` / 2 into the past (the inconsistency metric's window, Golas ch. 3.8); the
// variance counts only the samples in which the window held someone. Cells are updated when
// occupied and decayed lazily, so a call costs O(cells with someone in their window).
class TemporalPressure {
 public:
  TemporalPressure(const GridSpec<2>& spec, double seconds);
  // One sample, `dt` after the last one: the windows as just gathered (on this grid).
  void add(const CrowdWindows& windows, double dt);
  // P per cell [1/s^2] now (0 where fewer than two samples had anyone).
  void pressure(Grid<float, 2>& out) const;
  // The mean of p over the cells whose window held someone in the last sample (the crowd's cells):
  // Fig. 4.10's scene-mean temporal pressure when p is pressure()'s.
  double meanWhereOccupied(const Grid<float, 2>& p) const;

 private:
  struct Cell {
    double time = 0.0;                    // of the last update
    double occupied = 0.0;                // weight of the samples with someone in the window
    double density = 0.0;                 // weighted sum of the window's density
    double vx = 0.0, vy = 0.0, v2 = 0.0;  // weighted sums of the mean velocity and its square
    int samples = 0;
  };
  double decay(double elapsed) const;

  GridSpec<2> spec_;
  double rate_;         // ln 2 / half-life [1/s]
  double time_ = 0.0;   // of the last sample
  double total_ = 0.0;  // weight of every sample so far (the density's denominator)
  std::vector<Cell> cells_;
};

}  // namespace msim::crowd::stress
