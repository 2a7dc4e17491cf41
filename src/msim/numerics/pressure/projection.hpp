#pragma once
// PressureProjection<D>: steps 3 and 4 of Selle's pressure-velocity method (ch. 3.2): solve the
// Poisson equation lap p = (rho / dt) div u* and set u = u* - (dt / rho) grad p, on a MAC grid with
// solids given by per-face open fractions (Batty, Bertails & Bridson 2007):
//
//   flux through face f:  F_f = w_f u_f + (1 - w_f) u_solid,f     (w_f = open fraction)
//   divergence of cell i: div_i = sum_a (F_{i+1/2} - F_{i-1/2}) / dx
//
// With p^ = p dt / (rho dx) the projected velocity is u_f = u*_f - (p^_up - p^_low) and
// div(u) = 0 becomes A p^ = -dx div(u*), A the face-weighted matrix of PoissonMatrix. Faces that
// are fully solid take the solid's velocity (moving obstacles push the fluid), domain walls are
// solid and static, open domain sides hold p = 0 in the ghost cells (Dirichlet). Cells with no
// open face are inside the solid and have no pressure. The solver's max-norm residual is the
// divergence left over, so the tolerance bounds max |div u| relative to max |div u*|.
#include <array>
#include <memory>
#include <optional>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/numerics/pressure/floating_regions.hpp"
#include "msim/numerics/pressure/mic0.hpp"
#include "msim/numerics/pressure/multigrid.hpp"
#include "msim/numerics/pressure/pcg.hpp"
#include "msim/numerics/pressure/poisson_matrix.hpp"

namespace msim::numerics {

enum class DomainSide { Wall, Open };

template <int D>
struct DomainSides {
  std::array<std::array<DomainSide, 2>, D> side{};  // [axis][0 = lower, 1 = upper]; default walls
  static DomainSides allWalls() { return {}; }
  static DomainSides allOpen() {
    DomainSides s;
    for (auto& axis : s.side) axis = {DomainSide::Open, DomainSide::Open};
    return s;
  }
};

enum class PressurePreconditioner { Multigrid, Mic0 };

struct ProjectionSettings {
  PressurePreconditioner preconditioner = PressurePreconditioner::Multigrid;
  PcgSettings pcg;
  Mic0Settings mic0;
  MultigridSettings multigrid;
  // Faces open by less than this are closed: a sliver of a face adds a near-zero row to the
  // matrix (ill-conditioning) while closing it only forbids flow through a vanishing area.
  float minOpenFraction = 0.01f;
};

template <int D>
class PressureProjection {
 public:
  PressureProjection(const GridSpec<D>& spec, const DomainSides<D>& sides, const ProjectionSettings& settings = {});
  // The preconditioners point into this object.
  PressureProjection(const PressureProjection&) = delete;
  PressureProjection& operator=(const PressureProjection&) = delete;

  // Open fraction in [0,1] of every face (e.g. openFaceFractionsFromSdf); rebuilds the matrix,
  // its null space and the preconditioner (multigrid hierarchy). Without a call all faces are open.
  void setSolids(const MacGrid<D>& openFraction);
  // Velocity of the solid on each face [m/s]; used where faces are (partly) solid. Default 0;
  // faces on domain walls take the wall's normal velocity instead.
  void setSolidVelocity(const MacGrid<D>& solidVelocity);
  // Normal velocity [m/s, positive along +axis] of the wall on side 0 (lower) or 1 (upper) of
  // `axis`; default 0. A wall that moves fluid in or out is an inflow or outflow boundary with a
  // Neumann pressure condition (the wind tunnel of Selle ch. 2.9). Where every side is a wall the
  // caller must keep the net inflow zero, or no divergence-free field exists. Ignored on open sides.
  void setWallNormalVelocity(int axis, int side, double velocity);
  // Normal velocity [m/s] through single faces of the walls, added to their wall's (an inflow
  // over part of a side: a liquid's emitter against it); faces off the walls are ignored. Null:
  // none.
  void setWallFaceVelocity(const MacGrid<D>* velocity);

  // A free surface (liquids): cells with liquidPhi < 0 are liquid, the others air at pressure 0
  // with no unknown. Between a liquid cell i and an air neighbour j the surface lies at the
  // fraction theta = phi_i / (phi_i - phi_j) of the way from i to j (phi linear in between), and
  // the ghost-fluid method (Gibou, Fedkiw, Cheng & Kang 2002, as Enright, Nguyen & Fedkiw 2003
  // use it for water) extrapolates the pressure linearly to p = 0 there: the face adds
  // w_f / theta to i's diagonal and the update across it becomes u -= (p_j - p_i) / theta, which
  // is second order in the surface's position. theta is clamped below at minTheta (a cell whose
  // centre lies on the surface would otherwise get an unbounded diagonal). Rebuilds the matrix,
  // its null space (a drop touching no air or open side floats) and the preconditioner (the
  // multigrid hierarchy coarsens the Dirichlet terms too). Faces between two air cells keep their
  // velocity (the caller extrapolates it).
  void setFreeSurface(const Grid<float, D>& liquidPhi, float minTheta = 1e-3f);
  // Divergence [1/s] the projected velocity keeps in every cell that has an unknown (default 0):
  // the volume control of Kim, Liu, Llamas, Jiao & Rossignac (2007) makes a liquid that has lost
  // volume expand by div u = c > 0. A region with no Dirichlet cell cannot change its volume; its
  // mean target is removed with the rest of its right-hand side's mean (floatingRegions()).
  void setTargetDivergence(double perSecond) { targetDivergence_ = static_cast<float>(perSecond); }
  // A divergence [1/s] per cell added to the uniform one (an explosion's or a flame's expansion
  // where its gas is released); null: none. The grid must outlive its use.
  void setCellTargetDivergence(const Grid<float, D>* perCell) { cellTargetDivergence_ = perCell; }

  // Makes `velocity` divergence free; the pressure [Pa] is kept (pressure()) and warm-starts
  // the next call.
  PcgStats project(MacGrid<D>& velocity, double dt, double density);

  // Face-weighted divergence [1/s] of a velocity field (0 in cells inside solids).
  void divergence(const MacGrid<D>& velocity, Grid<float, D>& out) const;

  const Grid<float, D>& pressure() const { return pressure_; }
  Grid<float, D>& pressure() { return pressure_; }
  // Effective face weights: open fractions after thresholding, 0 on domain walls.
  const MacGrid<D>& faceWeights() const { return weights_; }
  // Velocity of the solids on every face (setSolidVelocity, with the wall velocities applied).
  const MacGrid<D>& solidVelocity() const { return solidVelocity_; }
  const PoissonMatrix<D>& matrix() const { return matrix_; }
  const FloatingRegions<D>& floatingRegions() const { return floating_; }
  // Levels of the multigrid hierarchy (1 when the MIC(0) preconditioner is used). The hierarchy
  // is built by the first projection after the matrix changed, so a projection whose solve runs
  // elsewhere (a grid split among processes) never pays for it.
  int multigridLevels() const { return multigrid_ ? multigrid_->levelCount() : 1; }
  const ProjectionSettings& settings() const { return settings_; }

 private:
  // dx * divergence per cell (the negated right-hand side of A p^ = b).
  void netOutflow(const MacGrid<D>& velocity, std::vector<float>& out) const;
  // Writes the wall normal velocities onto the wall faces of solidVelocity_.
  void applyWallVelocities();

  GridSpec<D> spec_;
  DomainSides<D> sides_;
  ProjectionSettings settings_;
  // Builds the preconditioner chosen by the settings for matrix_; invalidate drops it after the
  // matrix changed, and the next projection builds it again.
  void buildPreconditioner();
  void invalidatePreconditioner();
  bool preconditionerStale_ = true;

  MacGrid<D> weights_;
  MacGrid<D> solidVelocity_;
  std::optional<MacGrid<D>> wallFaceVelocity_;  // setWallFaceVelocity
  MacGrid<D> inverseTheta_;  // 1 / theta on liquid-air faces, 1 elsewhere; empty without a free surface
  MacGrid<D> coupling_;      // with a free surface: the weights between cells that have unknowns
  std::vector<float> dirichlet_;  // with a free surface: PoissonMatrix's Dirichlet terms
  bool freeSurface_ = false;
  float targetDivergence_ = 0.0f;
  const Grid<float, D>* cellTargetDivergence_ = nullptr;
  std::array<std::array<float, 2>, D> wallNormalVelocity_{};
  PoissonMatrix<D> matrix_;
  FloatingRegions<D> floating_;
  std::unique_ptr<Mic0Preconditioner<D>> mic0_;
  std::unique_ptr<MultigridPreconditioner<D>> multigrid_;
  PcgSolver<D> pcg_;
  Grid<float, D> pressure_;
  std::vector<float> rhs_, scaledPressure_;
};

}  // namespace msim::numerics
