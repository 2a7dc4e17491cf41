#pragma once
// MpiDomainSplit: DomainSplit<3> over MPI for one rank's GridBlock: ghost exchanges per field
// layout (cells and the three face components), max-reductions, and the pressure solve through
// DistributedProjection (hypre).
#include <mpi.h>

#include <memory>

#include "msim/core/domain_split.hpp"
#include "msim/parallel/distributed_projection.hpp"
#include "msim/parallel/ghost_exchange.hpp"

namespace msim::parallel {

class MpiDomainSplit final : public DomainSplit<3> {
 public:
  MpiDomainSplit(const GridBlock<3>& block, const numerics::DomainSides<3>& sides,
                 const numerics::PcgSettings& pressureSolve, MPI_Comm comm);

  BlockPlacement<3> placement() const override { return block_.placement(); }
  GridSpec<3> localSpec() const override { return block_.localSpec(); }
  IndexBox<3> owned() const override { return block_.ownedLocal(); }
  void exchange(Grid<float, 3>& cells) override { cells_.exchange(cells); }
  void exchange(MacGrid<3>& faces) override { faces_.exchange(faces); }
  void exchange(Grid<float, 3>& faces, int axis) override { faces_.exchange(faces, axis); }
  void gather(const Grid<float, 3>& local, Grid<float, 3>& global) override;
  void gather(const MacGrid<3>& local, MacGrid<3>& global) override;
  bool root() const override { return block_.rank == 0; }
  double maxOverRanks(double value) override;
  double sumOverRanks(double value) override;
  void sumOverRanks(std::span<double> values) override;
  std::size_t migrate(std::vector<double>& rows, int width) override;
  std::vector<double> neighbourRows(const std::vector<double>& rows, int width, int reach) override;
  std::vector<double> gatherRows(const std::vector<double>& rows) override;
  void setFreeSurface(const Grid<float, 3>& liquidPhi) override { projection_.setFreeSurface(liquidPhi); }
  void setOpenFractions(const MacGrid<3>& openFraction) override { projection_.setOpenFractions(openFraction); }
  void setSolidVelocity(const MacGrid<3>& solidVelocity) override { projection_.setSolidVelocity(solidVelocity); }
  void setWallNormalVelocity(int axis, int side, double velocity) override {
    projection_.setWallNormalVelocity(axis, side, velocity);
  }
  void setWallFaceVelocity(const MacGrid<3>* velocity) override { projection_.setWallFaceVelocity(velocity); }
  void setTargetDivergence(double perSecond) override { projection_.setTargetDivergence(perSecond); }
  void setCellTargetDivergence(const Grid<float, 3>* perCell) override { projection_.setCellTargetDivergence(perCell); }
  SplitSolveStats project(MacGrid<3>& velocity, Grid<float, 3>& pressure, double dt, double density) override;

  const GridBlock<3>& block() const { return block_; }
  MPI_Comm comm() const { return comm_; }

 private:
  GridBlock<3> block_;
  MPI_Comm comm_;
  GhostExchange<float, 3> cells_;
  MacGhostExchange<3> faces_;
  DistributedProjection projection_;
};

}  // namespace msim::parallel
