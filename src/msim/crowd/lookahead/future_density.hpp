#pragma once
// The continuum lookahead's pyramid of future densities (Golas ch. 3.5): level i holds the crowd
// as it will be dt_i ahead (horizons.hpp), every agent splatted at its straight-line extrapolation
// x_j + v_j dt_i, on a grid c^i times coarser than level 0's: an agent's predicted position grows
// more uncertain with the horizon, and a coarser cell spreads its unit mass over a wider, weaker
// footprint (the seed stores the future on coarser grids instead of widening each splat).
// Splats are bilinear (cloud in cell, core/transfer.hpp) and densities people per m^2. Level 0,
// the crowd now, also holds the local mean velocity and the spread of velocities about it, which
// the hybrid's blend weights read (eqs. 3.12-3.13). An agent asking about the density around it
// does not count itself: its own splat is taken out of what it samples.
#include <span>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/transfer.hpp"
#include "msim/core/vec.hpp"
#include "msim/crowd/agents.hpp"
#include "msim/crowd/lookahead/horizons.hpp"

namespace msim::crowd::lookahead {

// Which levels FutureDensity::build() splats: level 0 (the crowd now) and the far levels
// 1..levels. Levels left out keep what the last build gave them.
struct DensityLevels {
  bool now = true, far = true;
};

class FutureDensity {
 public:
  // Splats every agent into the levels asked for, over the walkable box [lo, hi] (extrapolated
  // positions beyond it stop at its walls), level 0's cells `cell` wide [m].
  void build(const HorizonSchedule& schedule, double cell, const Vec2& lo, const Vec2& hi,
             std::span<const Vec2f> positions, std::span<const Vec2f> velocities, DensityLevels which = {});

  int levels() const { return static_cast<int>(counts_.size()) - 1; }
  // Where an agent at x with velocity v was splatted at `level` (its extrapolation, clamped to the box).
  Vec2 predicted(int level, const Vec2f& x, const Vec2f& v) const;

  struct Density {
    double value = 0.0;                 // [1/m^2]
    Vec2 gradient = Vec2::Zero();       // [1/m^3]
  };
  // The density of `level` at `at` and its gradient (central differences between the level's
  // samples, both interpolated bilinearly).
  Density density(int level, const Vec2& at) const;
  // The same less a unit mass splatted at `at`: what an agent predicted there sees of the others.
  // (Its own splat's central-difference gradient vanishes at its own position.)
  Density othersDensity(int level, const Vec2& at) const;

  struct Flow {
    double density = 0.0;          // [1/m^2], everyone counted
    Vec2 meanVelocity = Vec2::Zero();  // density-weighted [m/s]
    double speedDeviation = 0.0;   // sigma_v: the density-weighted rms of v - mean [m/s]
  };
  // The crowd now (level 0) at `at`.
  Flow flow(const Vec2& at) const;

 private:
  // Each level's density and gradient per sample, interleaved (rho, d/dx, d/dy), and the taps of
  // the bilinear interpolation at a point.
  struct Level {
    GridSpec<2> spec;
    int nx = 0, ny = 0;
    std::vector<float> fields;
  };
  struct Taps {
    std::size_t corner = 0;  // sample (i0, j0)
    double a = 0.0, b = 0.0; // fractions towards i0 + 1, j0 + 1
  };
  Taps taps(const Level& level, const Vec2& at) const;
  Density interpolate(const Level& level, const Taps& t) const;
  void differentiate(std::size_t level);

  Vec2 lo_ = Vec2::Zero(), hi_ = Vec2::Zero();
  std::vector<double> horizon_;              // dt_i per level
  std::vector<Grid<float, 2>> counts_;       // agents per sample, per level
  std::vector<Level> levels_;
  Grid<float, 2> velocityX_, velocityY_, speed2_;  // level 0: sums of v_x, v_y and |v|^2 per sample
  std::vector<Splatter<2>> splatters_;
  std::vector<std::vector<Vec2f>> predicted_;  // per level, scratch
  std::vector<float> ones_, vx_, vy_, v2_;
};

}  // namespace msim::crowd::lookahead
