#pragma once
// DistributedProjection: the pressure projection of numerics::PressureProjection (Selle ch. 3.2,
// steps 3-4, with Batty et al.'s face weights) on a grid split among MPI ranks. Selle ch. 8.1
// runs CG with exchanged rows, reduced dot products and a per-rank incomplete Cholesky; here the
// solve goes to hypre's structured-grid CG preconditioned by PFMG multigrid, which scales with
// the rank count where a per-rank preconditioner loses convergence at block edges (ch. 8's own
// pitfall). Each rank assembles its cells' rows; the face velocities across block edges come
// from the ghost layers, and the pressure of neighbouring cells likewise.
//
// The system is the serial one: A p^ = -dx div u* with p^ = p dt / (rho dx), A_ii = sum of the
// cell's face weights, A_ij = -w_f, domain walls w = 0, open sides Dirichlet (p = 0 beyond).
// Convergence is declared, as in the serial PcgSolver, when |b - A p^|_inf <= tolerance |b|_inf.
// Supported: solids (open fractions per face), at rest or moving (their face velocities), and
// walls at rest or moving along their normals. A domain without open
// sides has the constants as null space; the right-hand side's mean over fluid cells is removed
// and one fluid cell is pinned, which changes p^ by a constant only (one connected fluid region
// is assumed, as in a box of smoke).
#include <HYPRE_struct_ls.h>
#include <mpi.h>

#include <array>
#include <optional>
#include <vector>

#include "msim/core/domain_split.hpp"
#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/numerics/pressure/pcg.hpp"
#include "msim/numerics/pressure/projection.hpp"
#include "msim/parallel/ghost_exchange.hpp"

namespace msim::parallel {

class DistributedProjection {
 public:
  DistributedProjection(const GridBlock<3>& block, const numerics::DomainSides<3>& sides,
                        const numerics::PcgSettings& settings, MPI_Comm comm, float minOpenFraction = 0.01f);
  ~DistributedProjection();
  DistributedProjection(const DistributedProjection&) = delete;
  DistributedProjection& operator=(const DistributedProjection&) = delete;

  // Open fraction of every local face (block.localSpec()'s MAC layout; ghosts need not be
  // filled); rebuilds the matrix and the multigrid hierarchy. Collective.
  void setOpenFractions(const MacGrid<3>& openFraction);
  // A free surface, as numerics::PressureProjection::setFreeSurface: cells with liquidPhi >= 0
  // are air at pressure 0 with no unknown; a liquid cell's face towards air adds w / theta to its
  // diagonal (the surface at theta = phi_i / (phi_i - phi_j), at least minTheta, ghost fluid
  // method) and the update across it is divided by theta. liquidPhi is the local cell-centred
  // field; its ghosts are exchanged here. Rebuilds the matrix. Collective.
  void setFreeSurface(const Grid<float, 3>& liquidPhi, float minTheta = 1e-3f);
  // The velocity of moving solids on every local face (block.localSpec()'s MAC layout), as
  // numerics::PressureProjection::setSolidVelocity: a face's closed part moves with it (its flux
  // counts in the divergence the solve removes) and a closed face takes it. The domain's walls
  // move with their own normal velocity whatever it says. Its ghosts are exchanged here.
  // Collective.
  void setSolidVelocity(const MacGrid<3>& solidVelocity);
  // A domain wall that moves along its normal (fluid enters or leaves through it: a wind
  // tunnel's inlet), as numerics::PressureProjection::setWallNormalVelocity [m/s along +axis].
  void setWallNormalVelocity(int axis, int side, double velocity);
  // Per wall face, added to its wall's normal velocity (a liquid's inflow under an emitter lying
  // against a wall; null: none), as numerics::PressureProjection::setWallFaceVelocity: local faces.
  void setWallFaceVelocity(const MacGrid<3>* velocity);
  // The divergence [1/s] the projection leaves in each local cell (expanding gas), as
  // numerics::PressureProjection::setCellTargetDivergence; null: none. Kept by pointer: the field
  // must outlive the calls to project().
  void setCellTargetDivergence(const Grid<float, 3>* perCell) { cellTargetDivergence_ = perCell; }
  // The divergence [1/s] left in every fluid cell besides (a liquid's volume control), as
  // numerics::PressureProjection::setTargetDivergence.
  void setTargetDivergence(double perSecond) { targetDivergence_ = perSecond; }
  // Makes the owned faces of `velocity` (a local MAC grid) divergence free; its ghosts are
  // exchanged first and are stale afterwards. `pressure` [Pa] (local, cell-centred) warm-starts
  // the solve and receives its result on the owned cells, as the serial projection keeps its
  // own (so a resumed run starts from the saved one). Collective.
  SplitSolveStats project(MacGrid<3>& velocity, Grid<float, 3>& pressure, double dt, double density);

  const MacGrid<3>& faceWeights() const { return weights_; }

 private:
  // How face `side` (0 lower, 1 upper) along `axis` of local cell l enters the equations.
  struct FaceTerm {
    double weight;  // w_f
    bool coupled;   // the neighbour across has an unknown
    double scale;   // 1 / theta across a liquid-air face, else 1
    IVec<3> across;  // the local cell on the face's other side
  };
  FaceTerm faceTerm(const IVec<3>& l, int axis, int side) const;
  void assemble();
  void destroyHypre();
  // |b - A x|_inf over every rank, for x = scaled_ with its ghosts filled.
  double maxResidual();

  GridBlock<3> block_;
  IVec<3> origin_;  // block_.cellOrigin(), kept: the face terms read it for every face
  numerics::DomainSides<3> sides_;
  numerics::PcgSettings settings_;
  MPI_Comm comm_;
  float minOpenFraction_;
  MacGrid<3> weights_;
  MacGrid<3> solidVelocity_;                 // with ghosts; the walls' own on the domain's walls
  std::array<std::array<float, 2>, 3> wallNormalVelocity_{};
  std::optional<MacGrid<3>> wallFaceVelocity_;  // setWallFaceVelocity
  const Grid<float, 3>* cellTargetDivergence_ = nullptr;
  double targetDivergence_ = 0.0;
  void applyWallVelocities();  // the walls' normal velocities into solidVelocity_
  // The side (0 lower, 1 upper) of the domain wall that local face `face` of `axis` lies on, or -1.
  int wallSide(int axis, const IVec<3>& face) const;
  std::optional<Grid<float, 3>> liquidPhi_;  // with ghosts; empty without a free surface
  MacGrid<3> inverseTheta_;                  // 1 / theta on liquid-air faces, 1 elsewhere
  MacGhostExchange<3> velocityGhosts_, weightGhosts_;
  GhostExchange<double, 3> cellGhosts_;
  GhostExchange<float, 3> phiGhosts_;
  Grid<double, 3> scaled_;  // p^ with ghosts, in hypre's precision: the residual test reads it
  std::vector<double> rhs_, values_, coefficients_;
  std::vector<unsigned char> fluid_;  // owned cells with an unknown (some face open)
  long long pinned_ = -1;             // global index of the pinned cell, -1 when none
  long long pinnedOrdinal_ = -1;      // its owned-cell ordinal on this rank, -1 when another rank owns it
  HYPRE_StructGrid grid_ = nullptr;
  HYPRE_StructStencil stencil_ = nullptr;
  HYPRE_StructMatrix matrix_ = nullptr;
  HYPRE_StructVector b_ = nullptr, x_ = nullptr;
  HYPRE_StructSolver pcg_ = nullptr, pfmg_ = nullptr;
};

}  // namespace msim::parallel
