// A cloth split among ranks (Selle ch. 8.2, parallel/split_cloth.hpp): every rank stores every
// particle, computes its own particles' rows of the implicit solves and shares them; collision
// impulses run in the two phases. Checked on 1, 2, 4 and 8 ranks: the exchange hands every
// particle its owner's value, the split implicit step is the one-process step within the solve's
// tolerance, the pairs and contacts found together are one process's, and a cloth crumpling on a
// floor never passes through itself while every rank keeps the same bits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "../solids/floor_drop.hpp"
#include "msim/parallel/split_cloth.hpp"
#include "msim/solids/collision/triangle_intersection.hpp"
#include "mpi_test_support.hpp"

namespace msim::parallel {
namespace {

using namespace msim::solids;
using testing::worldRank;
using testing::worldSize;

// Whether every rank holds rank 0's bits of x.
bool sameOnEveryRank(const std::vector<Vec3>& x) {
  std::vector<Vec3> root = x;
  MPI_Bcast(root.data()->data(), static_cast<int>(3 * root.size()), MPI_DOUBLE, 0, MPI_COMM_WORLD);
  int same = std::memcmp(root.data(), x.data(), x.size() * sizeof(Vec3)) == 0;
  MPI_Allreduce(MPI_IN_PLACE, &same, 1, MPI_INT, MPI_LAND, MPI_COMM_WORLD);
  return same != 0;
}

TEST(SplitCloth, EveryParticleGetsItsOwnersValueAndSumsAgree) {
  const TriangleMesh mesh = clothPatch(Vec3::Zero(), Vec3(1.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.2), 13, 9);
  const SplitCloth split(mesh.vertices, MPI_COMM_WORLD);
  const std::size_t n = mesh.vertices.size();
  // Each rank's own particles hold 7 p + 1, 2, 3; the others what only this rank would write.
  std::vector<Vec3> values(n, Vec3::Constant(-100.0 - worldRank()));
  for (const int p : split.owned()) values[static_cast<std::size_t>(p)] = Vec3(7.0 * p + 1.0, 7.0 * p + 2.0, 7.0 * p + 3.0);
  split.shareOwned(values.data()->data());
  for (std::size_t p = 0; p < n; ++p)
    ASSERT_EQ(values[p], Vec3(7.0 * p + 1.0, 7.0 * p + 2.0, 7.0 * p + 3.0)) << "particle " << p;
  // The parts: equal counts within one, each particle owned once.
  int mine = static_cast<int>(split.owned().size()), total = 0, fewest = 0, most = 0;
  MPI_Allreduce(&mine, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(&mine, &fewest, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&mine, &most, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  EXPECT_EQ(total, static_cast<int>(n));
  EXPECT_LE(most - fewest, 1);
  EXPECT_EQ(split.sum(worldRank() + 1.0), worldSize() * (worldSize() + 1) / 2.0);
}

// A 0.6 m square of 16 x 16 quads held at its top corners, swinging from a tilt: implicit springs,
// 20 steps of 1/240 s.
TEST(SplitCloth, ImplicitStepsEqualOneProcessWithinTheSolveTolerance) {
  const TriangleMesh mesh = clothPatch(Vec3(-0.3, 1.0, 0.0), Vec3(0.6, 0.0, 0.0), Vec3(0.0, -0.5, 0.3), 16, 16);
  const auto run = [&](const SplitCloth* split) {
    MassSpringSystem system = clothSystem(mesh, {.edgeStiffness = 20.0, .edgeDamping = 0.002, .bendStiffness = 0.05});
    system.pinned[0] = system.pinned[16] = 1;
    NewmarkSettings settings;
    settings.implicitSprings = true;
    settings.cgTolerance = 1e-10;
    NewmarkStepper stepper(settings);
    stepper.setSplit(split);
    int iterations = 0;
    for (int step = 0; step < 20; ++step) iterations += stepper.step(system, 1.0 / 240.0).iterations;
    EXPECT_GT(iterations, 20);
    return system;
  };
  const SplitCloth split(mesh.vertices, MPI_COMM_WORLD);
  const MassSpringSystem whole = run(nullptr), shared = run(&split);
  double worst = 0.0, travel = 0.0;
  for (std::size_t p = 0; p < whole.size(); ++p) {
    worst = std::max(worst, (shared.x[p] - whole.x[p]).norm());
    travel = std::max(travel, (whole.x[p] - mesh.vertices[p]).norm());
  }
  EXPECT_GT(travel, 0.01) << "the cloth swings";
  EXPECT_LE(worst, 1e-8 * travel) << "the split solve's answer";
  EXPECT_TRUE(sameOnEveryRank(shared.x));
  EXPECT_TRUE(sameOnEveryRank(shared.v));
}

// A sheet folded over itself in a wave: the pairs within reach (step A) and the repulsions'
// contacts found by the processes together equal one process's.
TEST(SplitCloth, PairsAndContactsFoundTogetherAreOneProcesssOwn) {
  TriangleMesh mesh = clothPatch(Vec3(-0.3, 0.0, -0.3), Vec3(0.6, 0.0, 0.0), Vec3(0.0, 0.0, 0.6), 20, 20);
  for (Vec3& x : mesh.vertices) x[1] = 0.004 * std::sin(25.0 * x[0]) + 0.006 * std::cos(31.0 * x[2]);  // bumps
  for (std::size_t k = 0; k < 10 * 21; ++k) {  // the rows at z < 0 folded over those at z > 0, 9 mm above
    Vec3& x = mesh.vertices[k];
    x = Vec3(x[0], 0.009 + x[1], -x[2]);
  }
  const SplitCloth split(mesh.vertices, MPI_COMM_WORLD);
  const auto find = [&](const ParticleSplit* s) {
    CollisionPairs pairs(mesh.triangles, mesh.vertices.size());
    std::vector<PointTrianglePair> pointTriangle;
    std::vector<EdgeEdgePair> edgeEdge;
    pairs.find(mesh.vertices, mesh.vertices, 0.02, pointTriangle, edgeEdge, nullptr, s);
    return std::make_pair(pointTriangle, edgeEdge);
  };
  const auto whole = find(nullptr), joined = find(&split);
  EXPECT_GT(whole.first.size(), 1000u);
  EXPECT_GT(whole.second.size(), 1000u);
  EXPECT_TRUE(joined.first == whole.first);
  EXPECT_TRUE(joined.second == whole.second);
  const auto contacts = [&](const ParticleSplit* s) {
    CollisionPairs pairs(mesh.triangles, mesh.vertices.size());
    SelfRepulsion repulsion({.thickness = 0.01});
    repulsion.setSplit(s);
    repulsion.findPairs(pairs, mesh.vertices, mesh.vertices);
    std::vector<Vec3> v(mesh.vertices.size(), Vec3(0.0, -0.1, 0.0));
    const std::vector<double> inverseMass(mesh.vertices.size(), 1.0);
    return repulsion.repelEndVelocity(mesh.vertices, v, inverseMass);
  };
  const int alone = contacts(nullptr);
  EXPECT_GT(alone, 100);
  EXPECT_EQ(contacts(&split), alone);
}

// The collision loop's test scene (tests/solids/floor_drop.hpp), smaller: a 0.6 m square of 16 x 16
// quads dropped edge down onto a floor folds over itself.
TEST(SplitCloth, ClothCrumplingOnAFloorNeverPassesThroughItself) {
  FloorDrop drop = floorDrop(16);
  const TriangleMesh& mesh = drop.mesh;
  MassSpringSystem& system = drop.system;
  const BodyContact& floor = drop.floor;
  ClothCollisionLoop loop(mesh.triangles, system.size(), drop.newmark, drop.settings);
  const SplitCloth split(system.x, MPI_COMM_WORLD);
  loop.setSplit(&split);
  const double T = 0.01;
  std::size_t worstSelf = 0;
  int repulsions = 0;
  for (int step = 0; step < 90; ++step) {
    const ClothCollisionStats s = loop.step(system, T, [&] { return T / 8.0; }, &floor);
    repulsions += s.repulsions;
    EXPECT_EQ(s.collisions.unresolved, 0) << "step " << step;
    worstSelf = std::max(worstSelf, countSelfIntersections(system.x, mesh.triangles));
  }
  EXPECT_EQ(worstSelf, 0u);
  EXPECT_GT(repulsions, 0) << "the cloth met itself";
  EXPECT_TRUE(sameOnEveryRank(system.x));
  EXPECT_TRUE(sameOnEveryRank(system.v));
}

}  // namespace
}  // namespace msim::parallel
