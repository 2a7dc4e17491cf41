#pragma once
// The Eulerian side of the inter-personal stress model (Golas ch. 4.3, Fig. 4.1 steps 1, 3, 4):
// the density (eq. 4.1) and velocity (eq. 4.2) splatted from the agents with a bilinear hat, with
// the obstacle correction (a partly covered cell's values divided by its free fraction, at least
// 0.05; a fully covered cell takes the density of the nearest cell that is not, so the density's
// gradient is tangential at walls); the discomfort's gradient on the cells' faces; and friction,
// the trace-free stress s of maximal dissipation (eq. 4.12):
//   minimise E(s) = 1 / (2 rho_yield) sum_faces (m*_f + dt (D s)_f)^2  over |s_d|, |s_o| <= b(rho),
// a bound-constrained convex QP solved by MPRGP (numerics/bound_qp.hpp, as the seed: Dostál and
// Schöberl 2005). Layout [the seed's, per Narain et al. 2010, is not printed]: momenta m on the MAC
// faces, s_d = s_xx = -s_yy at cell centres, s_o = s_xy at the cell corners, D the divergence of s
// onto the faces: (div s)_x = d_x s_d + d_y s_o, (div s)_y = d_x s_o - d_y s_d. Faces on the
// domain's walls or next to a fully covered cell carry no momentum (their rows drop out).
#include <span>
#include <vector>

#include <Eigen/Core>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/core/transfer.hpp"
#include "msim/crowd/agents.hpp"
#include "msim/crowd/stress/stress_laws.hpp"
#include "msim/numerics/bound_qp.hpp"

namespace msim::crowd::stress {

struct FrictionResult {
  numerics::BoundQpResult qp;
  double energyBefore = 0.0;  // E(0)
  double energyAfter = 0.0;   // E(s*)
};

class StressGrid {
 public:
  explicit StressGrid(const GridSpec<2>& grid);
  const GridSpec<2>& grid() const { return grid_; }

  // Eqs. 4.1-4.2 with the obstacle correction; `free` is each cell's free fraction (FreeArea).
  // `collisionFree` (empty, or one per agent) is averaged onto the cells the same way.
  void splat(std::span<const Vec2f> positions, std::span<const Vec2f> velocities, const Grid<float, 2>& free,
             std::span<const Vec2f> collisionFree = {});
  const Grid<float, 2>& density() const { return density_; }      // [1/m^2]
  const Grid<float, 2>& velocityX() const { return velocityX_; }  // [m/s], 0 where nobody is
  const Grid<float, 2>& velocityY() const { return velocityY_; }
  const Grid<float, 2>& collisionFreeX() const { return collisionFreeX_; }  // [m/s], 0 where nobody is
  const Grid<float, 2>& collisionFreeY() const { return collisionFreeY_; }
  // Whether the face carries momentum (inside the domain, between two cells not fully covered):
  // x faces first ((nx + 1) ny of them), then y faces (nx (ny + 1)).
  bool activeFace(std::size_t face) const { return active_[face] != 0; }
  std::size_t faceCount() const { return active_.size(); }

  // grad g(rho) on the faces: (g(right) - g(left)) / h, 0 on faces that carry no momentum.
  void discomfortGradient(const StressLaws& laws, MacGrid<2>& gradient) const;

  // Friction for the face momenta m* (faceCount() entries, 0 on inactive faces) over a step dt:
  // the QP above, warm-started from the last solve's stress, and the momentum change dt D s* on
  // the faces (`change`, faceCount() entries).
  FrictionResult friction(const Eigen::VectorXd& momentum, double dt, const StressLaws& laws,
                          const numerics::BoundQpSettings& settings, Eigen::VectorXd& change);
  // E(s) of eq. 4.12 for the face momenta m* and any stress s (as stress()), dt and rho_yield.
  double energy(const Eigen::VectorXd& momentum, const Eigen::VectorXd& stress, double dt, const StressLaws& laws) const;
  // The last solve's stress: s_d per cell (x fastest), then s_o per corner ((nx + 1) (ny + 1)).
  const Eigen::VectorXd& stress() const { return stress_; }
  const Eigen::VectorXd& bound() const { return upper_; }  // b per stress unknown
  // faces = D s (faceCount() entries, 0 on faces that carry no momentum) and its transpose,
  // stress = D^T faces (the values on faces that carry no momentum ignored), both on the grid;
  // std::invalid_argument for vectors of other sizes.
  void divergence(const Eigen::VectorXd& stress, Eigen::VectorXd& faces) const;
  void divergenceTranspose(const Eigen::VectorXd& faces, Eigen::VectorXd& stress) const;

 private:
  void followOpenFaces();

  GridSpec<2> grid_;
  int nx_ = 0, ny_ = 0;
  Grid<float, 2> count_, momentumX_, momentumY_, density_, velocityX_, velocityY_, covered_;
  Grid<float, 2> sumX_, sumY_, collisionFreeX_, collisionFreeY_;
  std::vector<float> ones_, vx_, vy_, cx_, cy_;
  Splatter<2> splatter_;
  std::vector<std::uint8_t> active_, builtFor_;
  Eigen::VectorXd columnNorms_;          // |column k of D|^2
  Eigen::VectorXd stress_, lower_, upper_, rhs_, diagonal_, faces_;
  std::vector<std::uint8_t> known_, nextKnown_;  // splat(): cells whose density is set
  numerics::BoundQpSolver solver_;
};

}  // namespace msim::crowd::stress
