// Turbulent winds acting on granular material (issue #7: winds as a force on granular clouds):
// a grain in air relaxes towards the wind with its response time, in proportion to the open
// volume round it, dv/dt = (1 - phi) (u_air - v) / tau. A dilute cloud is carried along at the
// predicted rate; a packed layer resting under its weight, which the air cannot get into, stays.
#include <gtest/gtest.h>

#include <cmath>

#include "msim/granular/granular_simulation.hpp"

using namespace msim;
using namespace msim::granular;

namespace {

// A weak turbulent wind (rms 1% of the mean) carried by a mean wind along x.
turbulence::TurbulentWind<3> breeze(double mean) {
  turbulence::SpectralWindParams p;
  p.resolution = 16;
  p.timeSamples = 4;
  p.size = 0.8;
  p.spectrum.largestEddy = 0.4;
  p.spectrum.smallestEddy = 0.1;
  p.spectrum.dissipation = p.spectrum.dissipationForSpeedRms(0.01 * mean);
  return turbulence::TurbulentWind<3>(turbulence::SpectralWind<3>(p), Vec3::Zero(), Vec3(mean, 0.0, 0.0));
}

// Mean velocity of the particles of one material below the height `below`.
Vec3 meanVelocity(const GranularSimulation& sim, std::uint16_t material, double below = 1e9) {
  const auto& p = sim.particles();
  Vec3 sum = Vec3::Zero();
  double mass = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.material[i] != material || p.position[i].y() >= below) continue;
    sum += double(p.mass[i]) * p.velocity[i].cast<double>();
    mass += p.mass[i];
  }
  return sum / mass;
}

}  // namespace

TEST(GranularWind, DiluteCloudIsCarriedAtItsResponseRate) {
  GranularSettings s;
  s.grid = GridSpec<3>(Vec3::Zero(), 0.05, IVec3(16, 16, 16));
  s.gravity = Vec3::Zero();
  s.airResponseTime = 0.1;
  GranularSimulation sim(s, {GranularMaterial{1600.0, 0.6}});
  const double fill = 0.1, wind = 0.5;
  SeedOptions cloud;
  cloud.fillFraction = fill;
  sim.seed(Vec3(0.2, 0.3, 0.2), Vec3(0.5, 0.5, 0.6), [](const Vec3&) { return true; }, cloud);
  sim.addWind(breeze(wind));
  const double dt = 0.01;
  for (const double until : {0.1, 0.3}) {
    while (sim.time() < until - 1e-9) sim.step(dt);
    const double predicted = wind * (1.0 - std::exp(-(1.0 - fill) * until / s.airResponseTime));
    const Vec3 c = meanVelocity(sim, 0);
    std::printf("t = %.1f s: cloud v_x %.3f m/s (predicted %.3f)\n", until, c.x(), predicted);
    EXPECT_NEAR(c.x(), predicted, 0.1 * predicted);
    EXPECT_LT(std::abs(c.y()) + std::abs(c.z()), 0.05 * wind);
  }
}

TEST(GranularWind, PackedPileUnderGravityIsNotBlownAway) {
  // A layer resting on the floor in a strong wind: the air cannot get into the packed material,
  // and friction under the layer's weight holds it; only the loose surface feels the drag.
  GranularSettings s;
  s.grid = GridSpec<3>(Vec3::Zero(), 0.05, IVec3(16, 16, 16));
  s.airResponseTime = 0.1;
  GranularSimulation sim(s, {GranularMaterial{1600.0, 0.6}});
  sim.seed(Vec3(0.0, 0.0, 0.0), Vec3(0.8, 0.2, 0.8), [](const Vec3&) { return true; }, SeedOptions{});
  const double wind = 2.0;
  sim.addWind(breeze(wind));
  while (sim.time() < 0.5 - 1e-9) sim.step(0.005);
  const Vec3 all = meanVelocity(sim, 0), inside = meanVelocity(sim, 0, 0.15);
  std::printf("t = 0.5 s in a %.1f m/s wind: layer |v| %.4f m/s, below its top cell %.4f m/s\n", wind, all.norm(),
              inside.norm());
  EXPECT_LT(inside.norm(), 0.02 * wind);
  EXPECT_LT(all.norm(), 0.1 * wind);
}
