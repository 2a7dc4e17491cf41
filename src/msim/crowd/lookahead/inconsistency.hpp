#pragma once
// The inconsistency metric of a crowd (Golas ch. 3.8, eqs. 3.6-3.9): how far agents' motion is
// from the straight lines the lookahead extrapolates. Each step gives a deviation sample per agent,
// dv = (v(n) - v(n-1)) / dt (3.6); the samples of a window (an agent and its neighbours for the
// local metric, every agent for a scene's) form the uncentred second moment C = (1/n) M^T M (3.7);
// with C = X^T Lambda^2 X (3.8) the metric is sigma = |lambda_1| + |lambda_2| (3.9), the sum of
// the square roots of C's eigenvalues [m/s^2]. The caption of Fig. 3.7 speaks of the sum of the
// eigenvalues instead (the trace of C, [m^2/s^4]); both are offered, the equations' the default.
// Constant velocities give 0; the metric does not change when the samples are rotated.
#include <Eigen/Core>

namespace msim::crowd::lookahead {

enum class MetricMode { SqrtEigenvalueSum, Trace };

// Weighted deviation samples summed: C = sum w dv dv^T / sum w. Moments of different agents add.
class DeviationMoment {
 public:
  void add(const Eigen::Vector2d& deviation, double weight = 1.0) {
    sum_ += weight * deviation * deviation.transpose();
    weight_ += weight;
  }
  // Older samples weigh less: every weight so far times `factor`.
  void scale(double factor) {
    sum_ *= factor;
    weight_ *= factor;
  }
  void add(const DeviationMoment& other) {
    sum_ += other.sum_;
    weight_ += other.weight_;
  }
  // sigma of the samples added (0 without any).
  double sigma(MetricMode mode = MetricMode::SqrtEigenvalueSum) const;
  // C's eigenvectors as columns, the principal directions of the deviations (Fig. 3.7).
  Eigen::Matrix2d directions() const;

 private:
  Eigen::Matrix2d sum_ = Eigen::Matrix2d::Zero();
  double weight_ = 0.0;
};

}  // namespace msim::crowd::lookahead
