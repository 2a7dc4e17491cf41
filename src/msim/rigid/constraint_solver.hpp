#pragma once
// Sequential-impulse solver (Catto, "Iterative Dynamics with Temporal Coherence", GDC 2005;
// Box2D): Gauss-Seidel over the constraint rows, clamping accumulated impulses (normal >= 0,
// friction inside the Coulomb disc |lambda_t| <= mu lambda_n). Rows are visited in input order,
// so the result is deterministic. Works on velocities only; positions are corrected by a
// Baumgarte bias that pushes only penetration beyond `slop`.
#include <vector>

#include "msim/rigid/collision.hpp"
#include "msim/rigid/hinge.hpp"

namespace msim::rigid {

struct SolverSettings {
  int iterations = 20;
  double baumgarte = 0.2;              // fraction of the position error removed per step
  double slop = 1e-5;                  // allowed penetration [m] before Baumgarte acts
  double restitutionThreshold = 0.5;   // approach speed [m/s] below which contacts don't bounce
};

void solveConstraints(std::vector<RigidBody>& bodies, const std::vector<Contact>& contacts,
                      const std::vector<Hinge>& hinges, const SolverSettings& settings, double dt);

}  // namespace msim::rigid
