// One Newmark step (Selle ch. 5.4) of a cloth patch hanging from its top edge, with implicit
// linear springs (ch. 5.5) at dt = 1/24 s: two half-step solves by CG (tolerance 1e-3, the seed's
// Table 6.1). Argument: quads per side (triangles = 2 n^2). Counters: CG iterations per step,
// particles, springs.
#include <benchmark/benchmark.h>

#include "msim/solids/cloth_mesh.hpp"
#include "msim/solids/newmark.hpp"

using namespace msim;

namespace {

void BM_ClothNewmarkStep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const TriangleMesh mesh = solids::clothPatch(Vec3(0.0, -1.0, 0.0), Vec3(1.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0), n, n);
  solids::ClothMaterial material;
  material.edgeDamping = 0.01;
  solids::MassSpringSystem cloth = solids::clothSystem(mesh, material);
  for (int i = 0; i <= n; ++i) cloth.pinned[static_cast<std::size_t>(n * (n + 1) + i)] = 1;
  solids::NewmarkSettings settings;
  settings.implicitSprings = true;
  settings.cgTolerance = 1e-3;
  solids::NewmarkStepper stepper(settings);
  int iterations = 0;
  for (auto _ : state) iterations = stepper.step(cloth, 1.0 / 24.0).iterations;
  state.counters["cg_it"] = iterations;
  state.counters["particles"] = static_cast<double>(cloth.size());
  state.counters["springs"] = static_cast<double>(cloth.springs.size());
}

}  // namespace

BENCHMARK(BM_ClothNewmarkStep)->Arg(64)->Arg(224)->Unit(benchmark::kMillisecond);
