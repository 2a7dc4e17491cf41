#pragma once
// One rigid body: shape, mass properties and state. Position is the world centre of mass, so the
// generalized velocity V = (v, omega) and generalized force F = (f, torque about the centre of
// mass) are the 6-vectors of Narain 2011 eq. 5.21-5.23, and an impulse dt*F changes V by
// M^{-1} dt F (the update below eq. 5.23).
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "msim/rigid/mass_properties.hpp"
#include "msim/rigid/shapes.hpp"

namespace msim::rigid {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// Contact material; a pair combines friction as sqrt(mu_a mu_b) and restitution as max(e_a, e_b)
// unless World::setPairFriction overrides the pair.
struct Material {
  double friction = 0.5;
  double restitution = 0.0;
};

class RigidBody {
 public:
  // Mass properties from the shape and density (InputError if density <= 0 or bad shape).
  static RigidBody fromDensity(Shape shape, double density);
  // Given total mass, the inertia scaled from the shape at uniform density (InputError if <= 0).
  static RigidBody fromMass(Shape shape, double mass);
  // Immovable body (infinite mass): walls, ground, kinematic obstacles.
  static RigidBody makeStatic(Shape shape);

  const Shape& shape() const { return shape_; }
  bool isStatic() const { return inverseMass_ == 0.0; }
  double mass() const { return mass_; }
  double inverseMass() const { return inverseMass_; }
  const Eigen::Matrix3d& bodyInertia() const { return bodyInertia_; }
  const Eigen::Matrix3d& bodyInverseInertia() const { return bodyInverseInertia_; }
  Eigen::Matrix3d rotation() const { return orientation.toRotationMatrix(); }
  // World inertia R I R^T and its inverse R I^{-1} R^T (zero for static bodies).
  Eigen::Matrix3d worldInertia() const;
  Eigen::Matrix3d worldInverseInertia() const;
  // 6x6 block-diagonal generalized mass M = diag(m 1, I_world) and its inverse.
  Mat6 massMatrix() const;
  Mat6 inverseMassMatrix() const;

  Vec6 generalizedVelocity() const;
  void setGeneralizedVelocity(const Vec6& V);
  // V += M^{-1} J for a generalized impulse J = (linear impulse, angular impulse about the
  // centre of mass); no effect on static bodies.
  void applyImpulse(const Vec6& J);
  // Impulse `impulse` applied at world point `point`: J = (p, (point - x) x p).
  void applyImpulseAt(const Vec3& point, const Vec3& impulse);
  Vec3 velocityAt(const Vec3& point) const {
    return velocity + angularVelocity.cross(point - position);
  }
  // Body-frame point -> world.
  Vec3 toWorld(const Vec3& local) const { return position + orientation * local; }

  double kineticEnergy() const;  // (1/2) V^T M V
  Vec3 linearMomentum() const { return mass_ * velocity; }
  Vec3 angularMomentum() const { return worldInertia() * angularVelocity; }  // about the COM

  // State (world frame), public like a plain struct: the solver and couplings write it directly.
  Vec3 position = Vec3::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  Vec3 velocity = Vec3::Zero();
  Vec3 angularVelocity = Vec3::Zero();
  Vec3 force = Vec3::Zero();   // external force, cleared after each step
  Vec3 torque = Vec3::Zero();  // external torque about the COM, cleared after each step
  Material material;

 private:
  RigidBody(Shape shape, const MassProperties& props, bool fixed);
  Shape shape_;
  double mass_ = 0.0;
  double inverseMass_ = 0.0;
  Eigen::Matrix3d bodyInertia_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d bodyInverseInertia_ = Eigen::Matrix3d::Zero();
};

}  // namespace msim::rigid
