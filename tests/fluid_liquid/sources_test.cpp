// Emitters, sinks and open sides (issue #24): a hose delivers about its velocity times its
// cross-section per second (measured +20% with the particle level set, +16% with FLIP at 64^2;
// imposing the hose's velocity again after the pressure solve leaves the excess as it is, so it is
// not the step's gravity), a drain empties a tank of what it holds, and FLIP particles that leave
// through an open side are gone; an emitter under water against a wall lets liquid in through
// the wall at its velocity (v h per second in 2D) (volume control follows all three, so the liquid neither swells
// nor shrinks to make up for them).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "../cell_field.hpp"
#include "msim/fluid/liquid/liquid_solver.hpp"
#include "msim/numerics/level_set/level_set_measures.hpp"

using namespace msim;
using namespace msim::fluid;

namespace {

GridSpec<2> unitSquare(int n) { return GridSpec<2>(Vec2::Zero(), 1.0 / n, IVec2(n, n)); }

Grid<float, 2> box(const GridSpec<2>& spec, const Vec2& lo, const Vec2& hi) {
  return test::cellField<2>(spec, [&](const Vec2& x) {
    return std::max({lo[0] - x[0], x[0] - hi[0], lo[1] - x[1], x[1] - hi[1]});
  });
}

double volumeOf(const LiquidSolver<2>& solver) { return numerics::enclosedVolume(solver.phi(), &solver.solid()); }

// The emitter on before every step for `seconds`, steps of at most 1/120 s.
void emitFor(LiquidSolver<2>& solver, const Grid<float, 2>& region, const Vec2& velocity, double seconds) {
  double t = 0.0;
  while (seconds - t > 1e-9) {
    solver.emit(region, velocity);
    const double dt = std::min({seconds - t, solver.cflTimestep(), 1.0 / 120.0});
    solver.step(dt);
    t += dt;
  }
}

// A hose pointing down into an empty closed tank for 0.5 s: the liquid's volume then is the
// hose's own plus v A t.
double hoseVolumeRatio(InterfaceTracker tracker) {
  const GridSpec<2> spec = unitSquare(64);
  LiquidParams<2> params;
  params.tracker = tracker;
  LiquidSolver<2> solver(spec, params);
  // Cells 28..35 across (8 cells = 0.125 m), 56..59 high.
  const Grid<float, 2> hose = box(spec, Vec2(28.0 / 64, 56.0 / 64), Vec2(36.0 / 64, 60.0 / 64));
  const Vec2 velocity(0.0, -1.0);
  emitFor(solver, hose, velocity, 0.5);
  const double area = 8.0 / 64, hoseVolume = 8.0 * 4.0 / (64.0 * 64.0);
  return volumeOf(solver) / (hoseVolume + 1.0 * area * 0.5);
}

// An inflow under water against the left wall of a closed tank filled 0.4 deep: the emitter's
// region is full of liquid from the start, so only its wall lets liquid in; after 0.5 s the tank
// holds the start plus v h t.
double submergedInflowRatio(InterfaceTracker tracker) {
  const GridSpec<2> spec = unitSquare(64);
  LiquidParams<2> params;
  params.tracker = tracker;
  LiquidSolver<2> solver(spec, params);
  solver.addLiquid(box(spec, Vec2(-1, -1), Vec2(2, 0.4)));
  solver.step(1.0 / 120.0);
  const double start = volumeOf(solver);
  const Grid<float, 2> inlet = box(spec, Vec2(-1, -1), Vec2(2.0 / 64, 0.25));  // 0.25 m of the wall
  const Vec2 velocity(0.5, 0.0);
  emitFor(solver, inlet, velocity, 0.5);
  return (volumeOf(solver) - start) / (0.5 * 0.25 * 0.5);
}

}  // namespace

TEST(LiquidSources, SubmergedInflowAgainstAWallDeliversVelocityTimesHeight) {
  for (const InterfaceTracker tracker : {InterfaceTracker::ParticleLevelSet, InterfaceTracker::Flip}) {
    const double ratio = submergedInflowRatio(tracker);
    RecordProperty(tracker == InterfaceTracker::Flip ? "flip_ratio" : "pls_ratio", std::to_string(ratio));
    // Measured -1.7% (particle level set) and +17% (FLIP, whose refills at half-empty cells
    // over-deliver as the hose's do).
    EXPECT_NEAR(ratio, 1.0, tracker == InterfaceTracker::Flip ? 0.2 : 0.05)
        << (tracker == InterfaceTracker::Flip ? "FLIP" : "particle level set");
  }
}

TEST(LiquidSources, HoseDeliversVelocityTimesCrossSection) {
  for (const InterfaceTracker tracker : {InterfaceTracker::ParticleLevelSet, InterfaceTracker::Flip}) {
    const double ratio = hoseVolumeRatio(tracker);
    RecordProperty(tracker == InterfaceTracker::Flip ? "flip_ratio" : "pls_ratio", std::to_string(ratio));
    EXPECT_NEAR(ratio, 1.0, 0.25) << (tracker == InterfaceTracker::Flip ? "FLIP" : "particle level set");
  }
}

TEST(LiquidSources, DrainEmptiesTheTank) {
  for (const InterfaceTracker tracker : {InterfaceTracker::ParticleLevelSet, InterfaceTracker::Flip}) {
    const GridSpec<2> spec = unitSquare(48);
    LiquidParams<2> params;
    params.tracker = tracker;
    LiquidSolver<2> solver(spec, params);
    solver.addLiquid(box(spec, Vec2(-1, -1), Vec2(2, 0.3)));
    solver.step(1.0 / 120.0);
    const double full = volumeOf(solver);
    // A drain over the whole floor, two cells deep.
    const Grid<float, 2> drain = box(spec, Vec2(-1, -1), Vec2(2, 2.0 / 48));
    double removed = 0.0;
    for (int s = 0; s < 400 && volumeOf(solver) > 0.0; ++s) {
      removed += solver.drain(drain);
      solver.step(1.0 / 120.0);
    }
    EXPECT_LT(volumeOf(solver), 0.02 * full);
    EXPECT_NEAR(removed / full, 1.0, 0.1);
  }
}

TEST(LiquidSources, FlipParticlesLeaveThroughAnOpenSide) {
  const GridSpec<2> spec = unitSquare(48);
  LiquidParams<2> params;
  params.tracker = InterfaceTracker::Flip;
  params.sides.side[0][1] = numerics::DomainSide::Open;  // x max
  LiquidSolver<2> solver(spec, params);
  solver.addLiquid(box(spec, Vec2(0.5, -1), Vec2(0.9, 0.4)), Vec2(2.0, 0.0));
  solver.step(1.0 / 120.0);
  const std::size_t before = solver.flipParticles().size();
  for (int s = 0; s < 120; ++s) solver.step(1.0 / 120.0);
  EXPECT_LT(solver.flipParticles().size(), before / 2);
  // What is left is not inflated to make up for what left.
  EXPECT_LT(volumeOf(solver), 0.6 * 0.4 * 0.4);
}
