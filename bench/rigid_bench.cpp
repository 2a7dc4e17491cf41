// Rigid-body step cost: N spheres (radius 0.05, restitution 0.2, friction 0.5) poured on a jittered
// lattice into a box and settling under gravity; reports time per World::step at dt = 1e-3.
// The world is pre-settled for 200 steps so the timed steps see a dense, contact-rich pile.
#include <benchmark/benchmark.h>

#include <cmath>

#include "msim/rigid/world.hpp"

namespace {

using msim::Vec3;
using namespace msim::rigid;

World makePile(int n) {
  const double r = 0.05, spacing = 2.2 * r;
  const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(n)) * 0.75));
  World w;
  const double width = side * spacing;
  w.addDomainBox(Vec3(0, 0, 0), Vec3(width, width, 100.0), Material{0.5, 0.0});
  for (int i = 0; i < n; ++i) {
    const int x = i % side, y = (i / side) % side, z = i / (side * side);
    // Deterministic jitter so the pile does not stay a perfect column stack.
    const double jx = 0.1 * r * std::sin(1.7 * i), jy = 0.1 * r * std::cos(2.3 * i);
    RigidBody b = RigidBody::fromDensity(Sphere{r}, 2500.0);
    b.position = Vec3((x + 0.5) * spacing + jx, (y + 0.5) * spacing + jy, r + z * spacing);
    b.material = Material{0.5, 0.2};
    w.addBody(b);
  }
  return w;
}

void BM_SpheresSettling(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  World w = makePile(n);
  for (int k = 0; k < 200; ++k) w.step(1e-3);
  for (auto _ : state) w.step(1e-3);
  state.counters["bodies"] = n;
  state.counters["contacts"] = static_cast<double>(w.lastContacts().size());
  state.SetItemsProcessed(state.iterations() * n);
}
BENCHMARK(BM_SpheresSettling)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond);

}  // namespace
