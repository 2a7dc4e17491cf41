// Global planning (Narain 2011 ch. 4.3.1) on a 120 x 108 m scene with 120 rotated square
// obstacles: navigation field build at 0.25 m cells (one goal and four goals in parallel), roadmap
// build (CDT + Floyd-Warshall), and per-agent query cost (direction) for both planners. The
// roadmap's benchmarks are in builds with the optional roadmap planner (-DMSIM_WITH_CGAL=ON).
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "msim/core/rng.hpp"
#include "msim/crowd/navigation_field.hpp"
#if MSIM_WITH_ROADMAP
#include "msim/crowd/roadmap/roadmap.hpp"
#endif

using namespace msim;
using namespace msim::crowd;

namespace {

const Vec2 kLo(0, 0), kHi(120, 108);

// One obstacle per 10 x 10.8 m block: a square of side 3-5 m, rotated and jittered.
const std::vector<Polygon>& obstacles() {
  static const std::vector<Polygon> out = [] {
    Rng rng(7);
    std::vector<Polygon> o;
    for (int j = 0; j < 10; ++j)
      for (int i = 0; i < 12; ++i) {
        const Vec2 c(10 * i + 5 + 2 * (rng.uniform() - 0.5), 10.8 * j + 5.4 + 2 * (rng.uniform() - 0.5));
        const double half = 1.5 + rng.uniform(), angle = M_PI / 2 * rng.uniform();
        Polygon p;
        for (int k = 0; k < 4; ++k)
          p.vertices.push_back(c + Eigen::Rotation2D<double>(angle + k * M_PI / 2) * Vec2(half * std::sqrt(2.0), 0));
        o.push_back(p);
      }
    return o;
  }();
  return out;
}

// Goals in the free corridors between the blocks.
std::vector<Goal> goals(int count) {
  std::vector<Goal> out;
  const Vec2 points[4] = {{0.5, 54.0}, {119.5, 54.0}, {60.0, 0.5}, {60.0, 107.5}};
  for (int g = 0; g < count; ++g) {
    Goal goal;
    goal.point = points[g];
    out.push_back(goal);
  }
  return out;
}

std::vector<Vec2> agents() {
  Rng rng(3);
  std::vector<Vec2> out;
  while (out.size() < 4096) {
    const Vec2 x(120 * rng.uniform(), 108 * rng.uniform());
    bool free = true;
    for (const Polygon& p : obstacles()) free = free && signedDistance(p, x) > 0.5;
    if (free) out.push_back(x);
  }
  return out;
}

NavigationFieldOptions fieldOptions() {
  NavigationFieldOptions o;
  o.lo = kLo, o.hi = kHi, o.cellSize = 0.25, o.clearance = 0.25;
  return o;
}

#if MSIM_WITH_ROADMAP
RoadmapOptions roadmapOptions() {
  RoadmapOptions o;
  o.lo = kLo, o.hi = kHi;
  o.spacing = 0;  // the seed's bare triangulation: the Steiner lattice would need > 10k vertices here
  return o;
}
#endif

void BM_NavigationFieldBuild(benchmark::State& state) {
  for (auto _ : state) {
    const NavigationField field(goals(static_cast<int>(state.range(0))), obstacles(), fieldOptions());
    benchmark::DoNotOptimize(field.distance(0, Vec2(60, 54)));
  }
  state.counters["cells"] = 480.0 * 432.0;
}
BENCHMARK(BM_NavigationFieldBuild)->Arg(1)->Arg(4)->Unit(benchmark::kMillisecond);

void BM_NavigationFieldDirection(benchmark::State& state) {
  static const NavigationField field(goals(1), obstacles(), fieldOptions());
  static const std::vector<Vec2> xs = agents();
  for (auto _ : state)
    for (const Vec2& x : xs) benchmark::DoNotOptimize(field.direction(0, x));
  state.SetItemsProcessed(state.iterations() * xs.size());
}
BENCHMARK(BM_NavigationFieldDirection);

#if MSIM_WITH_ROADMAP
void BM_RoadmapBuild(benchmark::State& state) {
  for (auto _ : state) {
    const Roadmap roadmap(goals(1), obstacles(), roadmapOptions());
    state.counters["vertices"] = static_cast<double>(roadmap.vertexCount());
  }
}
BENCHMARK(BM_RoadmapBuild)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_RoadmapDirection(benchmark::State& state) {
  static const Roadmap roadmap(goals(1), obstacles(), roadmapOptions());
  static const std::vector<Vec2> xs = agents();
  for (auto _ : state)
    for (const Vec2& x : xs) benchmark::DoNotOptimize(roadmap.direction(0, x));
  state.SetItemsProcessed(state.iterations() * xs.size());
}
BENCHMARK(BM_RoadmapDirection);
#endif

}  // namespace
