#include "msim/rigid/rigid_body.hpp"

#include <cmath>
#include <string>

#include "msim/core/error.hpp"

namespace msim::rigid {

RigidBody::RigidBody(Shape shape, const MassProperties& props, bool fixed)
    : shape_(std::move(shape)) {
  if (fixed) return;  // infinite mass: all inverse quantities stay zero
  mass_ = props.mass;
  inverseMass_ = 1.0 / props.mass;
  bodyInertia_ = props.inertia;
  bodyInverseInertia_ = props.inertia.inverse();
  if (!bodyInverseInertia_.allFinite())
    throw InputError("rigid body: inertia tensor is singular");
}

RigidBody RigidBody::fromDensity(Shape shape, double density) {
  const MassProperties p = shapeMassProperties(shape, density);
  return RigidBody(std::move(shape), p, false);
}

RigidBody RigidBody::fromMass(Shape shape, double mass) {
  if (!(mass > 0.0) || !std::isfinite(mass))
    throw InputError("rigid body: mass must be positive and finite, got " + std::to_string(mass));
  MassProperties p = shapeMassProperties(shape, 1.0);
  const double scale = mass / p.mass;
  p.mass = mass;
  p.inertia *= scale;
  return RigidBody(std::move(shape), p, false);
}

RigidBody RigidBody::makeStatic(Shape shape) {
  shapeMassProperties(shape, 1.0);  // validates the shape
  return RigidBody(std::move(shape), MassProperties{}, true);
}

Eigen::Matrix3d RigidBody::worldInertia() const {
  const Eigen::Matrix3d R = rotation();
  return R * bodyInertia_ * R.transpose();
}

Eigen::Matrix3d RigidBody::worldInverseInertia() const {
  const Eigen::Matrix3d R = rotation();
  return R * bodyInverseInertia_ * R.transpose();
}

Mat6 RigidBody::massMatrix() const {
  Mat6 M = Mat6::Zero();
  M.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * mass_;
  M.bottomRightCorner<3, 3>() = worldInertia();
  return M;
}

Mat6 RigidBody::inverseMassMatrix() const {
  Mat6 M = Mat6::Zero();
  M.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * inverseMass_;
  M.bottomRightCorner<3, 3>() = worldInverseInertia();
  return M;
}

Vec6 RigidBody::generalizedVelocity() const {
  Vec6 V;
  V << velocity, angularVelocity;
  return V;
}

void RigidBody::setGeneralizedVelocity(const Vec6& V) {
  velocity = V.head<3>();
  angularVelocity = V.tail<3>();
}

void RigidBody::applyImpulse(const Vec6& J) {
  if (isStatic()) return;
  velocity += inverseMass_ * J.head<3>();
  angularVelocity += worldInverseInertia() * J.tail<3>();
}

void RigidBody::applyImpulseAt(const Vec3& point, const Vec3& impulse) {
  Vec6 J;
  J << impulse, (point - position).cross(impulse);
  applyImpulse(J);
}

double RigidBody::kineticEnergy() const {
  return 0.5 * mass_ * velocity.squaredNorm() +
         0.5 * angularVelocity.dot(worldInertia() * angularVelocity);
}

}  // namespace msim::rigid
