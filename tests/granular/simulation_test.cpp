// Whole granular steps (Narain 2011 Fig. 5.7) against the seed's claims and plain physics:
// a resting layer stays within rho_max and comes to rest; pressure is never negative; an
// explosion disperses the material (no cohesion); a sphere denser than the sand rests on it with
// friction and sinks without (Fig. 5.5).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "msim/granular/granular_simulation.hpp"

using namespace msim;
using namespace msim::granular;

namespace {

constexpr double kDensity = 1600.0;

GranularSettings settingsFor(const IVec3& res, double dx) {
  GranularSettings s;
  s.grid = GridSpec<3>(Vec3::Zero(), dx, res);
  return s;
}

double maxPhi(const GranularSimulation& sim) {
  const auto& phi = sim.gridState().phi;
  return *std::max_element(phi.begin(), phi.end());
}

// Mean and 99th percentile of the particle speeds.
std::pair<double, double> speeds(const GranularSimulation& sim) {
  std::vector<double> v;
  for (const auto& u : sim.particles().velocity) v.push_back(u.norm());
  std::sort(v.begin(), v.end());
  double mean = 0.0;
  for (double x : v) mean += x;
  return {mean / static_cast<double>(v.size()), v[v.size() * 99 / 100]};
}

// Mass-weighted rms distance of the particles from c.
double rmsRadius(const GranularSimulation& sim, const Vec3& c) {
  double r2 = 0.0, m = 0.0;
  for (std::size_t i = 0; i < sim.particles().size(); ++i) {
    r2 += sim.particles().mass[i] * (sim.particles().position[i].cast<double>() - c).squaredNorm();
    m += sim.particles().mass[i];
  }
  return std::sqrt(r2 / m);
}

// Runs until time t with steps of at most maxDt; calls check() after every step.
template <typename Check>
void runUntil(GranularSimulation& sim, double t, double maxDt, Check&& check) {
  while (sim.time() < t - 1e-12) {
    sim.step(std::min(sim.stableTimestep(maxDt), t - sim.time()));
    check();
  }
}

}  // namespace

TEST(GranularSimulation, RestingLayerStaysBelowRhoMaxAndComesToRest) {
  GranularSimulation sim(settingsFor(IVec3(8, 14, 8), 0.05), {GranularMaterial{kDensity, 0.6}});
  sim.seed(Vec3(0, 0, 0), Vec3(0.4, 0.4, 0.4), [](const Vec3&) { return true; }, {});
  const double mass0 = sim.totalMass();
  double worstPhi = 0.0, minPressure = 0.0, firstMean = -1.0;
  runUntil(sim, 1.0, 1.0 / 60.0, [&] {
    worstPhi = std::max(worstPhi, maxPhi(sim));
    for (double p : sim.stress().pressure()) minPressure = std::min(minPressure, p);
    if (firstMean < 0.0) firstMean = speeds(sim).first;
  });
  // The grid density of the state the pressure solved (after the density correction).
  EXPECT_LE(worstPhi, 1.02) << "rho_max exceeded by more than 2%";
  EXPECT_GE(minPressure, 0.0);
  // At rest: the settling of the jittered seeding (mean speed after the first step, about
  // 0.02 m/s) has decayed more than tenfold, to the friction solves' velocity tolerance; what
  // is left is FLIP noise of single surface particles.
  const auto [mean, p99] = speeds(sim);
  EXPECT_LT(mean, 0.1 * firstMean) << "the layer has not come to rest (first step " << firstMean << " m/s)";
  EXPECT_LT(p99, 0.05);  // 2.5% of sqrt(g H), the speed scale of the settling
  EXPECT_NEAR(sim.totalMass(), mass0, 1e-6 * mass0);
}

TEST(GranularSimulation, ExplosionDispersesTheMaterial) {
  // A packed ball of sand at rest in zero gravity, its core given an outward velocity of 3 m/s
  // (the explosion of Fig. 5.1 as an instantaneous impulse): with no cohesion the cloud grows
  // (an incompressible fluid would keep its volume; the core's impulse is shared inelastically
  // with the shell, so the growth is slower than the core's speed).
  GranularSettings s = settingsFor(IVec3(20, 20, 20), 0.05);
  s.gravity = Vec3::Zero();
  GranularSimulation sim(s, {GranularMaterial{kDensity, 0.6}});
  const Vec3 c(0.5, 0.5, 0.5);
  sim.seed(c.array() - 0.2, c.array() + 0.2, [&](const Vec3& x) { return (x - c).norm() < 0.2; }, {});
  const double r0 = rmsRadius(sim, c);
  for (std::size_t i = 0; i < sim.particles().size(); ++i) {
    const Vec3 d = sim.particles().position[i].cast<double>() - c;
    if (d.norm() < 0.1) sim.particles().velocity[i] = (3.0 * d / std::max(d.norm(), 1e-6)).cast<float>();
  }
  double minPressure = 0.0;
  runUntil(sim, 0.2, 1.0 / 120.0, [&] {
    for (double p : sim.stress().pressure()) minPressure = std::min(minPressure, p);
  });
  const double growth = std::pow(rmsRadius(sim, c) / r0, 3.0);
  EXPECT_GT(growth, 1.5) << "volume growth " << growth;
  EXPECT_GE(minPressure, 0.0);
}

namespace {

// A ball of density rhoBall dropped onto the surface of a sand bed (Fig. 5.5); returns the height
// of its centre after `seconds`.
double ballHeightAfter(double alpha, double rhoBall, double seconds) {
  GranularSettings s = settingsFor(IVec3(16, 16, 16), 0.6 / 16);
  s.stress.tolerance = 1e-3;
  GranularSimulation sim(s, {GranularMaterial{kDensity, alpha}});
  sim.seed(Vec3(0, 0, 0), Vec3(0.6, 0.3, 0.6), [](const Vec3&) { return true; }, {});
  const double r = 0.075;
  rigid::RigidBody ball = rigid::RigidBody::fromDensity(rigid::Sphere{r}, rhoBall);
  ball.position = Vec3(0.3, 0.3 + r, 0.3);
  sim.world().addBody(ball);
  runUntil(sim, seconds, 1.0 / 60.0, [] {});
  return sim.world().bodies()[0].position.y();
}

}  // namespace

TEST(GranularSimulation, DenseBallRestsOnFrictionalSandAndSinksInFrictionlessSand) {
  // Narain Fig. 5.5: "the heaviest spheres are denser than the sand itself, yet internal friction
  // allows the material to support their weight". A ball of 3000 kg/m^3 on sand of 1600 kg/m^3
  // (surface at y = 0.3 m, ball radius 0.075 m): with alpha = 0.6 its centre stays above the
  // surface; with alpha = 0 the bed behaves as a heavy liquid the ball is denser than, and it sinks
  // to the floor.
  const double withFriction = ballHeightAfter(0.6, 3000.0, 0.8);
  const double without = ballHeightAfter(0.0, 3000.0, 0.8);
  EXPECT_GT(withFriction, 0.3) << "the ball sank into frictional sand";
  EXPECT_LT(without, 0.3 - 0.075) << "the ball did not sink into frictionless sand";
}
