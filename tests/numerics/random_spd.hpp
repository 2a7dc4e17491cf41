#pragma once
// Random test problems for the QP solver tests: dense symmetric positive definite matrices
// R R^T / n + shift I with R standard normal, so the eigenvalues are at least `shift`, and vectors
// of uniform entries.
#include <Eigen/Dense>

#include "msim/core/rng.hpp"

namespace msim::numerics {

inline Eigen::MatrixXd randomSpd(int n, Rng& rng, double shift) {
  Eigen::MatrixXd R(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) R(i, j) = rng.normal();
  return R * R.transpose() / n + shift * Eigen::MatrixXd::Identity(n, n);
}

// n entries uniform in [lo, hi).
inline Eigen::VectorXd randomVector(Eigen::Index n, Rng& rng, double lo, double hi) {
  Eigen::VectorXd v(n);
  for (double& x : v) x = rng.uniform(lo, hi);
  return v;
}

}  // namespace msim::numerics
