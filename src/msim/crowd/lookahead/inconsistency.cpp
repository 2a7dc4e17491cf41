#include "msim/crowd/lookahead/inconsistency.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace msim::crowd::lookahead {

double DeviationMoment::sigma(MetricMode mode) const {
  if (!(weight_ > 0.0)) return 0.0;
  const Eigen::Matrix2d c = sum_ / weight_;
  if (mode == MetricMode::Trace) return c.trace();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(c, Eigen::EigenvaluesOnly);
  // C is positive semi-definite; rounding may leave an eigenvalue a hair below 0.
  return std::sqrt(std::max(0.0, eigen.eigenvalues()[0])) + std::sqrt(std::max(0.0, eigen.eigenvalues()[1]));
}

Eigen::Matrix2d DeviationMoment::directions() const {
  if (!(weight_ > 0.0)) return Eigen::Matrix2d::Identity();
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(sum_ / weight_).eigenvectors();
}

}  // namespace msim::crowd::lookahead
