// Whole granular steps (Narain 2011 Fig. 5.7) with the split of Table 5.1's text (pressure,
// friction, particles; seed: 17 / 35 / 33 % of the time): a sand bed on the hourglass grid of
// Table 5.1 (25 x 50 x 25, half full: 125k particles at 8 per cell, 422k at 27) and a ball resting on sand (Fig. 5.5,
// 24^3, two-way coupling).
#include <benchmark/benchmark.h>

#include "msim/granular/granular_simulation.hpp"

using namespace msim;
using namespace msim::granular;

namespace {

void report(benchmark::State& state, const GranularSimulation& sim, const GranularStepTimes& sum) {
  const double n = static_cast<double>(state.iterations());
  state.counters["particles"] = static_cast<double>(sim.particles().size());
  state.counters["pressure_s"] = sum.pressure / n;
  state.counters["friction_s"] = sum.friction / n;
  state.counters["particles_s"] = sum.particles / n;
  state.counters["transfer_s"] = sum.transfer / n;
  state.counters["correction_s"] = sum.correction / n;
  state.counters["assembly_s"] = sum.assembly / n;
  state.counters["step_s"] = sum.step / n;
  state.counters["friction_iterations"] = sim.stress().stats().frictionIterations;
  state.counters["pressure_iterations"] = sim.stress().stats().pressureIterations;
}

void accumulate(GranularStepTimes& sum, const GranularStepTimes& t) {
  sum.transfer += t.transfer;
  sum.correction += t.correction;
  sum.pressure += t.pressure;
  sum.friction += t.friction;
  sum.bodies += t.bodies;
  sum.particles += t.particles;
  sum.assembly += t.assembly;
  sum.other += t.other;
  sum.step += t.step;
}

// Warms up for 10 steps of dt, then times steps of dt.
void timeSteps(benchmark::State& state, GranularSimulation& sim, double dt) {
  for (int k = 0; k < 10; ++k) sim.step(dt);
  GranularStepTimes sum;
  for (auto _ : state) {
    sim.step(dt);
    accumulate(sum, sim.lastStepTimes());
  }
  report(state, sim, sum);
}

// Argument: particles seeded per cell (8: the seed's r = dx/4; granular_hourglass seeds 12.7 for
// the seed's particle count).
void BM_SandBed25x50x25(benchmark::State& state) {
  GranularSettings s;
  s.grid = GridSpec<3>(Vec3::Zero(), 0.02, IVec3(25, 50, 25));
  s.stress.tolerance = 1e-3;
  s.particlesPerCell = static_cast<double>(state.range(0));
  GranularSimulation sim(s, {GranularMaterial{1600.0, 0.6}});
  sim.seed(Vec3::Zero(), Vec3(0.5, 0.5, 0.5), [](const Vec3&) { return true; }, {});
  timeSteps(state, sim, 1.0 / 120.0);
}

void BM_BallOnSand24(benchmark::State& state) {
  GranularSettings s;
  s.grid = GridSpec<3>(Vec3::Zero(), 0.025, IVec3(24, 24, 24));
  s.stress.tolerance = 1e-3;
  GranularSimulation sim(s, {GranularMaterial{1600.0, 0.6}});
  sim.seed(Vec3::Zero(), Vec3(0.6, 0.3, 0.6), [](const Vec3&) { return true; }, {});
  rigid::RigidBody ball = rigid::RigidBody::fromDensity(rigid::Sphere{0.075}, 3000.0);
  ball.position = Vec3(0.3, 0.375, 0.3);
  sim.world().addBody(ball);
  timeSteps(state, sim, 1.0 / 60.0);
}

}  // namespace

BENCHMARK(BM_SandBed25x50x25)->Arg(8)->Arg(27)->Unit(benchmark::kMillisecond)->Iterations(10);
BENCHMARK(BM_BallOnSand24)->Unit(benchmark::kMillisecond)->Iterations(10);
