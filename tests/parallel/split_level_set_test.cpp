// Redistancing on a split grid (Selle ch. 8.1, seed notes A5): the distances within k cells of
// the interface against the serial fast marching's, with ceil(k) ghost layers, fewer and more.
#include <gtest/gtest.h>

#include <cmath>

#include "msim/parallel/split_level_set.hpp"
#include "mpi_test_support.hpp"

namespace msim::parallel {
namespace {

using testing::fromRoot;
using testing::worldRank;
using testing::worldSize;

const GridSpec<3> kLevelSetGrid(Vec<3>::Zero(), 1.0 / 40, IVec<3>(40, 36, 32));
constexpr double kBand = 6.0;  // the serial reinitialisation's band [cells]

// A wobbly ball whose phi is far from a distance (scaled and bumped): the march has work.
Grid<float, 3> wobblyBall() {
  Grid<float, 3> phi(kLevelSetGrid);
  for (std::size_t i = 0; i < phi.count(); ++i) {
    const Vec<3> x = phi.position(phi.coord(i)) - Vec<3>(0.52, 0.44, 0.41);
    const double r = x.norm(), bump = 0.04 * std::sin(9 * x[0]) * std::cos(7 * x[1]) + 0.03 * std::sin(11 * x[2]);
    phi[i] = static_cast<float>(3.0 * (r - 0.27 - bump) * (1.0 + x[0]));
  }
  return phi;
}

// Largest |split - serial| [cells] over the cells within k cells of the interface (by the serial
// distance), on rank 0 (0 elsewhere).
double differenceWithin(double k, int ghost) {
  Grid<float, 3> serial = wobblyBall();
  if (worldRank() == 0) numerics::reinitializeFastMarching<3>(serial, kBand);
  const GridBlock<3> block(kLevelSetGrid, BlockDecomposition<3>(kLevelSetGrid.res, worldSize(), 2, "test"), worldRank(), ghost);
  Grid<float, 3> local = localPart(wobblyBall(), block);
  GhostExchange<float, 3> ghosts(block, IVec<3>::Zero(), MPI_COMM_WORLD);
  reinitializeSplit<3>(local, ghosts, kBand);
  const Grid<float, 3> split = gatherToRoot(local, block, MPI_COMM_WORLD);
  double worst = 0.0;
  if (worldRank() == 0)
    for (std::size_t i = 0; i < serial.count(); ++i)
      if (std::abs(serial[i]) <= k * kLevelSetGrid.dx) worst = std::max(worst, double(std::abs(serial[i] - split[i])));
  return worst / kLevelSetGrid.dx;
}

// The chapter's rule: a band of k valid cells needs ceil(k) ghost layers. The discrete distance
// of a cell depends on its whole upwind cone, which spreads sideways beyond k cells, so the split
// distances are not bit-equal there: they agree within 0.015 cells (half the serial march's own
// error, 0.03 cells on a circle), and one layer fewer gives at least 3 times the difference.
TEST(SplitLevelSet, DistancesWithinKCellsMatchTheSerialOnesWithCeilKGhostLayers) {
  for (double k : {1.5, 3.0, 4.5}) {
    const int ghost = static_cast<int>(std::ceil(k));
    const double enough = differenceWithin(k, ghost), fewer = differenceWithin(k, ghost - 1);
    if (worldRank() == 0) {
      std::printf("band of %.1f cells on %d ranks: %d ghost layers %.2g cells from the serial distances, %d: %.2g\n", k,
                  worldSize(), ghost, enough, ghost - 1, fewer);
      EXPECT_LT(enough, 0.015) << "k = " << k;
      if (worldSize() > 1) {
        EXPECT_GT(fewer, 3.0 * enough) << "k = " << k;
      }
    }
    fromRoot(!::testing::Test::HasFailure());
  }
}

// Wider ghost layers converge to the serial march: three more than ceil(k) agree to 1e-4 cells.
TEST(SplitLevelSet, WiderGhostLayersConvergeToTheSerialDistances) {
  const double d = differenceWithin(3.0, 6);
  if (worldRank() == 0) {
    EXPECT_LT(d, 1e-4);
  }
  fromRoot(!::testing::Test::HasFailure());
}

}  // namespace
}  // namespace msim::parallel
