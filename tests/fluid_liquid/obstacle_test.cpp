// Obstacles (issue #24). Moving: a vertical plate pushed into a 2D tank of water at 0.1 m/s must
// displace the water, not destroy it: the liquid outside the plate keeps its area while the plate
// sweeps a fifth of the tank (it is the plate's face velocities that push it, through the
// pressure's boundary condition), so the water left in front of the plate rises by the swept area
// over the width that is left: 0.4 m deep over 0.9 m becomes 0.45 m over 0.8 m. Measured at 64^2
// after 1 s: particle level set area within 1.8%, level 0.449 m; FLIP -5.0% and 0.432 m (its
// particles bunch against the plate); with volume control 1.9% / 0.456 m and 1.4% / 0.454 m.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "../cell_field.hpp"
#include "msim/fluid/liquid/liquid_solver.hpp"
#include "msim/numerics/level_set/level_set_measures.hpp"
#include "msim/numerics/pressure/face_fractions.hpp"

using namespace msim;
using namespace msim::fluid;

namespace {

struct Outcome {
  double areaChange = 0.0;   // largest |A(t) / A(0) - 1|
  double meanLevel = 0.0;    // mean surface height in front of the plate at the end [m]
};

Outcome pushThePlate(InterfaceTracker tracker, bool volumeControl) {
  const int n = 64;
  const GridSpec<2> spec(Vec2::Zero(), 1.0 / n, IVec2(n, n));
  LiquidParams<2> params;
  params.tracker = tracker;
  params.volumeControl = volumeControl;
  LiquidSolver<2> solver(spec, params);
  const double speed = 0.1, thickness = 0.1;
  auto place = [&](double t) {
    const double right = thickness + speed * t;  // the plate spans x in [-1, right], all heights
    solver.setObstacles(numerics::sampleNodes<2>(spec, [&](const Vec2& x) { return x[0] - right; }));
    MacGrid<2> v(spec);
    v.component(0).fill(static_cast<float>(speed));
    solver.setObstacleVelocity(v);
  };
  place(0.0);
  solver.addLiquid(test::cellField<2>(spec, [](const Vec2& x) { return x[1] - 0.4; }));
  auto area = [&] { return numerics::enclosedVolume(solver.phi(), &solver.solid()); };
  const double dt = 1.0 / 120.0;
  solver.step(dt);
  const double start = area();
  Outcome o;
  double t = dt;
  for (int s = 1; s < 120; ++s) {  // 1 s: the plate moves from x = 0.1 to 0.2
    place(t + 0.5 * dt);
    solver.step(dt);
    t += dt;
    o.areaChange = std::max(o.areaChange, std::abs(area() / start - 1.0));
  }
  // The surface height in every column from x = 0.25 on, from phi's crossing.
  const Grid<float, 2>& phi = solver.phi();
  double sum = 0.0;
  int columns = 0;
  for (int i = static_cast<int>(0.25 * n); i < n; ++i) {
    for (int j = 0; j + 1 < n; ++j) {
      const float p = phi(IVec2(i, j)), q = phi(IVec2(i, j + 1));
      if (p < 0.0f && q >= 0.0f) {
        sum += phi.position(IVec2(i, j))[1] + spec.dx * p / (p - q);
        ++columns;
        break;
      }
    }
  }
  o.meanLevel = sum / columns;
  return o;
}

}  // namespace

TEST(LiquidMovingObstacle, PlatePushesTheWaterWithoutLosingIt) {
  for (const InterfaceTracker tracker : {InterfaceTracker::ParticleLevelSet, InterfaceTracker::Flip}) {
    const char* name = tracker == InterfaceTracker::Flip ? "FLIP" : "particle level set";
    const Outcome free = pushThePlate(tracker, false), held = pushThePlate(tracker, true);
    RecordProperty(std::string(name) + " area change", std::to_string(free.areaChange));
    RecordProperty(std::string(name) + " level", std::to_string(free.meanLevel));
    RecordProperty(std::string(name) + " area change controlled", std::to_string(held.areaChange));
    RecordProperty(std::string(name) + " level controlled", std::to_string(held.meanLevel));
    const bool flip = tracker == InterfaceTracker::Flip;
    EXPECT_LT(free.areaChange, flip ? 0.06 : 0.03) << name;
    EXPECT_NEAR(free.meanLevel, 0.45, flip ? 0.02 : 0.01) << name;
    EXPECT_LT(held.areaChange, 0.03) << name;
    EXPECT_NEAR(held.meanLevel, 0.45, 0.01) << name;
  }
}

// A column of water collapsing in a tank built of obstacles (floor and walls, not the domain's
// sides): the walls are no surface of the liquid, so it keeps its area as well as in the same tank
// made of the domain's sides (the level set is continued into the obstacles; left with the air's
// sign there, the walls eroded the water and a 3D pool lost 40% in a second). Without volume
// control. Measured over 1 s at 64 cells per metre: particle level set 4.7% (domain tank 5.3%),
// FLIP 8.5% (7.0%).
namespace {

double largestAreaChange(InterfaceTracker tracker, bool obstacleTank) {
  const double dx = 1.0 / 64, wall = 0.125;
  // The obstacle tank fills the unit square; the domain tank is its inside, 0.75 x 0.875.
  const GridSpec<2> spec = obstacleTank ? GridSpec<2>(Vec2::Zero(), dx, IVec2(64, 64))
                                        : GridSpec<2>(Vec2(wall, wall), dx, IVec2(48, 56));
  LiquidParams<2> params;
  params.tracker = tracker;
  params.volumeControl = false;
  LiquidSolver<2> solver(spec, params);
  if (obstacleTank)
    solver.setObstacles(numerics::sampleNodes<2>(spec, [&](const Vec2& x) {
      return std::min({x[1] - wall, x[0] - wall, 1.0 - wall - x[0]});
    }));
  solver.addLiquid(test::cellField<2>(spec, [&](const Vec2& x) {
    return std::max({wall - x[0], x[0] - 0.425, wall - x[1], x[1] - 0.625});
  }));
  auto area = [&] { return numerics::enclosedVolume(solver.phi(), &solver.solid()); };
  solver.step(1.0 / 120.0);
  const double start = area();
  double worst = 0.0;
  for (int s = 1; s < 120; ++s) {
    solver.step(1.0 / 120.0);
    worst = std::max(worst, std::abs(area() / start - 1.0));
  }
  return worst;
}

}  // namespace

TEST(LiquidObstacles, ContainerOfObstaclesHoldsTheWaterAsDomainWallsDo) {
  for (const InterfaceTracker tracker : {InterfaceTracker::ParticleLevelSet, InterfaceTracker::Flip}) {
    const char* name = tracker == InterfaceTracker::Flip ? "FLIP" : "particle level set";
    const double obstacles = largestAreaChange(tracker, true), walls = largestAreaChange(tracker, false);
    RecordProperty(std::string(name) + " obstacle tank", std::to_string(obstacles));
    RecordProperty(std::string(name) + " domain tank", std::to_string(walls));
    EXPECT_LT(obstacles, walls + 0.03) << name;
  }
}
