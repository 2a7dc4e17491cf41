#include "msim/crowd/lookahead/inconsistency.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace msim::crowd::lookahead {

double DeviationMoment::sigma(MetricMode mode) const {
  if (!(weight_ > 0.0)) return 0.0;
  const Eigen::Matrix2d c = sum_ / weight_;
  if (mode == MetricMode::Trace) return c.trace();
  // sqrt(l1) + sqrt(l2) of the symmetric positive semi-definite C without its eigenvalues:
  // (sqrt(l1) + sqrt(l2))^2 = l1 + l2 + 2 sqrt(l1 l2) = tr C + 2 sqrt(det C). Rounding may leave
  // det C a hair below 0.
  return std::sqrt(std::max(0.0, c.trace() + 2.0 * std::sqrt(std::max(0.0, c.determinant()))));
}

Eigen::Matrix2d DeviationMoment::directions() const {
  if (!(weight_ > 0.0)) return Eigen::Matrix2d::Identity();
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(sum_ / weight_).eigenvectors();
}

}  // namespace msim::crowd::lookahead
