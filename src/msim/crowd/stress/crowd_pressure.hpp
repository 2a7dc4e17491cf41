#pragma once
// Helbing et al.'s (2007) "crowd pressure" P = rho Var(v), the local density times the local
// variance of velocities, which rises above about 0.02 /s^2 where a crowd turns turbulent (Golas
// eq. 4.13), with the variance taken over space or over time, and the strain-rate magnitude that
// outlines the shear bands between clusters (Fig. 4.11). On each cell of a grid, the agents of the
// (2w+1)^2 cells around it give the local density (their number over the window's area) and the
// local velocity (their mean).
#include <span>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/crowd/agents.hpp"

namespace msim::crowd::stress {

// Spatial variant: P per cell [1/s^2], the window's agents' mean squared deviation from their mean
// velocity (0 where the window holds fewer than 2 agents); `window` w >= 0 cells.
void spatialPressure(std::span<const Vec2f> positions, std::span<const Vec2f> velocities, int window,
                     Grid<float, 2>& pressure);

// |grad v + grad v^T|_F per cell [1/s] of the window-mean velocity field, by central differences
// across the cell (one-sided next to a cell whose window holds nobody; 0 where neither side has
// anyone along an axis or the cell's own window is empty). The summary is over the cells whose
// window holds someone; its coefficient of variation (spread / mean) is what sets clusters with
// shear bands between them apart from a smoothly sheared crowd (the seed's check T14).
struct StrainRateSummary {
  double mean = 0.0, max = 0.0, variation = 0.0;
  std::size_t cells = 0;
};
StrainRateSummary strainRate(std::span<const Vec2f> positions, std::span<const Vec2f> velocities, int window,
                             Grid<float, 2>& strain);

// Temporal variant (Fig. 4.10's P(t), Fig. 4.6's maps): each cell's window-mean velocity sampled at
// every call, its variance over time and the cell's mean density over time, both with weights that
// halve every `window` / 2 seconds into the past (the inconsistency metric's window, Golas ch. 3.8);
// the variance counts only the samples in which the window held someone. Cells are updated when
// occupied and decayed lazily, so a call costs O(agents + occupied cells).
class TemporalPressure {
 public:
  TemporalPressure(const GridSpec<2>& spec, int window, double seconds);
  // One sample of the crowd at the current time, `dt` after the last one.
  void add(std::span<const Vec2f> positions, std::span<const Vec2f> velocities, double dt);
  // P per cell [1/s^2] now (0 where fewer than two samples had anyone).
  void pressure(Grid<float, 2>& out) const;
  // The mean of p over the cells whose window held someone in the last sample (the crowd's cells):
  // Fig. 4.10's scene-mean temporal pressure when p is pressure()'s.
  double meanWhereOccupied(const Grid<float, 2>& p) const;

 private:
  struct Cell {
    double time = 0.0;                  // of the last update
    double occupied = 0.0;              // weight of the samples with someone in the window
    double density = 0.0;               // weighted sum of the window's density
    double vx = 0.0, vy = 0.0, v2 = 0.0;  // weighted sums of the mean velocity and its square
    int samples = 0;
  };
  double decay(double elapsed) const;

  GridSpec<2> spec_;
  int window_;
  double rate_;         // ln 2 / half-life [1/s]
  double time_ = 0.0;   // of the last sample
  double total_ = 0.0;  // weight of every sample so far (the density's denominator)
  std::vector<Cell> cells_;
  struct Sums {
    double count = 0.0, vx = 0.0, vy = 0.0;
  };
  // Per-sample scratch: each cell's own agents and its window's, and the cells holding someone
  // (occupied_) or with someone in their window (touched_).
  std::vector<Sums> own_, windowTotals_;
  std::vector<std::uint32_t> occupied_, touched_;
};

}  // namespace msim::crowd::stress
