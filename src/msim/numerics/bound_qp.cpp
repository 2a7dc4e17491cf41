#include "msim/numerics/bound_qp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace msim::numerics {

SparseQpOperator::SparseQpOperator(const Eigen::SparseMatrix<double>& A) : A_(A) {
  if (A.rows() != A.cols())
    throw std::invalid_argument("SparseQpOperator: matrix is " + std::to_string(A.rows()) + "x" +
                                std::to_string(A.cols()) + ", not square");
  diagonal_ = A.diagonal();
  // Column sums of |A| equal its row sums for a symmetric A; ||A||_2 <= ||A||_1 (Gershgorin).
  for (Eigen::Index c = 0; c < A.outerSize(); ++c) {
    double sum = 0.0;
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, c); it; ++it) sum += std::abs(it.value());
    normBound_ = std::max(normBound_, sum);
  }
}

void SparseQpOperator::apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const { y.noalias() = A_ * x; }

void BoundQpSolver::setFace(const Eigen::VectorXd& p, QpFacePreconditioner* preconditioner) {
  for (Eigen::Index i = 0; i < p.size(); ++i) free_[i] = p[i] > 0.0 ? 1 : 0;
  if (preconditioner) preconditioner->setFace(free_);
}

void BoundQpSolver::precondition(QpFacePreconditioner* preconditioner) {
  if (preconditioner) {
    preconditioner->apply(g_, z_);
    return;
  }
  // For a diagonal M, M_FF^{-1} = (M^{-1})_FF: Jacobi needs no refactoring when the face changes.
  for (Eigen::Index i = 0; i < g_.size(); ++i)
    z_[i] = free_[i] ? (jacobi_ ? g_[i] * invDiagonal_[i] : g_[i]) : 0.0;
}

BoundQpResult BoundQpSolver::solve(const QpOperator& A, const Eigen::VectorXd& b, Eigen::VectorXd& p,
                                   const BoundQpSettings& settings, QpFacePreconditioner* preconditioner) {
  const Eigen::Index n = A.size();
  if (b.size() != n || p.size() != n)
    throw std::invalid_argument("BoundQpSolver: operator has size " + std::to_string(n) + ", b " +
                                std::to_string(b.size()) + ", p " + std::to_string(p.size()));
  if (!(settings.tolerance >= 0.0) || !(settings.gamma > 0.0) || settings.maxIterations < 0 ||
      !(settings.alphaBar >= 0.0) || !(settings.alphaBarFactor > 0.0 && settings.alphaBarFactor <= 2.0))
    throw std::invalid_argument("BoundQpSolver: invalid settings (need tolerance >= 0, gamma > 0, "
                                "maxIterations >= 0, alphaBar >= 0, 0 < alphaBarFactor <= 2)");

  BoundQpResult result;
  const double bNorm = b.norm();
  if (bNorm == 0.0) {
    // A is positive definite, so f(p) >= 0 = f(0) on p >= 0: the solution is p = 0 exactly.
    p.setZero();
    result.converged = true;
    result.activeCount = static_cast<int>(n);
    return result;
  }
  const double alphaBar = settings.alphaBar > 0.0 ? settings.alphaBar : settings.alphaBarFactor / A.normUpperBound();
  if (!(alphaBar > 0.0) || !std::isfinite(alphaBar))
    throw std::invalid_argument("BoundQpSolver: expansion step length is not a positive number");
  const double threshold = settings.tolerance * bNorm;
  const double gamma2 = settings.gamma * settings.gamma;

  // Size the work vectors once per problem size; the iteration below does not allocate.
  free_.resize(static_cast<std::size_t>(n));
  g_.resize(n);
  z_.resize(n);
  d_.resize(n);
  Ad_.resize(n);
  jacobi_ = !preconditioner && settings.preconditioning == BoundQpPreconditioning::Jacobi;
  if (jacobi_) {
    A.diagonal(invDiagonal_);
    if (invDiagonal_.size() != n || !(invDiagonal_.minCoeff() > 0.0))
      throw std::invalid_argument("BoundQpSolver: Jacobi preconditioning needs a positive diagonal of size n");
    invDiagonal_ = invDiagonal_.cwiseInverse();
  }

  p = p.cwiseMax(0.0);  // warm start projected onto the feasible set
  auto updateGradient = [&] {
    A.apply(p, g_);
    g_ -= b;
    ++result.operatorApplications;
  };
  // After a step that may change the free set, restart CG from the new preconditioned free
  // gradient (the face changed, so the old conjugate directions are no longer A_FF-conjugate).
  auto restart = [&] {
    setFace(p, preconditioner);
    precondition(preconditioner);
    d_ = z_;
  };
  updateGradient();
  restart();

  while (true) {
    // Free gradient phi (g on F), chopped gradient beta (min(g, 0) off F), and the reduced free
    // gradient phi~_i = min(p_i / alphaBar, phi_i), whose product with phi measures how far a
    // fixed-length projected step along phi can go before it is cut by the bound.
    double phi2 = 0.0, beta2 = 0.0, reducedPhi = 0.0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double gi = g_[i];
      if (free_[i]) {
        phi2 += gi * gi;
        reducedPhi += std::min(p[i] / alphaBar, gi) * gi;
      } else if (gi < 0.0) {
        beta2 += gi * gi;
      }
    }
    result.projectedGradientNorm = std::sqrt(phi2 + beta2);
    if (result.projectedGradientNorm <= threshold) {
      result.converged = true;
      break;
    }
    if (result.iterations >= settings.maxIterations) break;
    ++result.iterations;

    if (beta2 <= gamma2 * reducedPhi) {
      // Proportional iterate: a CG step on the face, unless it would leave p >= 0.
      A.apply(d_, Ad_);
      ++result.operatorApplications;
      const double dAd = d_.dot(Ad_);
      const double alphaCg = g_.dot(d_) / dAd;  // exact line search; d is zero off the face
      double alphaFeasible = std::numeric_limits<double>::infinity();
      for (Eigen::Index i = 0; i < n; ++i)
        if (d_[i] > 0.0) alphaFeasible = std::min(alphaFeasible, p[i] / d_[i]);

      if (alphaCg <= alphaFeasible) {
        // The clamp only removes round-off when alphaCg is within an ulp of alphaFeasible.
        for (Eigen::Index i = 0; i < n; ++i) p[i] = std::max(p[i] - alphaCg * d_[i], 0.0);
        g_ -= alphaCg * Ad_;
        precondition(preconditioner);
        // Next direction A-conjugate to the previous one (Dostál & Schöberl 2005, CG step).
        const double conj = z_.dot(Ad_) / dAd;
        d_ = z_ - conj * d_;
        ++result.cgSteps;
      } else {
        // Expansion: the largest feasible step along d, then a fixed-length step alphaBar along
        // the free gradient at that point, projected onto p >= 0. With alphaBar <= 2/||A|| this
        // decreases f and may add several constraints at once (unlike active-set CG).
        p -= alphaFeasible * d_;
        g_ -= alphaFeasible * Ad_;
        for (Eigen::Index i = 0; i < n; ++i)
          p[i] = p[i] > 0.0 ? std::max(p[i] - alphaBar * g_[i], 0.0) : 0.0;
        updateGradient();
        restart();
        ++result.expansionSteps;
      }
    } else {
      // Proportioning: the chopped gradient dominates, so the active set is wrong; an exact line
      // search along -beta releases the constraints whose multipliers are negative.
      for (Eigen::Index i = 0; i < n; ++i) d_[i] = !free_[i] && g_[i] < 0.0 ? g_[i] : 0.0;
      A.apply(d_, Ad_);
      ++result.operatorApplications;
      const double alpha = beta2 / d_.dot(Ad_);  // g^T beta = beta^T beta
      p -= alpha * d_;
      g_ -= alpha * Ad_;
      restart();
      ++result.proportioningSteps;
    }
  }

  result.relativeProjectedGradient = result.projectedGradientNorm / bNorm;
  result.activeCount = static_cast<int>((p.array() == 0.0).count());
  return result;
}

}  // namespace msim::numerics
