#pragma once
// DomainSplit<D>: what a grid solver needs from the processes its domain is split among
// (msim/parallel implements it over MPI; Selle ch. 8.1). The solver's grids are one block of the
// global grid with ghost layers (placement()); it calls exchange() where a stencil is about to
// read the neighbours' samples, reduces its scalars over the ranks, and hands the pressure solve,
// the one global coupling, to project(). Without a split (the default) none of this is called.
#include <cstddef>
#include <span>
#include <vector>

#include "msim/core/block_placement.hpp"
#include "msim/core/grid.hpp"
#include "msim/core/index_box.hpp"
#include "msim/core/mac_grid.hpp"

namespace msim {

struct SplitSolveStats {
  int iterations = 0;
  double relativeResidual = 0.0;  // |b - A x|_inf / |b|_inf over every rank
  bool converged = false;
};

template <int D>
class DomainSplit {
 public:
  virtual ~DomainSplit() = default;
  virtual BlockPlacement<D> placement() const = 0;
  // The local grid: the owned cells and the ghost layers, over which the solver's fields lie.
  virtual GridSpec<D> localSpec() const = 0;
  // The owned cells in the local grid's coordinates.
  virtual IndexBox<D> owned() const = 0;
  // Fills the ghost samples of a local cell-centred field, or of every component of a local MAC
  // grid, from their owners. Collective.
  virtual void exchange(Grid<float, D>& cells) = 0;
  virtual void exchange(MacGrid<D>& faces) = 0;
  // The same for one face component of a MAC grid (a local grid of that layout). Collective.
  virtual void exchange(Grid<float, D>& faces, int axis) = 0;
  // The owned samples of every rank's local field put together into `global` on rank 0 (left
  // as it is elsewhere). Collective.
  virtual void gather(const Grid<float, D>& local, Grid<float, D>& global) = 0;
  virtual void gather(const MacGrid<D>& local, MacGrid<D>& global) = 0;
  // Whether this rank writes the run's files (rank 0).
  virtual bool root() const = 0;
  // The largest of `value` over every rank, and the sum. Collective.
  virtual double maxOverRanks(double value) = 0;
  virtual double sumOverRanks(double value) = 0;
  // Each entry summed over every rank, in place (every rank passes as many). Collective.
  virtual void sumOverRanks(std::span<double> values) = 0;
  // The local samples [lo, hi) of a field with the given layout (cell-centred: zero; face
  // component a: unit vector a) that are this rank's own: its owned cells, and along a face axis
  // the faces below them, the domain's last face belonging to the last block.
  void ownedSamples(const IVec<D>& extra, IVec<D>& lo, IVec<D>& hi) const {
    lo = owned().lo;
    hi = owned().hi;
    const BlockPlacement<D> where = placement();
    for (int a = 0; a < D; ++a)
      if (extra[a] > 0 && hi[a] + where.cellOrigin[a] == where.globalRes[a]) hi[a] += 1;
  }
  // Particles as rows of `width` doubles whose first D entries are the position [m]; a particle
  // belongs to the rank whose owned cells hold it (outside the domain: the nearest cell's).
  // migrate: the rows this rank no longer owns go to their owners, those received are appended;
  // returns how many left. Collective.
  virtual std::size_t migrate(std::vector<double>& rows, int width) = 0;
  // Copies of the other ranks' rows lying within `reach` cells of this rank's own cells (at most
  // the ghost layers; each rank passes its own rows): the neighbours' particles whose stencils
  // touch an owned cell. Collective.
  virtual std::vector<double> neighbourRows(const std::vector<double>& rows, int width, int reach) = 0;
  // Every rank's rows on rank 0, in rank order (elsewhere: empty). Collective.
  virtual std::vector<double> gatherRows(const std::vector<double>& rows) = 0;
  // Static solids for the pressure solve: the open fraction of every local face. Collective.
  virtual void setOpenFractions(const MacGrid<D>& openFraction) = 0;
  // Moving solids for the pressure solve: their velocity on every local face (the closed parts
  // of faces move with it). Collective.
  virtual void setSolidVelocity(const MacGrid<D>& solidVelocity) = 0;
  // A domain wall moving along its normal (an inlet) [m/s along +axis]; others stay at rest.
  virtual void setWallNormalVelocity(int axis, int side, double velocity) = 0;
  // Besides, the wall faces of the block given their own normal velocity (a liquid's inflow where an
  // emitter lies against a wall; null: none), as PressureProjection::setWallFaceVelocity. Local.
  virtual void setWallFaceVelocity(const MacGrid<D>* velocity) = 0;
  // The divergence [1/s] project() leaves in each local cell (expanding gas; null: none). The
  // field must outlive the calls to project().
  virtual void setCellTargetDivergence(const Grid<float, D>* perCell) = 0;
  // A divergence [1/s] left in every fluid cell besides (a liquid's volume control).
  virtual void setTargetDivergence(double perSecond) = 0;
  // A free surface for the pressure solve (liquids): cells with liquidPhi >= 0 are air at
  // pressure 0, as numerics::PressureProjection::setFreeSurface. Collective.
  virtual void setFreeSurface(const Grid<float, D>& liquidPhi) = 0;
  // The pressure projection of the global grid on the local velocity:
  // u = u* - (dt / rho) grad p with div u = 0 on the owned cells; `pressure` [Pa] warm-starts
  // the solve and receives p on the owned cells. Collective.
  virtual SplitSolveStats project(MacGrid<D>& velocity, Grid<float, D>& pressure, double dt, double density) = 0;
};

}  // namespace msim
