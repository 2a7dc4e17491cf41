// The block decomposition and the ghost exchange: every stored sample of every block, ghosts of
// edge and corner neighbours included, holds the global field's value after one exchange; the
// decomposition picks the lattice of least interface and refuses rank counts it cannot use.
#include <gtest/gtest.h>

#include "msim/core/error.hpp"
#include "msim/parallel/ghost_exchange.hpp"
#include "mpi_test_support.hpp"

namespace msim::parallel {
namespace {

using testing::worldRank;
using testing::worldSize;

// A value that identifies its global sample: any misplaced copy shows.
float label(const IVec<3>& c) { return static_cast<float>(c[0] + 100 * c[1] + 10000 * c[2]); }

TEST(GhostExchange, FillsEveryGhostWithItsOwnersValueOnEveryLayout) {
  const GridSpec<3> global(Vec<3>::Zero(), 0.1, IVec<3>(13, 11, 9));
  const GridBlock<3> block(global, BlockDecomposition<3>(global.res, worldSize(), 2, "test"), worldRank(), 3);
  for (int layout = 0; layout < 4; ++layout) {  // cells, then faces along x, y, z
    const IVec<3> extra = layout == 0 ? IVec<3>::Zero().eval() : IVec<3>::Unit(layout - 1).eval();
    const GridSpec<3> local = block.localSpec();
    Vec<3> offset = Vec<3>::Constant(0.5);
    if (layout > 0) offset[layout - 1] = 0.0;
    Grid<float, 3> field(local, local.res + extra, offset, -1.0f);
    const IndexBox<3> owned = block.ownedSamples(worldRank(), extra);
    const IVec<3> origin = block.cellOrigin();
    for (std::size_t i = 0; i < field.count(); ++i) {
      const IVec<3> g = field.coord(i) + origin;
      if ((g.array() >= owned.lo.array()).all() && (g.array() < owned.hi.array()).all()) field[i] = label(g);
    }
    GhostExchange<float, 3>(block, extra, MPI_COMM_WORLD).exchange(field);
    int wrong = 0;
    for (std::size_t i = 0; i < field.count(); ++i)
      if (field[i] != label(field.coord(i) + origin)) ++wrong;
    EXPECT_EQ(wrong, 0) << "layout " << layout << " on rank " << worldRank();
  }
}

// The communication model of docs/parallel.md: two blocks of an n^3 grid split across x receive,
// per exchange, g n^2 cell samples and g n (n + 1) of each face component across the cut; along
// it, the lower block g + 1 layers (the face on the cut is the upper block's), the upper g.
TEST(GhostExchange, ReceivesTheVolumeTheCommunicationModelCounts) {
  if (worldSize() != 2) GTEST_SKIP() << "the model's case is two blocks";
  const int n = 24, g = 3;
  const GridSpec<3> global(Vec<3>::Zero(), 1.0 / n, IVec<3>::Constant(n));
  const GridBlock<3> block(global, BlockDecomposition<3>(global.res, IVec<3>(2, 1, 1), g, "test"), worldRank(), g);
  const GhostExchange<float, 3> cells(block, IVec<3>::Zero(), MPI_COMM_WORLD);
  const GhostExchange<float, 3> facesAlong(block, IVec<3>::Unit(0), MPI_COMM_WORLD);
  const int along = worldRank() == 0 ? g + 1 : g;
  EXPECT_EQ(cells.receivedSamples(), std::size_t(g * n * n));
  EXPECT_EQ(facesAlong.receivedSamples(), std::size_t(along * n * n));
  EXPECT_EQ(MacGhostExchange<3>(block, MPI_COMM_WORLD).receivedSamples(),
            std::size_t(along * n * n + 2 * g * n * (n + 1)));
}

TEST(BlockDecomposition, ChoosesTheLatticeOfLeastInterface) {
  // 8 ranks on a long grid: slabs across the long axis cut the fewest faces.
  EXPECT_EQ(BlockDecomposition<3>(IVec<3>(256, 32, 32), 8, 4, "k").blocks(), IVec<3>(8, 1, 1));
  // On a cube, 2x2x2.
  EXPECT_EQ(BlockDecomposition<3>(IVec<3>(64, 64, 64), 8, 4, "k").blocks(), IVec<3>(2, 2, 2));
  // A prime rank count on a cube: one axis takes it all.
  EXPECT_EQ(BlockDecomposition<3>(IVec<3>(64, 64, 64), 7, 4, "k").blocks().prod(), 7);
  // Owned boxes tile the grid: their cell counts add up and sizes differ by one at most.
  const BlockDecomposition<3> d(IVec<3>(35, 17, 9), IVec<3>(3, 2, 2), 1, "k");
  long long cells = 0;
  for (int r = 0; r < d.ranks(); ++r) cells += d.ownedCells(r).count();
  EXPECT_EQ(cells, 35LL * 17 * 9);
}

TEST(BlockDecomposition, RefusesARankCountThatCannotSplitTheGrid) {
  try {
    BlockDecomposition<3>(IVec<3>(8, 8, 8), 11, 4, "mpi ranks");
    FAIL() << "11 ranks on 8^3 cells with 4 per block";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mpi ranks"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("8x8x8"), std::string::npos) << e.what();
  }
  EXPECT_THROW(BlockDecomposition<3>(IVec<3>(8, 8, 8), IVec<3>(3, 1, 1), 4, "k"), InputError);
}

}  // namespace
}  // namespace msim::parallel
