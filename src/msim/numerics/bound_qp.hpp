#pragma once
// Bound-constrained convex QP
//
//   minimise  f(p) = 1/2 p^T A p - b^T p   subject to  p >= 0,   A symmetric positive definite,
//
// which is the LCP  p >= 0,  A p - b >= 0,  p^T (A p - b) = 0  of Narain (2011) eqs. 4.15-4.19
// (unilateral incompressibility of crowds, ch. 4.4; the same structure appears for granular
// media, ch. 5). Solved by MPRGP, Modified Proportioning with Reduced Gradient Projections
// (Dostál & Schöberl, Comput. Optim. Appl. 30(1):23-43, 2005), as Narain ch. 4.4 recommends:
// conjugate-gradient steps on the current free set, expansion steps of fixed length alpha_bar
// along the free gradient followed by projection onto p >= 0, and proportioning steps that
// release constraints when the chopped gradient dominates. A is only ever applied (matrix-free),
// so the crowd and granular modules can pass their own Poisson-like stencils.
// See docs/bound_qp.md for parameters and validation numbers.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace msim::numerics {

// A symmetric positive definite operator, given by its action.
class QpOperator {
 public:
  virtual ~QpOperator() = default;
  virtual Eigen::Index size() const = 0;
  // y = A x. x and y have size() entries and are distinct objects.
  virtual void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const = 0;
  // d = diag(A) (used by Jacobi preconditioning; must be positive).
  virtual void diagonal(Eigen::VectorXd& d) const = 0;
  // An upper bound of ||A||_2, e.g. the Gershgorin bound max_i sum_j |a_ij|. The expansion step
  // length must lie in (0, 2/||A||] for the cost to decrease (Dostál & Schöberl 2005).
  virtual double normUpperBound() const = 0;
};

// Diagonal entries of samples that couple to nothing (no stencil weight, decoupled(i) true): any
// positive value keeps A definite, and their bounds or right-hand sides hold them at 0. They take
// the largest real diagonal (1 if there is none): MPRGP's expansion steps have the fixed length
// 1.9 / ||A||, so a stand-in far above the real diagonals shortens them as many times (a
// stand-in of 1, over a hundred times the granular friction diagonals, made flowing sand's
// friction solves take a thousand steps instead of about ten). Returns that value. Parallel.
template <typename Decoupled>
double setDecoupledDiagonals(std::span<double> diagonal, const Decoupled& decoupled);

// Adapter for an assembled symmetric matrix. Keeps a reference: the matrix must outlive it.
class SparseQpOperator final : public QpOperator {
 public:
  // Throws std::invalid_argument unless A is square.
  explicit SparseQpOperator(const Eigen::SparseMatrix<double>& A);
  Eigen::Index size() const override { return A_.rows(); }
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override;
  void diagonal(Eigen::VectorXd& d) const override { d = diagonal_; }
  double normUpperBound() const override { return normBound_; }

 private:
  const Eigen::SparseMatrix<double>& A_;
  Eigen::VectorXd diagonal_;
  double normBound_ = 0.0;  // max absolute row sum (Gershgorin)
};

// Preconditioning "in face" (Dostál, Optimal Quadratic Programming Algorithms, Springer 2009):
// the CG steps on the free set F use z_F = M_FF^{-1} g_F with M_FF a preconditioner of the
// reduced matrix A_FF, and z = 0 on the active set. The solver announces every new face before
// applying; implementations that factor A_FF (e.g. MIC(0) of the free cells) refactor there.
class QpFacePreconditioner {
 public:
  virtual ~QpFacePreconditioner() = default;
  // free[i] != 0 exactly where p_i > 0; stays valid until the next setFace() call.
  virtual void setFace(const std::vector<std::uint8_t>& free) = 0;
  // z_F = M_FF^{-1} g_F, z = 0 off the face. g and z are distinct, of size n.
  virtual void apply(const Eigen::VectorXd& g, Eigen::VectorXd& z) = 0;
};

// Preconditioner used when solve() is given no QpFacePreconditioner.
enum class BoundQpPreconditioning { None, Jacobi };

struct BoundQpSettings {
  double tolerance = 1e-8;   // stop when ||g^P(p)||_2 <= tolerance * ||b||_2
  int maxIterations = 10000;  // CG + expansion + proportioning steps
  // Proportioning parameter Gamma > 0: a proportioning step is taken when
  // ||beta||^2 > Gamma^2 phi~^T phi (Dostál & Schöberl 2005); phi~ is the reduced free gradient.
  double gamma = 1.0;
  // Expansion step length; 0 means alphaBarFactor / A.normUpperBound(). Must be in (0, 2/||A||].
  double alphaBar = 0.0;
  double alphaBarFactor = 1.9;
  BoundQpPreconditioning preconditioning = BoundQpPreconditioning::Jacobi;
};

struct BoundQpResult {
  int iterations = 0;  // = cgSteps + expansionSteps + proportioningSteps
  int cgSteps = 0;
  int expansionSteps = 0;
  int proportioningSteps = 0;
  int operatorApplications = 0;         // products with A, including the initial gradient
  double projectedGradientNorm = 0.0;   // ||g^P(p)||_2 at exit
  double relativeProjectedGradient = 0.0;  // projectedGradientNorm / ||b||_2 (0 when b = 0)
  int activeCount = 0;                  // entries at a bound at exit (p_i = 0 for p >= 0)
  bool converged = false;
};

class BoundQpSolver {
 public:
  // Minimises 1/2 p^T A p - b^T p over p >= 0, warm-started from p (first projected onto p >= 0).
  // The projected gradient g^P (Dostál & Schöberl 2005) is g_i on the free set and
  // min(g_i, 0) on the active set, g = A p - b; it vanishes exactly at the KKT point.
  // Throws std::invalid_argument for mismatched sizes or invalid settings. Work vectors are kept
  // between solves, so repeated solves of one size do not allocate.
  BoundQpResult solve(const QpOperator& A, const Eigen::VectorXd& b, Eigen::VectorXd& p,
                      const BoundQpSettings& settings = {}, QpFacePreconditioner* preconditioner = nullptr);

  // The same over the box lower <= p <= upper (entries may be -inf / +inf; lower <= upper), the
  // form of the linearised friction bounds -s_max <= s_ij <= s_max of Narain (2011) eq. 5.15:
  // MPRGP for box constraints (Dostál 2009, ch. 8; Kružík et al. 2020). The free set is
  // lower < p < upper; the chopped gradient is min(g, 0) at a lower and max(g, 0) at an upper
  // bound; steps are cut at either bound and expansions project onto the box. The face
  // preconditioner sees free[i] != 0 exactly where p_i is strictly inside its bounds. When b = 0
  // the tolerance is taken relative to the projected gradient at the projected warm start.
  // std::invalid_argument also for bound vectors of another size, NaN bounds or lower > upper.
  BoundQpResult solve(const QpOperator& A, const Eigen::VectorXd& b, const Eigen::VectorXd& lower,
                      const Eigen::VectorXd& upper, Eigen::VectorXd& p, const BoundQpSettings& settings = {},
                      QpFacePreconditioner* preconditioner = nullptr);

 private:
  // lower and upper both null: p >= 0.
  BoundQpResult solveBox(const QpOperator& A, const Eigen::VectorXd& b, const Eigen::VectorXd* lower,
                         const Eigen::VectorXd* upper, Eigen::VectorXd& p, const BoundQpSettings& settings,
                         QpFacePreconditioner* preconditioner);
  void setFace(const Eigen::VectorXd& p, QpFacePreconditioner& preconditioner);  // free_ from p
  double dot(const Eigen::VectorXd& x, const Eigen::VectorXd& y);  // blocked, deterministic

  bool boxed_ = false;              // the current solve has box bounds (else p >= 0)
  const double* lower_ = nullptr;  // bounds of the current solve (zeros_, infinities_ for p >= 0)
  const double* upper_ = nullptr;
  Eigen::VectorXd zeros_, infinities_;
  std::vector<std::uint8_t> free_;
  Eigen::VectorXd g_, z_, d_, Ad_, invDiagonal_;
  std::vector<double> partial_;  // per-block partial sums of the vector loops
};

template <typename Decoupled>
double setDecoupledDiagonals(std::span<double> diagonal, const Decoupled& decoupled) {
  const double largest = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, diagonal.size(), 4096), 0.0,
      [&](const tbb::blocked_range<std::size_t>& r, double m) {
        for (std::size_t i = r.begin(); i != r.end(); ++i)
          if (!decoupled(i)) m = std::max(m, diagonal[i]);
        return m;
      },
      [](double a, double b) { return std::max(a, b); });
  const double fill = largest > 0.0 ? largest : 1.0;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, diagonal.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i)
      if (decoupled(i)) diagonal[i] = fill;
  });
  return fill;
}

}  // namespace msim::numerics
