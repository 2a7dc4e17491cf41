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

const GridSpec<3> kMigrationGrid(Vec<3>(-1.0, 0.0, 0.5), 1.0 / 24, IVec<3>(24, 20, 16));

// An attribute that is a function of the particle's identity: a copy with a wrong pairing shows.
Vecf<3> tagOf(float id) { return Vecf<3>(id, 2.0f * id + 1.0f, -id); }

TEST(ParticleMigration, EveryParticleHasOneOwnerAndNoneIsLostOrDuplicated) {
  const GridBlock<3> block(kMigrationGrid, BlockDecomposition<3>(kMigrationGrid.res, worldSize(), 2, "test"), worldRank(), 1);
  // 2000 particles spread over the domain, each rank keeping those in its cells.
  constexpr int kTotal = 2000;
  Particles<3> p;
  p.addScalar("id");
  p.addVector("tag");
  Rng seeder(7);
  for (int n = 0; n < kTotal; ++n) {
    Vecf<3> x;
    for (int a = 0; a < 3; ++a)
      x[a] = static_cast<float>(kMigrationGrid.origin[a] + seeder.uniform() * kMigrationGrid.res[a] * kMigrationGrid.dx);
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
      for (int a = 0; a < 3; ++a) p.positions()[i][a] += static_cast<float>((2.0 * r.uniform() - 1.0) * 3 * kMigrationGrid.dx);
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

// Rows of doubles (the particle level set's markers: position, radius, sign) after jumps: each row
// on its owner, none lost or duplicated (gathered on rank 0), and every rank's neighbour copies
// exactly the other ranks' rows within 1 and 2 cells of its own (checked against the gathered set).
TEST(ParticleMigration, RowsMigrateAndNeighboursReceiveTheRowsNearTheirCells) {
  const GridBlock<3> block(kMigrationGrid, BlockDecomposition<3>(kMigrationGrid.res, worldSize(), 2, "test"), worldRank(), 2);
  constexpr int kTotal = 1500, kWidth = 4;  // position and an identity
  std::vector<double> rows;
  Rng seeder(11);
  for (int n = 0; n < kTotal; ++n) {
    Vec<3> x;
    for (int a = 0; a < 3; ++a) x[a] = kMigrationGrid.origin[a] + seeder.uniform() * kMigrationGrid.res[a] * kMigrationGrid.dx;
    if (ownerOf<3>(x, block) == worldRank()) rows.insert(rows.end(), {x[0], x[1], x[2], double(n)});
  }
  for (std::size_t at = 0; at < rows.size(); at += kWidth) {
    Rng r(static_cast<std::uint64_t>(rows[at + 3]));
    for (int a = 0; a < 3; ++a) rows[at + a] += (2.0 * r.uniform() - 1.0) * 3 * kMigrationGrid.dx;
  }
  long sent = static_cast<long>(migrateRows<3>(rows, kWidth, block, MPI_COMM_WORLD));
  int misplaced = 0;
  for (std::size_t at = 0; at < rows.size(); at += kWidth)
    misplaced += ownerOf<3>(Vec<3>(rows[at], rows[at + 1], rows[at + 2]), block) != worldRank();
  EXPECT_EQ(misplaced, 0) << "rank " << worldRank();
  // The neighbour copies against the whole set: the rows of other ranks within `reach` cells of
  // this rank's own (every rank gets every row through rank 0's broadcast).
  std::vector<double> all = gatherRowsToRoot(rows, MPI_COMM_WORLD);
  long count = static_cast<long>(all.size());
  MPI_Bcast(&count, 1, MPI_LONG, 0, MPI_COMM_WORLD);
  all.resize(static_cast<std::size_t>(count));
  MPI_Bcast(all.data(), static_cast<int>(count), MPI_DOUBLE, 0, MPI_COMM_WORLD);
  bool someExpected = false;
  for (const int reach : {1, 2}) {
    const std::vector<double> received = neighbourRows<3>(rows, kWidth, reach, block, MPI_COMM_WORLD);
    const IndexBox<3> own = block.owned();
    std::vector<double> expected, got;
    for (std::size_t at = 0; at < all.size(); at += kWidth) {
      const Vec<3> x(all[at], all[at + 1], all[at + 2]);
      IVec<3> c;
      for (int a = 0; a < 3; ++a)
        c[a] = std::clamp(static_cast<int>(std::floor((x[a] - kMigrationGrid.origin[a]) / kMigrationGrid.dx)), 0, kMigrationGrid.res[a] - 1);
      const bool near = IndexBox<3>{own.lo.array() - reach, own.hi.array() + reach}.contains(c);
      if (near && ownerOf<3>(x, block) != worldRank()) expected.push_back(all[at + 3]);
    }
    for (std::size_t at = 0; at < received.size(); at += kWidth) got.push_back(received[at + 3]);
    std::sort(expected.begin(), expected.end());
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, expected) << "rank " << worldRank() << ", reach " << reach;
    someExpected = someExpected || !expected.empty();
  }
  long sentEverywhere = 0;
  MPI_Reduce(&sent, &sentEverywhere, 1, MPI_LONG, MPI_SUM, 0, MPI_COMM_WORLD);
  bool ok = !::testing::Test::HasFailure();
  if (worldRank() == 0) {
    std::vector<double> ids;
    for (std::size_t at = 0; at < all.size(); at += kWidth) ids.push_back(all[at + 3]);
    std::sort(ids.begin(), ids.end());
    std::vector<double> each(kTotal);
    std::iota(each.begin(), each.end(), 0.0);
    EXPECT_EQ(ids, each);
    if (worldSize() > 1) {
      EXPECT_GT(sentEverywhere, 0) << "no row crossed a block edge: the test tests nothing";
      EXPECT_TRUE(someExpected) << "rank 0 has no neighbour rows: the test tests nothing";
    }
    ok = ok && !::testing::Test::HasFailure();
  }
  int allOk = ok;
  MPI_Allreduce(MPI_IN_PLACE, &allOk, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  EXPECT_TRUE(allOk);
}

}  // namespace
}  // namespace msim::parallel
