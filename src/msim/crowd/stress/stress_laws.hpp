#pragma once
// The material laws of inter-personal stress in extreme crowds (Golas ch. 4.3): once people are
// pressed together, discomfort p = g(rho) pushes them apart (the isotropic stress) and friction
// (the trace-free stress s, bounded by the Drucker-Prager yield criterion |s|_F <= sqrt(3) alpha p,
// eq. 4.11) resists their sliding past each other. Both vanish below the critical density, where
// navigation alone moves the crowd (eq. 4.3), and people's accelerations are bounded (eq. 4.7).
#include "msim/core/vec.hpp"

namespace msim::crowd::stress {

struct StressLaws {
  double critical = 3.5;   // rho_crit [1/m^2]: no stress below
  double yield = 5.5;      // rho_yield [1/m^2]: the discomfort's plateau and full friction from here
  double c1 = 13.33;       // eq. 4.10's scale
  double c2 = 1.5;         // eq. 4.10's offset
  double epsilon = 0.01;   // eq. 4.10's guard against the pole at rho_yield [1/m^2]
  // Eq. 4.10 as printed jumps from 0 to 31.4 at rho_crit (c2 = 1.5 makes it continuous nowhere);
  // the chapter asks for zero gradient below rho_crit, which a constant lower branch at the middle
  // branch's value there gives without the jump (continuous, the default); literal: 0 below.
  bool continuousLowerBranch = true;
  double frictionMax = 0.75;  // alpha above rho_yield
};

// p = g(rho) (eq. 4.10): the lower branch below rho_crit; c1 rho / sqrt(rho_yield - rho + eps) - c2
// up to rho_yield; c3 rho - c2 above, c3 = c1 / sqrt(eps) for continuity there.
double discomfort(double density, const StressLaws& laws);
// dg/drho, 0 on the lower branch.
double discomfortSlope(double density, const StressLaws& laws);
// alpha(rho): 0 below rho_crit, linear to frictionMax at rho_yield, frictionMax above.
double frictionCoefficient(double density, const StressLaws& laws);
// The bound b of each trace-free stress component (s_d = s_xx = -s_yy and s_o = s_xy) that keeps
// |s|_F = sqrt(2 s_d^2 + 2 s_o^2) <= sqrt(3) alpha g (eq. 4.11): the inscribed box,
// b = sqrt(3) / 2 alpha g (the chapter's infinity-norm approximation of the cone).
double frictionBound(double density, const StressLaws& laws);

// Eq. 4.7: the acceleration a scaled down to at most maxAcceleration, its direction kept.
Vec2 clampAcceleration(const Vec2& acceleration, double maxAcceleration);

}  // namespace msim::crowd::stress
