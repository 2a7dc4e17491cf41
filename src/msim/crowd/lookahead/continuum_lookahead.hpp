#pragma once
// The continuum local collision avoidance of Golas ch. 3.5 and its lookahead. People walk at the
// speed the density allows, f(rho) = v_free max(0, 1 - rho / rho_max) (the chapter's "linear
// form" of the fundamental diagram; its formula is not printed, so this one is an assumption
// that meets the chapter's rho_max = 5.5 /m^2, floored at Chapter 4's 0.01 m/s), and choose the
// direction that makes most progress along the preferred velocity v_p over a planning horizon
// T, the density changing along the way at the rate f v.grad(rho) (eq. 3.1):
//   v* = argmax_{|v| <= 1} v_p.v + (f' T / 2) (v.grad rho) (v_p.v)        (eq. 3.2)
// by an ascent from the current direction; the agent walks f(rho) v*. No pressure solve: each
// agent decides on its own. The seed ascends by projected gradient steps whose size it does not
// give; J's maximum over the disc lies on its edge (bestDirection), and Newton steps along the
// edge reach it in 2-4 iterations where fixed steps of 1 / (|v_p| (1 + |f'| T |grad rho|)) took
// up to 20 against steep gradients.
// The lookahead (Fig. 3.4) asks this question on the future densities (future_density.hpp) from
// the agent's depth L down to level 0, each level's answer the next one's preferred direction:
// far levels steer around congestion that will be there, near ones have the last word.
#include "msim/core/vec.hpp"
#include "msim/crowd/lookahead/future_density.hpp"

namespace msim::crowd::lookahead {

struct ContinuumSettings {
  double maxDensity = 5.5;      // rho_max [1/m^2]: f(rho) = 0 from here on
  double planHorizon = 1.0;     // T of eq. 3.1 [s] (not given in the seed; its suggested 1 s)
  int maxIterations = 20;       // of the gradient ascent (the seed: fewer than 10 on average)
  double tolerance = 1e-4;      // the ascent stops once a step turns the direction by less than this [rad]
  double slowest = 0.01;        // f's floor [m/s] (Chapter 4's)
};

// f(rho) and its slope df/drho at `density` for an agent whose free walking speed is `freeSpeed`.
double continuumSpeed(double density, double freeSpeed, const ContinuumSettings& settings);
double continuumSpeedSlope(double density, double freeSpeed, const ContinuumSettings& settings);

struct DirectionChoice {
  Vec2 direction = Vec2::Zero();  // |v*| <= 1
  int iterations = 0;
  bool converged = false;
};
// Eq. 3.2 by ascent along the unit circle from `start` (a direction; zero starts along v_p): the
// nearest local maximum, |v*| = 1. v_p = 0 has no best direction: zero, converged.
DirectionChoice bestDirection(const Vec2& preferred, const Vec2& densityGradient, double speedSlope, const Vec2& start,
                              const ContinuumSettings& settings);

struct CascadeResult {
  Vec2 velocity = Vec2::Zero();
  int iterations = 0;  // of all levels' ascents
  int solves = 0;      // levels asked
};
// The lookahead of an agent at x walking at v (its current velocity) towards v_p, free speed
// `freeSpeed`: eq. 3.2 on levels depth, depth - 1, .., `lowest`, each at the agent's extrapolation
// x + v dt_i, its answer the next level's preferred direction at the planner's preferred speed.
// With lowest = 0 the result is the continuum LCA's velocity f(rho_0) v*; with lowest = 1 (the
// level-0 decision is left to another model, the UIC or ORCA) the preferred velocity the far levels
// suggest, |v_p| v*.
CascadeResult continuumLookahead(const FutureDensity& future, const ContinuumSettings& settings, const Vec2f& x,
                                 const Vec2f& v, const Vec2f& preferred, double freeSpeed, int depth, int lowest);

}  // namespace msim::crowd::lookahead
