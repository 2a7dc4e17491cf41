// One Newmark step (Selle ch. 5.4) of a cloth patch hanging from its top edge, with implicit
// linear springs (ch. 5.5) at dt = 1/(24 k): two half-step solves by CG (tolerance 1e-3, the seed's
// Table 6.1), after a first step that builds the matrix's pattern and the first multigrid
// hierarchy. Arguments: quads per side (triangles = 2 n^2), the preconditioner (0 block-Jacobi,
// 1 smoothed-aggregation multigrid with rigid modes), and k: 1 is a frame-sized step, 16 an inner
// step of the collision loop (ch. 6.3, one linearisation per half step as the seed). Counters: CG
// iterations per step, seconds per 1000 CG iterations (everything in the step over its
// iterations), multigrid setups per step, particles, springs.
// The collision loop's stages (ch. 6.2-6.3) on a cloth folded into pleats 1.5 thicknesses apart
// (every layer near two others): step A, the pairs within the thickness with their sides, and
// step C, continuous collision detection of a motion that shakes every vertex by up to 0.3
// thicknesses (no crossing: the cost of proving that). Counters: pairs, collisions. And the exact
// intersection referee (collision/triangle_intersection.hpp) counting the same folded cloth.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <random>

#include "msim/solids/cloth_mesh.hpp"
#include "msim/solids/collision/triangle_intersection.hpp"
#include "msim/solids/collision_pairs.hpp"
#include "msim/solids/newmark.hpp"
#include "msim/solids/self_collision.hpp"
#include "msim/solids/self_repulsion.hpp"

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
  settings.preconditioner = state.range(1) == 1 ? solids::SolvePreconditioner::Multigrid : solids::SolvePreconditioner::Jacobi;
  const int substeps = static_cast<int>(state.range(2));
  if (substeps > 1) settings.newtonIterations = 1;
  const double dt = 1.0 / (24.0 * substeps);
  solids::NewmarkStepper stepper(settings);
  stepper.step(cloth, dt);  // the matrix's pattern and the first multigrid hierarchy
  int iterations = 0, setups = 0;
  for (auto _ : state) {
    const solids::NewmarkStats stats = stepper.step(cloth, dt);
    iterations += stats.iterations;
    setups += stats.preconditionerSetups;
  }
  state.counters["cg_it"] = benchmark::Counter(iterations, benchmark::Counter::kAvgIterations);
  state.counters["setups"] = benchmark::Counter(setups, benchmark::Counter::kAvgIterations);
  state.counters["per_1000_it"] = benchmark::Counter(1e-3 * iterations, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["particles"] = static_cast<double>(cloth.size());
  state.counters["springs"] = static_cast<double>(cloth.springs.size());
}

constexpr double kThickness = 0.002;  // below the edge length (1/224 m), as cloth.md asks

// An n x n quad patch of 1 m folded every n / 16 rows into pleats 1.5 thicknesses apart.
TriangleMesh pleatedCloth(int n) {
  TriangleMesh mesh = solids::clothPatch(Vec3::Zero(), Vec3(1.0, 0.0, 0.0), Vec3(0.0, 0.0, 1.0), n, n);
  const int rowsPerPleat = std::max(2, n / 16);
  const double rowLength = 1.0 / n;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const int pleat = j / rowsPerPleat, along = j % rowsPerPleat;
      const double z = (pleat % 2 == 0 ? along : rowsPerPleat - along) * rowLength;
      mesh.vertices[static_cast<std::size_t>(j * (n + 1) + i)] = Vec3(i * rowLength, pleat * 1.5 * kThickness, z);
    }
  return mesh;
}

// The pleated cloth with its pairs and a repulsion of the cloth's thickness.
struct PleatedCloth {
  TriangleMesh mesh;
  solids::CollisionPairs pairs;
  solids::RepulsionSettings settings;
  explicit PleatedCloth(int n) : mesh(pleatedCloth(n)), pairs(mesh.triangles, mesh.vertices.size()) {
    settings.thickness = kThickness;
  }
  // The vertices each moved by up to 0.3 thicknesses along each axis.
  std::vector<Vec3> shaken(std::mt19937& rng) const {
    std::uniform_real_distribution<double> shake(-0.3 * kThickness, 0.3 * kThickness);
    std::vector<Vec3> x = mesh.vertices;
    for (Vec3& p : x) p += Vec3(shake(rng), shake(rng), shake(rng));
    return x;
  }
};

void BM_ClothCollisionPairs(benchmark::State& state) {
  PleatedCloth cloth(static_cast<int>(state.range(0)));
  solids::SelfRepulsion repulsion(cloth.settings);
  for (auto _ : state) repulsion.findPairs(cloth.pairs, cloth.mesh.vertices, cloth.mesh.vertices);
  state.counters["pairs"] = repulsion.stats().pointTrianglePairs + repulsion.stats().edgeEdgePairs;
  state.counters["triangles"] = static_cast<double>(cloth.mesh.triangles.size());
}

// Step B.2's self-repulsion on the pleated cloth shaken by up to 0.3 thicknesses, every particle
// elsewhere at each call (two shakes in turn, so every pair is examined again): finding the pairs
// closer than the thickness among step A's candidates, then the impulses (twice per inner step).
void BM_ClothRepulsionPass(benchmark::State& state) {
  PleatedCloth cloth(static_cast<int>(state.range(0)));
  solids::SelfRepulsion repulsion(cloth.settings);
  repulsion.findPairs(cloth.pairs, cloth.mesh.vertices, cloth.mesh.vertices);
  std::mt19937 rng(7);
  const std::array<std::vector<Vec3>, 2> shaken{cloth.shaken(rng), cloth.shaken(rng)};
  const std::vector<double> inverseMass(cloth.mesh.vertices.size(), 1e4);
  std::vector<Vec3> v(cloth.mesh.vertices.size(), Vec3::Zero());
  int contacts = 0;
  std::size_t call = 0;
  for (auto _ : state) contacts = repulsion.repelPositionVelocity(shaken[call++ % 2], v, inverseMass, 1.0 / 384.0);
  state.counters["pairs"] = repulsion.stats().pointTrianglePairs + repulsion.stats().edgeEdgePairs;
  state.counters["contacts"] = contacts;
  state.counters["triangles"] = static_cast<double>(cloth.mesh.triangles.size());
}

void BM_ClothContinuousCollisions(benchmark::State& state) {
  PleatedCloth cloth(static_cast<int>(state.range(0)));
  std::mt19937 rng(7);
  const std::vector<Vec3> end = cloth.shaken(rng);
  const std::vector<double> mass(cloth.mesh.vertices.size(), 1e-4);
  const std::vector<char> pinned(cloth.mesh.vertices.size(), 0);
  solids::SelfCollisionResolver resolver;
  solids::SelfCollisionStats stats;
  for (auto _ : state) {
    std::vector<Vec3> x1 = end;
    stats = resolver.resolve(cloth.pairs, cloth.mesh.vertices, x1, mass, pinned, 1.0 / 24.0, 1.0 / 192.0, cloth.settings);
  }
  state.counters["collisions"] = stats.collisions;
  state.counters["triangles"] = static_cast<double>(cloth.mesh.triangles.size());
}

void BM_IntersectionReferee(benchmark::State& state) {
  const TriangleMesh mesh = pleatedCloth(static_cast<int>(state.range(0)));
  std::size_t found = 0;
  for (auto _ : state) found = solids::countSelfIntersections(mesh.vertices, mesh.triangles);
  state.counters["intersections"] = static_cast<double>(found);
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
}

}  // namespace

BENCHMARK(BM_ClothNewmarkStep)->ArgsProduct({{64, 224}, {0, 1}, {1}})->MinTime(3.0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ClothNewmarkStep)->Args({224, 0, 16})->MinTime(3.0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ClothCollisionPairs)->Arg(224)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ClothRepulsionPass)->Arg(224)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ClothContinuousCollisions)->Arg(224)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IntersectionReferee)->Arg(224)->Unit(benchmark::kMillisecond);
