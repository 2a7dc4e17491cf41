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
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/solids/body_contact.hpp"
#include "msim/solids/mass_spring.hpp"
#include "msim/solids/self_repulsion.hpp"

namespace msim::solids {

struct NewmarkSettings {
  bool implicitSprings = false;  // ch. 5.5
  bool tensionAcross = true;     // with implicit springs: a stretched spring's T / L across it too
  int newtonIterations = 1;      // most linearisations per half step with implicit springs (the seed: 1)
  double newtonTolerance = 1e-3;  // stop once an iteration moves no particle's x_k by this of the shortest spring
  double cgTolerance = 1e-6;     // relative residual of each solve (the seed's Table 6.1: 1e-3)
  int cgMaxIterations = 1000;
};

struct NewmarkStats {
  int iterations = 0;        // CG iterations of the step's two solves
  bool converged = true;     // both reached the tolerance
  int contacts = 0;          // particles that met a body
  int repulsions = 0;        // self-repulsion pairs closer than the thickness (step B.2)
  int linearisations = 0;    // solves of the step's two half steps (Newton iterations)
};

class NewmarkStepper {
 public:
  explicit NewmarkStepper(const NewmarkSettings& settings = {}) : settings_(settings) {}
  // Advances the system by dt, against `bodies` and with `repulsion` when given;
  // std::invalid_argument for dt <= 0.
  NewmarkStats step(MassSpringSystem& system, double dt, const BodyContact* bodies = nullptr,
                    const SelfRepulsion* repulsion = nullptr);
  const NewmarkSettings& settings() const { return settings_; }

 private:
  // Backward Euler over h from velocity `from`, the elasticity taken where the positions `base`
  // move to with the answer (newmark.cpp), into `out`.
  NewmarkStats solveHalfStep(const MassSpringSystem& system, const std::vector<Vec3>& base,
                             const std::vector<Vec3>& from, double h, std::vector<Vec3>& out);
  // The matrix's spring terms linearised at `at` (reach c = dt with implicit springs, else 0), and
  // the inverse of its diagonal.
  void gatherTerms(const MassSpringSystem& system, const std::vector<Vec3>& at, double h, double reach);
  void applyTerms(const std::vector<Vec3>& u, std::vector<Vec3>& y, bool elasticOnly) const;
  NewmarkStats conjugateGradients(const MassSpringSystem& system, double rhsNorm2, std::vector<Vec3>& out);

  NewmarkSettings settings_;
  std::vector<Vec3> forces_, start_, half_, mid_;
  std::vector<int> touched_;  // the body each particle met in the step, or -1
  std::vector<double> inverseMass_;
  // A term of the step's matrix: with r = sum_i w_i v_i, c (r . d) d + c' (r - (r . d) d) on each
  // node i, weighted w_i.
  struct Term {
    std::array<int, 4> node{};
    std::array<double, 4> weight{};
    int count = 0;
    Vec3 direction = Vec3::Zero();
    double coefficient = 0.0;  // h (b + c k / l0) along d
    double stiffness = 0.0;    // its elastic part, h c k / l0
    double sideways = 0.0;     // h c T / L across d
  };
  std::vector<Term> terms_;
  std::vector<Vec3> inverseDiagonal_, residual_, product_, search_, precond_, linearisedAt_, previous_;
  double shortestSpring_ = 0.0;  // rest length, or altitude, over the last gathered terms
};

}  // namespace msim::solids
