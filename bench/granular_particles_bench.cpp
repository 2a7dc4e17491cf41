// The particle side of the granular step (Narain 2011 ch. 5.4) at the size of the seed's splash
// example (table 5.1: 50x40x50 grid, ~400k simulation particles): P2G, G2P, advection with shape
// update, split/merge, and the whole sequence. per_particle is the wall time per particle.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "msim/granular/particle_advection.hpp"
#include "msim/granular/particle_grid_transfer.hpp"
#include "msim/granular/render_points.hpp"
#include "msim/granular/split_merge.hpp"

using namespace msim;
using namespace msim::granular;

namespace {

constexpr double kDx = 0.02;
constexpr double kDt = 0.004;
const GridSpec<3> kGrid(Vec3::Zero(), kDx, IVec3(50, 40, 50));
const std::vector<GranularMaterial> kMaterials{{1600.0, 0.6}};

// The lower half of the domain filled: 50 x 20 x 50 cells x 8 = 400k particles.
const GranularParticles& seeded() {
  static const GranularParticles p = [] {
    GranularParticles out;
    seedBox(out, kGrid, Vec3::Zero(), Vec3(1.0, 0.4, 1.0), kMaterials);
    return out;
  }();
  return p;
}

// A stand-in for the solver's output: shear along x over y plus a swirl in the x-z plane, which
// keeps stretching and squeezing particles so that split/merge has work every step.
MacGrid<3> shearingFlow() {
  MacGrid<3> v(kGrid);
  for (int a = 0; a < 3; ++a) {
    Grid<float, 3>& face = v.component(a);
    for (std::size_t i = 0; i < face.count(); ++i) {
      const Vec3 x = face.position(face.coord(i));
      const Vec3 u(2.0 * (x[1] - 0.2) + 0.5 * std::sin(M_PI * x[2]), 0.0, 0.5 * std::sin(M_PI * x[0]));
      face[i] = static_cast<float>(u[a]);
    }
  }
  return v;
}

void perParticle(benchmark::State& state, std::size_t particles) {
  state.counters["particles"] = static_cast<double>(particles);
  state.counters["per_particle"] = benchmark::Counter(
      static_cast<double>(particles), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_ParticleToGrid(benchmark::State& state) {
  const GranularParticles& p = seeded();
  ParticleGridFields fields(kGrid);
  ParticleGridTransfer transfer;
  for (auto _ : state) {
    transfer.toGrid(p, kMaterials, fields);
    benchmark::DoNotOptimize(fields.velocity.component(0).data().data());
  }
  perParticle(state, p.size());
}
BENCHMARK(BM_ParticleToGrid)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_GridToParticles(benchmark::State& state) {
  GranularParticles p = seeded();
  const MacGrid<3> oldVelocity(kGrid), newVelocity = shearingFlow();
  ParticleGridTransfer transfer;
  for (auto _ : state) {
    transfer.toParticles(oldVelocity, newVelocity, p);
    benchmark::DoNotOptimize(p.velocity.data());
  }
  perParticle(state, p.size());
}
BENCHMARK(BM_GridToParticles)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_AdvectWithShapes(benchmark::State& state) {
  GranularParticles p = seeded();
  const MacGrid<3> velocity = shearingFlow(), displacement(kGrid, 0.0f);
  std::vector<Vec3> correction;
  for (auto _ : state) {
    sampleCorrection(p, displacement, correction);
    advectParticles(p, velocity, kDt, correction);
    benchmark::DoNotOptimize(p.position.data());
  }
  perParticle(state, p.size());
}
BENCHMARK(BM_AdvectWithShapes)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_SplitMerge(benchmark::State& state) {
  // The state one advection after 40 steps of shear with split/merge (strain about 1.6): the
  // particles that just became invalid (those no split or merge could fix were regularized).
  GranularParticles deformed = seeded();
  const MacGrid<3> velocity = shearingFlow();
  SplitMerge splitMerge(particleRadius(kDx));
  for (int k = 0; k < 40; ++k) {
    if (k > 0) splitMerge.apply(deformed);
    advectParticles(deformed, velocity, 5 * kDt);
  }
  GranularParticles p;
  SplitMergeStats stats;
  for (auto _ : state) {
    state.PauseTiming();
    p = deformed;
    state.ResumeTiming();
    stats = splitMerge.apply(p);
  }
  perParticle(state, deformed.size());
  std::size_t invalid = 0;
  for (const ParticleShape& a : deformed.shape) invalid += !isValidShape(shapeMatrix(a), splitMerge.radius());
  state.counters["invalid"] = static_cast<double>(invalid);
  state.counters["splits"] = static_cast<double>(stats.splits);
  state.counters["merges"] = static_cast<double>(stats.merges);
  state.counters["regularized"] = static_cast<double>(stats.regularized);
}
BENCHMARK(BM_SplitMerge)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ParticleStep(benchmark::State& state) {
  // P2G, G2P (the solver replaced by a fixed field), advection with shapes, split/merge.
  GranularParticles p = seeded();
  ParticleGridFields fields(kGrid);
  ParticleGridTransfer transfer;
  SplitMerge splitMerge(particleRadius(kDx));
  const MacGrid<3> solved = shearingFlow();
  double particles = 0.0;
  for (auto _ : state) {
    particles += static_cast<double>(p.size());
    transfer.toGrid(p, kMaterials, fields);
    transfer.toParticles(fields.velocity, solved, p);
    advectParticles(p, solved, kDt);
    splitMerge.apply(p);
  }
  state.counters["particles"] = particles / static_cast<double>(state.iterations());
  state.counters["per_particle"] =
      benchmark::Counter(particles, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ParticleStep)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_RenderPointStep(benchmark::State& state) {
  // Render points (ch. 5.6) carried through one particle step of the shearing flow: advection with
  // their particles' motion and the escape test (resampling those outside), one pass. 20 points per
  // particle: 8M points; the seed's hourglass had 2.4M. per_point is the wall time per point.
  GranularParticles p = seeded();
  const MacGrid<3> solved = shearingFlow();
  RenderPoints points(20, 1);
  points.sample(p);
  std::vector<ParticleMotion> motion;
  const GranularParticles start = p;
  const RenderPoints startPoints = points;
  double escaped = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    p = start;
    points = startPoints;
    advectParticles(p, solved, kDt, {}, &motion);
    state.ResumeTiming();
    escaped += static_cast<double>(points.carry(motion, kDt, kGrid, p, {}));
  }
  state.counters["points"] = static_cast<double>(points.size());
  state.counters["escaped"] = escaped / static_cast<double>(state.iterations());
  state.counters["per_point"] = benchmark::Counter(static_cast<double>(points.size()),
                                                   benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_RenderPointStep)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
