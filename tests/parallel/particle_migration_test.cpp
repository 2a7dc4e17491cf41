// Marker particles on a split grid (Selle ch. 8.1, seed notes A5): after every move each
// particle has exactly one owner, the rank whose cells hold it, and the particles (count,
// identities, attributes) are those before the move.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "msim/core/rng.hpp"
#include "msim/parallel/particle_migration.hpp"
#include "mpi_test_support.hpp"

namespace msim::parallel {
namespace {

using testing::fromRoot;
using testing::worldRank;
using testing::worldSize;

const GridSpec<3> kGlobal(Vec<3>(-1.0, 0.0, 0.5), 1.0 / 24, IVec<3>(24, 20, 16));

// An attribute that is a function of the particle's identity: a copy with a wrong pairing shows.
Vecf<3> tagOf(float id) { return Vecf<3>(id, 2.0f * id + 1.0f, -id); }

TEST(ParticleMigration, EveryParticleHasOneOwnerAndNoneIsLostOrDuplicated) {
  const GridBlock<3> block(kGlobal, BlockDecomposition<3>(kGlobal.res, worldSize(), 2, "test"), worldRank(), 1);
  // 2000 particles spread over the domain, each rank keeping those in its cells.
  constexpr int kTotal = 2000;
  Particles<3> p;
  p.addScalar("id");
  p.addVector("tag");
  Rng seeder(7);
  for (int n = 0; n < kTotal; ++n) {
    Vecf<3> x;
    for (int a = 0; a < 3; ++a)
      x[a] = static_cast<float>(kGlobal.origin[a] + seeder.uniform() * kGlobal.res[a] * kGlobal.dx);
    if (ownerOf<3>(x, block) != worldRank()) continue;
    const std::size_t i = p.append(x);
    p.scalar("id")[i] = static_cast<float>(n);
    p.vector("tag")[i] = tagOf(static_cast<float>(n));
  }
  long sentTotal = 0;
  for (int round = 0; round < 5; ++round) {
    // Each particle jumps up to 3 cells (some leave the domain: they go to the nearest cell's owner).
    for (std::size_t i = 0; i < p.size(); ++i) {
      Rng r(static_cast<std::uint64_t>(p.scalar("id")[i]) * 31 + round);
      for (int a = 0; a < 3; ++a) p.positions()[i][a] += static_cast<float>((2.0 * r.uniform() - 1.0) * 3 * kGlobal.dx);
    }
    sentTotal += static_cast<long>(migrateParticles<3>(p, block, MPI_COMM_WORLD));
    int misplaced = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      misplaced += ownerOf<3>(p.positions()[i], block) != worldRank();
      misplaced += p.vector("tag")[i] != tagOf(p.scalar("id")[i]);
    }
    EXPECT_EQ(misplaced, 0) << "rank " << worldRank() << ", round " << round;
  }
  // Every identity exactly once over all ranks.
  const int mine = static_cast<int>(p.size());
  std::vector<int> counts(worldSize()), offsets(worldSize(), 0);
  MPI_Gather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  for (int r = 1; r < worldSize(); ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  std::vector<float> all(worldRank() == 0 ? static_cast<std::size_t>(offsets.back() + counts.back()) : 0);
  MPI_Gatherv(p.scalar("id").data(), mine, MPI_FLOAT, all.data(), counts.data(), offsets.data(), MPI_FLOAT, 0,
              MPI_COMM_WORLD);
  long sentEverywhere = 0;
  MPI_Reduce(&sentTotal, &sentEverywhere, 1, MPI_LONG, MPI_SUM, 0, MPI_COMM_WORLD);
  bool ok = true;
  if (worldRank() == 0) {
    std::sort(all.begin(), all.end());
    std::vector<float> expected(kTotal);
    std::iota(expected.begin(), expected.end(), 0.0f);
    EXPECT_EQ(all, expected);
    if (worldSize() > 1) {
      EXPECT_GT(sentEverywhere, 0) << "no particle crossed a block edge: the test tests nothing";
    }
    ok = !::testing::Test::HasFailure();
  }
  EXPECT_TRUE(fromRoot(ok));
}

}  // namespace
}  // namespace msim::parallel
