#pragma once
// Density-dependent walking speed: the fundamental diagram the UIC continuum follows by default.
//
// Narain's model walks every agent at its constant v_max until the density reaches rho_max
// (ch. 4.4.1), so a door passes rho_max v_max, about 3.6 agents/(m s) at the defaults, twice what
// people achieve (1.5-2.0 /(m s) through bottlenecks of 0.8-2.4 m: Seyfried et al. 2009, Kretz et
// al. 2006, Liddle et al. 2011). Ch. 4.4.1 suggests the remedy: make v_max depend on the density
// ("agents in dense regions have been observed to walk more slowly (Fruin, 1971)"). Here each
// pedestrian's speed is
//
//     v_i = v_max,i * v_W(rho_i) / v0,   v_W(rho) = v0 (1 - exp(-gamma (1/rho - 1/rho_jam)))
//
// with Weidmann's (1993) fundamental diagram and its published constants (v0 = 1.34 m/s,
// gamma = 1.913 /m^2, rho_jam = 5.4 /m^2; fundamental_diagram.hpp), where rho_i is the density of
// the OTHER people in a square of side `window` (1.5 m: the areas Weidmann's densities were
// counted over) centred `lookahead` ahead of the pedestrian along its preferred direction, over the
// free (walkable) part of that square. Counting the space one walks into, rather than a window
// centred on oneself, is what makes a bottleneck's flow come out as measured: the pedestrian in a
// door has the queue behind and free space ahead, and walks out at the speed that space allows.
// Counting only the others gives a lone walker its free speed. Calibration (docs/evacuation.md):
// with these two geometric choices and no fitted constant, doors of 0.8, 1.2, 1.6 and 2.4 m pass
// 1.6-1.9 agents/(m s).
//
// The square is made of whole cells of a fine grid (at most 0.25 m; `window` rounded to a whole
// number of them) and sits on the cell lines nearest its centre, so its sides move by at most half
// a cell. The free area of every such square comes once from the static obstacles; the people of
// every square that can hold someone are counted each step by two sliding sums over the cells
// people stand in. Each pedestrian then costs two lookups whatever the density. Outside the
// walkable box counts as covered; moving obstacles (vehicles) count as free, so a pedestrian beside a vehicle reads a
// slightly lower density than it stands in.
#include <cstdint>
#include <span>
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/crowd/fundamental_diagram.hpp"
#include "msim/crowd/polygon.hpp"

namespace msim::crowd {

struct SpeedDensitySettings {
  bool enabled = true;     // off: the seed's constant v_max (Narain ch. 4.4.1)
  WeidmannParams weidmann;
  double window = 1.5;     // side of the counting square [m]
  double lookahead = 0.5;  // its centre ahead of the pedestrian [m], at most window / 2 - 0.25 so it holds them
  // The least free area a square counts as [m^2]: a pedestrian squeezed into a corner, with a
  // sliver of walkable floor in its square, does not read an extreme density from one neighbour.
  double minFreeArea = 0.5;
};

class WalkingDensity {
 public:
  // The walkable box [lo, hi] and its static obstacles. Throws std::invalid_argument for settings
  // out of range (window <= 0, lookahead < 0 or > window / 2 - 0.25 m, minFreeArea <= 0, Weidmann
  // constants <= 0) or an empty box, InputError for a degenerate polygon (as FreeArea).
  WalkingDensity(const Vec2& lo, const Vec2& hi, std::span<const Polygon> obstacles, const SpeedDensitySettings& settings);

  // For each person k at people[k] (everyone in the scene, whatever their model) walking along
  // preferred[k]: rho_k, the others per free square metre in the square ahead, and
  // speed[k] = maxSpeed[k] v_W(rho_k) / v0. Spans of equal size; parallel; no allocation once warm.
  void measure(std::span<const Vec2f> people, std::span<const Vec2f> preferred, std::span<const float> maxSpeed,
               std::span<float> density, std::span<float> speed);

  // The free area [m^2] of the axis-aligned square of side `window` centred at c (clamped to the
  // walkable box), exact for the table's cells (bilinear between its corners).
  double freeArea(const Vec2& c) const;
  const SpeedDensitySettings& settings() const { return settings_; }

 private:
  static constexpr int kOpenCounts = 64;          // counts whose open-floor speeds are tabulated
  static constexpr std::uint16_t kWhole = 65535;  // a square's free area when it is all floor

  double integral(double x, double y) const;  // free area of [lo, (x, y)], bilinear in the table
  // The square whose lower-left corner is cell (ia, ja), ia in [-pad_, nx_), ja in [-pad_, ny_).
  std::size_t corner(int ia, int ja) const {
    return static_cast<std::size_t>(ja + pad_) * static_cast<std::size_t>(cornersX_) + static_cast<std::size_t>(ia + pad_);
  }

  SpeedDensitySettings settings_;
  Vec2 lo_, hi_;
  double cell_ = 0.25;
  int nx_ = 0, ny_ = 0;
  int across_ = 1, pad_ = 0, cornersX_ = 0;  // cells across a square; corners before the box; corners per row
  double fullArea_ = 0.0;                    // a square of open floor [m^2]
  std::vector<double> table_;                // (nx_ + 1) x (ny_ + 1) corners: free area of [lo, corner]
  std::vector<std::uint16_t> freeSquare_;    // per square (corner()): its free area in fullArea_ / kWhole
  std::vector<float> openSpeed_;             // v_W(k / fullArea_) / v0 for k others, k < kOpenCounts
  // This step's people: per cell; per cell row and square column; per square (corner()). Counted
  // modulo 2^16 (half the memory of 32 bits, and twice the lanes of the sums): exact while a
  // square holds fewer than 65536 people.
  std::vector<std::uint16_t> cellPeople_, rowSums_, squarePeople_;
};

}  // namespace msim::crowd
