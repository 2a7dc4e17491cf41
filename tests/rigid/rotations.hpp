#pragma once
// Rotations for placing the rigid tests' bodies.
#include <Eigen/Geometry>

#include "msim/core/vec.hpp"

namespace msim::rigid::testing {

// The rotation by `angle` [rad] about `axis` (any length).
inline Eigen::Quaterniond about(double angle, const Vec3& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis.normalized()));
}

}  // namespace msim::rigid::testing
