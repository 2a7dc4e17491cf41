#pragma once
// Time integration of one body, split around the velocity-level constraint solve:
//   integrateVelocity: v += dt (g + f/m), omega += dt I_w^{-1} torque   (symplectic Euler kick)
//   ... contacts and joints change (v, omega) ...
//   integratePosition: x += dt v; orientation by an implicit-midpoint Lie-group step that holds
//                      the world angular momentum L = I_w omega fixed (the gyroscopic term).
// Why the second: the explicit gyroscopic update omega += -dt I^{-1}(omega x I omega) gains energy
// and Catto's (2015) one-Newton-step implicit update loses |L| at O(dt^2) per step. Holding L
// while rotating, with the rotation taken at the midpoint orientation, conserves L exactly for a
// torque-free body and, being time-symmetric, keeps the kinetic energy bounded.
#include "msim/rigid/rigid_body.hpp"

namespace msim::rigid {

void integrateVelocity(RigidBody& body, const Vec3& gravity, double dt);
void integratePosition(RigidBody& body, double dt);

}  // namespace msim::rigid
