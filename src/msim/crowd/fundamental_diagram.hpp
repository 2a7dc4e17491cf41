#pragma once
// Fundamental diagram data: speed against local density, per agent or per measurement area,
// binned by density, and Weidmann's empirical curve to compare with. Weidmann (1993),
// "Transporttechnik der Fussgaenger", Schriftenreihe des IVT 90, ETH Zuerich, fits
//   v(rho) = v0 (1 - exp(-gamma (1/rho - 1/rho_jam)))
// to published pedestrian data for walking on the flat.
#include <cstddef>
#include <span>
#include <vector>

#include "msim/crowd/agents.hpp"

namespace msim::crowd {

struct FdSample {
  double density = 0.0;  // [1/m^2]
  double speed = 0.0;    // [m/s]
};

// (density_i, |v_i|) per agent. std::invalid_argument for mismatched sizes or non-finite data.
std::vector<FdSample> fdSamples(std::span<const double> density, std::span<const Vec2f> velocities);

struct FdBin {
  double densityLo = 0.0, densityHi = 0.0;  // [lo, hi) [1/m^2]
  std::size_t count = 0;
  double meanDensity = 0.0;  // [1/m^2]
  double meanSpeed = 0.0;    // [m/s]
  double stdSpeed = 0.0;     // sample standard deviation (n - 1), 0 for fewer than 2 [m/s]
};

// Bins [k w, (k+1) w) for k = 0 .. ceil(maxDensity / w) - 1; samples at or beyond maxDensity go
// to the last bin, negative densities are rejected. Empty bins are kept (count 0) so bins of
// different runs line up. std::invalid_argument for w <= 0, maxDensity <= 0 or non-finite data.
std::vector<FdBin> binByDensity(std::span<const FdSample> samples, double binWidth, double maxDensity);

struct WeidmannParams {
  double v0 = 1.34;      // free walking speed [m/s]
  double gamma = 1.913;  // [1/m^2]
  double rhoJam = 5.4;   // density at which walking stops [1/m^2]
};

// Weidmann's v(rho); v0 for rho <= 0 (the limit) and 0 for rho >= rho_jam, where the formula
// would turn negative.
double weidmannSpeed(double density, const WeidmannParams& params = {});

}  // namespace msim::crowd
