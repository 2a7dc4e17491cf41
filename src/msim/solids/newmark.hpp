#pragma once
// The time step of Selle ch. 5.4: elasticity explicit, damping implicit (the elastic step limit
// grows linearly with the stiffness's inverse square root, the damping's only with its inverse;
// fully implicit over-damps). With h = dt / 2:
//   1. v(n+1/2) from v(n) by backward Euler over h at x(n):
//        M v' = M v(n) + h (F_e(x(n)) + F_d(v')),  a linear solve by CG;
//   2. x(n+1) = x(n) + dt v(n+1/2);
//   3. step 1 again at x(n+1/2) = (x(n) + x(n+1)) / 2;
//   4. v(n+1) = 2 v(n+1/2) - v(n).
// Steps 3-4 are the trapezoidal rule, better conditioned (the seed prints (x(n) + v(n+1)) / 2 in
// step 3 and drops the minus in step 4: misprints). With implicit linear springs (ch. 5.5) each
// spring's force is linearised about its direction d at the solve's positions, which adds the
// damping h k / l0 along d (the seed's dt k / l0 for a whole step; here the half step's own h);
// beyond the seed, a stretched spring's tension T also acts implicitly across it (h T / L), so
// that a swinging cloth, not only a hanging one, is stable at one step per frame.
// Pinned particles keep their velocity (scripted vertices set it) and move with it.
// With bodies (ch. 6.2 B, 6.5) the step becomes the seed's inner step without self-collisions:
// step 2 moves each particle with BodyContact::move (cut where it meets a body, the rest of the
// step with Gamma of its velocity); particles that met a body restart step 3 from Gamma(v(n)) and
// end with Gamma of their new velocity (object friction, step B.7). With self-repulsion the
// velocity that moves the positions gets the inelastic and elastic repulsions before step 2 (step
// B.2) and the end velocity the inelastic ones with friction (step B.8; self_repulsion.hpp).
#include <array>
#include <utility>
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/numerics/block_jacobi.hpp"
#include "msim/numerics/smoothed_aggregation.hpp"
#include "msim/numerics/sparse_cg.hpp"
#include "msim/solids/body_contact.hpp"
#include "msim/solids/mass_spring.hpp"
#include "msim/solids/newmark_matrix.hpp"
#include "msim/solids/particle_split.hpp"
#include "msim/solids/self_repulsion.hpp"

namespace msim::solids {

// How the solves are preconditioned: the inverse of each particle's 3 x 3 diagonal block
// (block-Jacobi), or a smoothed-aggregation multigrid V-cycle on the matrix
// (numerics/smoothed_aggregation.hpp, with the rigid motions as near-null space). Multigrid's
// iteration counts stay nearly flat as a taut cloth at a large step is refined, where Jacobi's grow
// with its width; at the small steps of colliding cloth the matrix is well conditioned and the
// cheaper Jacobi iterations win (docs/solids.md).
enum class SolvePreconditioner { Jacobi, Multigrid };

struct NewmarkSettings {
  bool implicitSprings = false;  // ch. 5.5
  bool tensionAcross = true;     // with implicit springs: a stretched spring's T / L across it too
  int newtonIterations = 1;      // most linearisations per half step with implicit springs (the seed: 1)
  double newtonTolerance = 1e-3;  // stop once an iteration moves no particle's x_k by this of the shortest spring
  double cgTolerance = 1e-6;     // relative residual of each solve (the seed's Table 6.1: 1e-3)
  int cgMaxIterations = 1000;
  SolvePreconditioner preconditioner = SolvePreconditioner::Jacobi;
};

struct NewmarkStats {
  int iterations = 0;        // CG iterations of the step's two solves
  bool converged = true;     // both reached the tolerance
  int contacts = 0;          // particles that met a body
  int repulsions = 0;        // self-repulsion pairs closer than the thickness (step B.2)
  int linearisations = 0;    // solves of the step's two half steps (Newton iterations)
  int preconditionerSetups = 0;  // multigrid hierarchies built (one serves solves until it ages)
};

class NewmarkStepper {
 public:
  explicit NewmarkStepper(const NewmarkSettings& settings = {}) : settings_(settings) {}
  // Advances the system by dt, against `bodies` and with `repulsion` when given;
  // std::invalid_argument for dt <= 0.
  NewmarkStats step(MassSpringSystem& system, double dt, const BodyContact* bodies = nullptr,
                    SelfRepulsion* repulsion = nullptr);
  const NewmarkSettings& settings() const { return settings_; }
  // Splits the solves' rows among processes (particle_split.hpp; null: this process alone): each
  // computes its own particles' rows of every product and the dot products over them, summed over
  // the processes, and the answer's rows are shared after each solve; each assembles its own rows
  // of the matrix (the forces and the springs' linearisation are evaluated whole on every process).
  // Block-Jacobi only (std::invalid_argument with multigrid, whose V-cycle mixes the rows).
  void setSplit(const ParticleSplit* split);

 private:
  // Backward Euler over h from velocity `from`, the elasticity taken where the positions `base`
  // move to with the answer (newmark.cpp), into `out`, whose free particles' values on entry are
  // the solves' first guess (pinned ones keep `from`).
  NewmarkStats solveHalfStep(const MassSpringSystem& system, const std::vector<Vec3>& base,
                             const std::vector<Vec3>& from, double h, std::vector<Vec3>& out);
  // The matrix's spring terms linearised at `at` (reach c = dt with implicit springs, else 0), the
  // matrix, and with Jacobi its preconditioner.
  void gatherTerms(const MassSpringSystem& system, const std::vector<Vec3>& at, double h, double reach);
  // The terms each particle takes part in (incidence_, CSR by particle) for the matrix and applyElastic.
  void gatherIncidence(std::size_t particles);
  // y += h c K u, the terms' elastic part; u and y 3 values per particle.
  void applyElastic(const double* u, double* y) const;
  NewmarkStats conjugateGradients(const MassSpringSystem& system, double h, double rhsNorm2, std::vector<Vec3>& out);

  NewmarkSettings settings_;
  std::vector<Vec3> forces_, start_, half_, mid_;
  std::vector<Vec3> lastChange_;  // the last step's v(n + 1/2) - v(n), and its dt, for the next first guess
  double lastDt_ = 0.0;
  std::vector<int> touched_;  // the body each particle met in the step, or -1
  std::vector<double> inverseMass_;
  std::vector<SpringTerm> terms_;
  std::vector<int> incidenceStart_, incidenceFill_;      // per particle, into incidence_
  std::vector<std::pair<int, int>> incidence_;           // (term, the particle's place among its nodes)
  struct TermParticles {
    int count = 0;
    std::array<int, 4> node{};
  };
  std::vector<TermParticles> termParticles_;  // what incidence_ was gathered for
  long incidenceVersion_ = 0;                 // counts the gatherings (the matrix keeps its slots until it changes)
  mutable std::vector<Vec3> termForces_;                 // applyElastic's scratch, one per term
  std::vector<Vec3> residual_, product_, linearisedAt_, previous_;
  double shortestSpring_ = 0.0;  // rest length, or altitude, over the last gathered terms
  NewmarkMatrix matrix_;
  numerics::BlockJacobi jacobi_;
  // The multigrid hierarchy is built from one solve's matrix and kept while it serves: the matrices
  // of later solves differ little (springs turn slowly from step to step). A new one is built when
  // the half step h changes by more than a quarter (the stiffness terms scale with h^2), or when a
  // solve gains less than a quarter of the digits per iteration that the first one after the setup did.
  numerics::SmoothedAggregation multigrid_{numerics::AggregationSettings{.blockSize = 3}};  // rigid modes
  bool stale_ = true;
  double multigridH_ = 0.0;     // the half step it was built for
  double multigridRate_ = 0.0;  // its log10 residual reduction per iteration when new (0: not yet measured)
  std::size_t multigridParticles_ = 0;
  Eigen::VectorXd unknowns_, residualVector_;
  const ParticleSplit* split_ = nullptr;
  Eigen::VectorXd sharedSearch_;  // with a split: the search direction with every process's rows
  numerics::SparseCgWorkspace workspace_;
};

}  // namespace msim::solids
