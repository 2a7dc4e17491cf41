#include "msim/rigid/integrator.hpp"

#include <cmath>

namespace msim::rigid {
namespace {

// exp(dt [w]x) as a unit quaternion (rotation by angle |w| dt about w).
Eigen::Quaterniond rotationStep(const Vec3& w, double dt) {
  const double angle = w.norm() * dt;
  if (angle < 1e-300) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, w / w.norm()));
}

Vec3 omegaFor(const RigidBody& body, const Eigen::Quaterniond& q, const Vec3& L) {
  const Eigen::Matrix3d R = q.toRotationMatrix();
  return R * (body.bodyInverseInertia() * (R.transpose() * L));
}

}  // namespace

void integrateVelocity(RigidBody& body, const Vec3& gravity, double dt) {
  if (body.isStatic()) return;
  body.velocity += dt * (gravity + body.inverseMass() * body.force);
  body.angularVelocity += dt * (body.worldInverseInertia() * body.torque);
}

void integratePosition(RigidBody& body, double dt) {
  body.force.setZero();
  body.torque.setZero();
  if (body.isStatic()) return;
  body.position += dt * body.velocity;
  const Vec3 L = body.angularMomentum();
  if (L.squaredNorm() == 0.0) return;
  const Eigen::Quaterniond q0 = body.orientation;
  // Fixed point for the midpoint rate w = I_w(q_mid)^{-1} L, q_mid = exp(dt/2 w) q0. Contracts
  // with factor ~ dt |w|, so a handful of iterations reach round-off at usual step sizes.
  Vec3 w = body.angularVelocity;
  for (int it = 0; it < 50; ++it) {
    const Eigen::Quaterniond qMid = (rotationStep(w, 0.5 * dt) * q0).normalized();
    const Vec3 next = omegaFor(body, qMid, L);
    const double change = (next - w).norm();
    w = next;
    if (change <= 1e-15 * w.norm()) break;
  }
  body.orientation = (rotationStep(w, dt) * q0).normalized();
  body.angularVelocity = omegaFor(body, body.orientation, L);
}

}  // namespace msim::rigid
