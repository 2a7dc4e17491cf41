#pragma once
// The continuum step of the dense-crowd model (Narain 2011, ch. 4.3.2-4.4.3): the unilateral
// incompressibility constraint (UIC) projection.
//
//  1. Agents -> grid (eqs. 4.1-4.2, Linear kernel): density rho [agents/m^2] at cell centres and at
//     MAC faces (Sum splat of unit masses / dx^2), preferred velocity v~ on the faces (Normalized
//     splat), and the agents' preferred speed on the faces (Normalized splat), used as v_max in
//     renorm so that heterogeneous maximum speeds work; for uniform speeds it is the seed's
//     constant v_max.
//  2. v = psolve(renorm(psolve(v~))) (eq. 4.20), psolve(u) = u - grad p, each p from the LCP of
//     eqs. 4.15-4.19 with sigma = f rho_max - rho (ch. 4.4.3):
//        z = sigma^{n+1} = b + A p >= 0,  p >= 0,  p z = 0,
//        b = sigma^n + div(rho^n u) dt,   A x = -div(rho^n grad x) dt  (face weights rho_face dt/dx^2),
//     solved as min 1/2 p^T A p + b^T p, p >= 0 by MPRGP with MIC(0) in face (numerics/bound_qp),
//     each solve warm-started from its own pressure of the previous call. Domain boundary faces
//     are walls (no flux, zero normal velocity).
//     The clamp after eq. 4.20 is read as: the inner psolve uses b = max(sigma^n, 0) + div(...) dt,
//     so an overdensity left by the last step is corrected by the outer psolve alone, without
//     renorm amplifying the corrective motion.
//  3. Agent velocities (eq. 4.3): v_i = v~_i + r(x_i) (v(x_i) - v~_i), r = rho / (f rho_max)
//     clamped to [0, 1] per cell and interpolated bilinearly; v(x_i) gathered from the MAC grid.
//
// Cells whose faces all carry zero density (no agents around) are decoupled from the problem
// (A_ii = 0): p cannot act there, so they are excluded (p = 0). Every other diagonal gets a
// relative shift of settings.regularization, which makes A positive definite (A alone is a
// Neumann Laplacian, singular on a cluster with no slack cell) at a density error of
// regularization * p per cell, far below the solver tolerance.
//
// Cost: one bucketing and one fused splat pass over the agents, one fused gather pass, and per QP
// iteration O(cells of the crowd's bounding box) (the QP is posed on that box; MIC(0) works on the
// free cells only); the iteration count grows with the number of constrained cells, not with the
// agent count (ch. 4.5.1). Deterministic: independent of the thread count.
// Buffers are sized on the first call; later calls with as many agents or fewer do not allocate
// (except the QP box vectors when the crowd's bounding box changes size).
#include <span>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/core/transfer.hpp"
#include "msim/crowd/agents.hpp"
#include "msim/numerics/bound_qp.hpp"
#include "msim/numerics/bound_qp_mic0.hpp"

namespace msim::crowd {

struct UicSettings {
  // Maximum density rho_max [agents/m^2] (eq. 4.4: 2 alpha / (sqrt(3) d_min^2); 4.6 at
  // d_min = 0.5 m, alpha = 1).
  double rhoMax = 4.0;
  // QP stopping test: ||projected gradient||_2 <= tolerance * rhoMax. The projected gradient is the
  // residual of the LCP in density units (sigma^{n+1} on constrained cells, its negative part
  // elsewhere), so this bounds the predicted overdensity of every cell by tolerance * rhoMax.
  double tolerance = 5e-3;
  int maxIterations = 500;      // per QP solve
  double regularization = 1e-6;  // diagonal shift relative to rhoMax dt / dx^2 (see above)
  // Faces whose pressure-corrected speed is below this fraction of v_max keep their velocity in
  // renorm: their direction is noise (e.g. opposing streams cancelling).
  double renormMinFraction = 1e-3;
};

struct UicStats {
  int activeCells = 0;           // cells where the UIC is active after the outer solve (p > 0)
  int innerIterations = 0;       // MPRGP iterations of the inner psolve
  int outerIterations = 0;       // and of the outer psolve
  bool converged = false;        // both solves met the tolerance
  double maxRatioBefore = 0.0;   // max rho / (f rho_max) over the cells with f > 0, before
  double maxRatioAfter = 0.0;    // the same for the density predicted by the final v (eq. 4.14)
  double splatSeconds = 0.0;     // agents -> grid
  double solveSeconds = 0.0;     // both LCPs, stencil, renorm
  double agentSeconds = 0.0;     // grid -> agents (eq. 4.3)
  double totalSeconds = 0.0;
};

class UicProjection {
 public:
  // Throws std::invalid_argument for rhoMax <= 0 or non-finite, tolerance <= 0, maxIterations < 1,
  // a negative regularization or renormMinFraction, or a grid with dx <= 0 or res < 1.
  UicProjection(const GridSpec<2>& grid, const UicSettings& settings = {});

  // One projection for the agents' positions, preferred velocities v~_i and preferred (maximum)
  // speeds, over the free-area fractions `freeArea` (cell-centred on grid(), e.g.
  // FreeArea::fraction()), with time step dt [s]. Writes v_i of eq. 4.3 into `velocities`.
  // Throws InputError for a non-finite or outside-the-grid position, a non-finite preferred
  // velocity, a non-finite or negative speed, a free-area grid of another layout, a non-positive
  // dt, or spans of different sizes.
  const UicStats& project(std::span<const Vec2f> positions, std::span<const Vec2f> preferredVelocities,
                          std::span<const float> maxSpeeds, const Grid<float, 2>& freeArea, double dt,
                          std::span<Vec2f> velocities);

  const GridSpec<2>& grid() const { return grid_; }
  const UicSettings& settings() const { return settings_; }
  const UicStats& stats() const { return stats_; }
  // Fields of the last projection, for outputs and metrics.
  const Grid<float, 2>& density() const { return density_; }            // rho^n at cell centres [1/m^2]
  const MacGrid<2>& faceDensity() const { return faceDensity_; }        // rho^n at the faces [1/m^2]
  const MacGrid<2>& preferredVelocity() const { return preferred_; }    // v~ (eq. 4.2) [m/s]
  const MacGrid<2>& velocity() const { return velocity_; }              // v of eq. 4.20 [m/s]
  const Grid<float, 2>& pressure() const { return pressure_; }          // p of the outer psolve [m^2/s]
  const Grid<float, 2>& predictedDensity() const { return predicted_; }  // rho^n - div(rho^n v) dt
  const Grid<float, 2>& freeArea() const { return freeArea_; }          // f used by the last call

 private:
  // The fastest and slowest maximum speed (found while validating the agents).
  struct SpeedRange {
    float fastest = 0.0f, slowest = 0.0f;
  };
  SpeedRange validate(std::span<const Vec2f> positions, std::span<const Vec2f> preferredVelocities,
                      std::span<const float> maxSpeeds, const Grid<float, 2>& freeArea, double dt,
                      std::span<Vec2f> velocities) const;
  void splatAgents(std::span<const Vec2f> positions, std::span<const Vec2f> preferredVelocities,
                   std::span<const float> maxSpeeds, SpeedRange speeds);
  void buildStencil(double dt);
  template <typename F>
  void forBox(const F& f) const;
  // b of eq. 4.17 for face velocity u, in the solver's sign (minus b), excluded cells 0.
  double massOutflow(const MacGrid<2>& u, const IVec2& cell, std::size_t k) const;
  void assembleRhs(const MacGrid<2>& u, double dt, bool clampSigma, Eigen::VectorXd& rhs) const;
  numerics::BoundQpResult solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& p);
  void subtractGradient(const MacGrid<2>& u, const Eigen::VectorXd& p, MacGrid<2>& out) const;  // psolve
  void renorm(const MacGrid<2>& u, MacGrid<2>& out) const;
  void predict(double dt);
  void agentVelocities(std::span<const Vec2f> positions, std::span<const Vec2f> preferredVelocities,
                       std::span<Vec2f> velocities);

  GridSpec<2> grid_;
  UicSettings settings_;
  UicStats stats_;
  // Fused splat: each chunk of agents sums into grids of its own, zero between calls, and
  // records the rows of samples it touched. Single-precision accumulators (a cell sums tens of
  // weights <= 1): half the memory of double, so the five grids of a 126^2 crowd grid stay in a
  // 512 KB L2 cache.
  static constexpr std::size_t kChunkAgents = 32768, kMaxChunks = 8;
  struct SplatChunk {
    std::vector<float> cellMass;
    std::array<std::vector<float>, 2> faceMassFlow;  // per face its mass and its flow, interleaved
    std::array<std::vector<float>, 2> faceSpeed;
    int rowLo = 0, rowHi = -1;                         // rows of samples it holds
  };
  std::vector<SplatChunk> chunks_;

  Grid<float, 2> density_, pressure_, predicted_, freeArea_, ratio_;
  MacGrid<2> faceDensity_, preferred_, speed_, inner_, renormed_, velocity_;

  std::array<std::vector<double>, 2> lowerWeight_;  // stencil of A (numerics/bound_qp_mic0.hpp)
  std::vector<double> diagonal_;
  std::vector<std::uint8_t> excluded_;  // A_ii = 0: decoupled, p = 0
  // The QP lives on the bounding box of the included cells (boxOrigin_, boxRes_).
  bool boxEmpty_ = true;
  IVec2 boxOrigin_ = IVec2::Zero(), boxRes_ = IVec2::Ones();
  std::array<std::vector<double>, 2> boxLower_;
  std::vector<double> boxDiagonal_;
  Eigen::VectorXd boxRhs_, boxPressure_;
  numerics::GridPoissonQpOperator<2> operator_;
  numerics::GridMic0FacePreconditioner<2> preconditioner_;
  numerics::BoundQpSolver solver_;
  Eigen::VectorXd rhs_, innerPressure_, outerPressure_;

};

}  // namespace msim::crowd
