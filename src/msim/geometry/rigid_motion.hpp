#pragma once
// A rigid motion in 3D that scenes script (pinned vertices, moving bodies): a translation at
// `velocity` and a turn at `angularVelocity` (world frame) about `center`, which moves with it:
//   x(t) = c + v t + R(omega t) (x(0) - c).
#include <Eigen/Geometry>

#include "msim/core/vec.hpp"

namespace msim::geometry {

struct RigidMotion {
  Vec3 velocity = Vec3::Zero();         // [m/s]
  Vec3 angularVelocity = Vec3::Zero();  // [rad/s]
  Vec3 center = Vec3::Zero();           // [m] at t = 0

  bool moves() const { return velocity.norm() > 0.0 || angularVelocity.norm() > 0.0; }
  bool turns() const { return angularVelocity.norm() > 0.0; }
  Eigen::Matrix3d rotation(double t) const {
    const double angle = angularVelocity.norm() * t;
    return angle > 0.0 ? Eigen::AngleAxisd(angle, angularVelocity.normalized()).toRotationMatrix()
                       : Eigen::Matrix3d::Identity();
  }
  Vec3 centerAt(double t) const { return center + velocity * t; }
  // Where the point that stood at x0 at t = 0 stands at t.
  Vec3 apply(const Vec3& x0, double t) const { return centerAt(t) + rotation(t) * (x0 - center); }
  // Where the point that stands at x at t stood at t = 0.
  Vec3 inverse(const Vec3& x, double t) const { return center + rotation(t).transpose() * (x - centerAt(t)); }
  // The velocity of the moving frame at x (a point standing at x at time t).
  Vec3 velocityAt(const Vec3& x, double t) const { return velocity + angularVelocity.cross(x - centerAt(t)); }
};

}  // namespace msim::geometry
