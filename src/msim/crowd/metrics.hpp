#pragma once
// Per-frame crowd metrics: grid density, speed statistics and the nearest-neighbour validation of
// Narain (2011, sec. 4.5.1): "the distance of each agent to its nearest neighbor was measured over
// all frames ... a mean of 1.25 d_min in the densest regions, and less than 0.12% of agents
// approach slightly closer than d_min". Voronoi density, measurement lines and fundamental
// diagrams live in voronoi_density.hpp, measurement_line.hpp and fundamental_diagram.hpp.
#include <cstddef>
#include <limits>
#include <span>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/crowd/agents.hpp"

namespace msim::crowd {

// Agents per m^2 of free area in each cell of `spec`: count / (dx^2 f), with f the free-area
// fraction of the cell (Narain 2011 sec. 4.4.3 scales rho_max by the same f), or 1 if
// `freeFraction` is null. Agents outside the grid are not counted; cells with f <= 0 get 0.
// std::invalid_argument for non-finite positions or a free-fraction grid over another spec.
Grid<double, 2> gridDensity(const GridSpec<2>& spec, std::span<const Vec2f> positions,
                            const Grid<double, 2>* freeFraction = nullptr);

// Linear-interpolation percentile (Hyndman & Fan 1996, type 7, the default of R and NumPy) of
// q in [0, 1]; `sorted` ascending and non-empty.
double percentile(std::span<const double> sorted, double q);

struct SpeedStats {
  std::size_t count = 0;
  double mean = 0.0, stddev = 0.0;  // population standard deviation [m/s]
  double min = 0.0, p05 = 0.0, p25 = 0.0, median = 0.0, p75 = 0.0, p95 = 0.0, max = 0.0;
};
// Statistics of |v_i|; all zero for no agents. std::invalid_argument for non-finite velocities.
SpeedStats speedStats(std::span<const Vec2f> velocities);

// Nearest neighbour of each agent among those closer than `searchRadius`. With per-agent radii
// the contact distance of a pair is d_min = r_i + r_j (agents.hpp), so "nearest" is measured in
// units of it: ratio_i = min_j |x_i - x_j| / (r_i + r_j). For equal radii that is the nearest
// distance / d_min.
struct NearestNeighbours {
  std::vector<double> distance;  // |x_i - x_j| for the j minimising the ratio; +inf if none [m]
  std::vector<double> ratio;     // |x_i - x_j| / (r_i + r_j); +inf if none
};
// Uses NeighbourGrid. std::invalid_argument for mismatched sizes, non-finite positions, radii <= 0
// or searchRadius <= 0.
NearestNeighbours nearestNeighbours(std::span<const Vec2f> positions, std::span<const float> radii,
                                    double searchRadius);

struct NearestNeighbourOptions {
  // rho_max of the UIC, Narain (2011) eq. 4.4: 2 alpha / (sqrt(3) d_min^2) [1/m^2]; > 0.
  double rhoMax = 0.0;
  // "Dense" agents have local density >= denseFraction * rhoMax.
  double denseFraction = 0.9;
  // An agent is "closer than d_min" if its ratio < 1 - contactTolerance: float positions of
  // agents placed exactly d_min apart must not count as overlapping.
  double contactTolerance = 1e-6;
};

// The validation numbers of one frame, kept as sums so frames can be pooled.
struct NearestNeighbourFrame {
  std::size_t agents = 0;        // agents in the frame
  std::size_t closer = 0;        // agents with ratio < 1 - tolerance
  std::size_t dense = 0;         // agents in dense regions with a neighbour within searchRadius
  std::size_t denseCloser = 0;   // of those, closer than d_min
  double denseRatioSum = 0.0;    // sum of their ratios
  double minRatio = std::numeric_limits<double>::infinity();

  double meanDenseRatio() const;  // mean NN distance / d_min in dense regions (NaN if none)
  double fractionCloser() const;  // closer / agents (0 if no agents)
};
// `localDensity` per agent (e.g. voronoiDensity or the grid density at the agent) [1/m^2].
NearestNeighbourFrame nearestNeighbourFrame(const NearestNeighbours& nn, std::span<const double> localDensity,
                                            const NearestNeighbourOptions& options);

// Pools frames as in the seed ("over all frames of the circle scenario"): every agent of every
// frame is one sample.
class NearestNeighbourAccumulator {
 public:
  void add(const NearestNeighbourFrame& frame);
  const NearestNeighbourFrame& total() const { return total_; }
  std::size_t frames() const { return frames_; }

 private:
  NearestNeighbourFrame total_;
  std::size_t frames_ = 0;
};

}  // namespace msim::crowd
