#pragma once
// Random dense symmetric positive definite test matrices for the QP solver tests:
// R R^T / n + shift I with R standard normal, so the eigenvalues are at least `shift`.
#include <Eigen/Dense>

#include "msim/core/rng.hpp"

namespace msim::numerics {

inline Eigen::MatrixXd randomSpd(int n, Rng& rng, double shift) {
  Eigen::MatrixXd R(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) R(i, j) = rng.normal();
  return R * R.transpose() / n + shift * Eigen::MatrixXd::Identity(n, n);
}

}  // namespace msim::numerics
