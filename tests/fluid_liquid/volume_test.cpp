// Volume of a 3D dam break over 4 s (issue #24: within 1% with the particle level set, 2% with
// FLIP). The tank and the column are those of scenes/dam_break_3d.json (1.6 x 1.0 x 0.6 m, a
// 0.4 m block of water 0.5 m high) at the scene's 64 x 40 x 24 cells: the wave breaks on the far
// wall, throws sheets and spray thinner than a cell and sloshes back, which the trackers alone do
// not survive. Volume control (Kim et al. 2007, with the leak fed forward) is what holds it; the
// same run without it must stray further than the limit, or the test would not show that the
// control does the work: that run stops once it has strayed beyond the limit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "../cell_field.hpp"
#include "msim/fluid/liquid/liquid_solver.hpp"
#include "msim/numerics/level_set/level_set_measures.hpp"

using namespace msim;
using namespace msim::fluid;

namespace {

// Largest |V(t) / V(0) - 1| over 4 s, sampled after every step, or the first beyond `stopAbove`;
// V(0) is the exact volume (the particle level set starts within 0.02% of it) or FLIP's first
// surface.
double largestVolumeError(InterfaceTracker tracker, bool volumeControl, double stopAbove) {
  const double dx = 1.0 / 40.0;
  const GridSpec<3> spec(Vec3::Zero(), dx, IVec3(64, 40, 24));
  LiquidParams<3> params;
  params.tracker = tracker;
  params.volumeControl = volumeControl;
  LiquidSolver<3> solver(spec, params);
  solver.addLiquid(test::cellField<3>(spec, [](const Vec3& x) { return std::max(x[0] - 0.4, x[1] - 0.5); }));
  const double exact = 0.4 * 0.5 * 0.6;
  double worst = 0.0, worstOfStart = 0.0, start = 0.0, t = 0.0;
  while (4.0 - t > 1e-9 && (tracker == InterfaceTracker::Flip ? worstOfStart : worst) <= stopAbove) {
    const double dt = std::min(4.0 - t, solver.cflTimestep());
    solver.step(dt);
    t += dt;
    const double v = numerics::enclosedVolume(solver.phi(), &solver.solid());
    if (start == 0.0) start = v;
    worst = std::max(worst, std::abs(v / exact - 1.0));
    worstOfStart = std::max(worstOfStart, std::abs(v / start - 1.0));
  }
  // FLIP's surface, rebuilt from its particles, starts 1.5% below the box (the reconstruction's
  // bias, which volume control then holds): its volume is kept against its own start.
  return tracker == InterfaceTracker::Flip ? worstOfStart : worst;
}

// Within `limit` with volume control, beyond it without (the control does the work).
void expectControlHolds(InterfaceTracker tracker, double limit) {
  const double controlled = largestVolumeError(tracker, true, 1.0);
  const double uncontrolled = largestVolumeError(tracker, false, limit);
  testing::Test::RecordProperty("largest_volume_error", std::to_string(controlled));
  testing::Test::RecordProperty("volume_error_without_control", std::to_string(uncontrolled));
  EXPECT_LT(controlled, limit);
  EXPECT_GT(uncontrolled, limit);
}

}  // namespace

TEST(LiquidVolume, ParticleLevelSetDamBreakKeepsItsVolume) {
  expectControlHolds(InterfaceTracker::ParticleLevelSet, 0.01);
}

TEST(LiquidVolume, FlipDamBreakKeepsItsVolume) { expectControlHolds(InterfaceTracker::Flip, 0.02); }
