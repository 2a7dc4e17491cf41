#pragma once
// Preconditioned conjugate gradients on a symmetric positive definite system given by its product
// (a callable apply(x, y): y = A x, e.g. parallelMultiply with an assembled matrix, or a product
// applied term by term) with any preconditioner that offers apply(r, z) (block_jacobi.hpp,
// smoothed_aggregation.hpp). Dot products run on all cores; the work vectors live in a workspace so
// that repeated solves allocate nothing once it has grown.
#include <cmath>

#include <Eigen/Sparse>

#include "msim/numerics/sparse_ops.hpp"

namespace msim::numerics {

struct SparseCgStats {
  int iterations = 0;
  bool converged = false;
  double residualNorm2 = 0.0;
  double initialResidualNorm2 = 0.0;
  // log10 of the residual's reduction per iteration (negative; 0 without iterations): how well the
  // preconditioner serves the matrix, whatever the start.
  double digitsPerIteration() const {
    return iterations > 0 && initialResidualNorm2 > 0.0 && residualNorm2 > 0.0
               ? 0.5 * std::log10(residualNorm2 / initialResidualNorm2) / iterations
               : 0.0;
  }
};

struct SparseCgWorkspace {
  Eigen::VectorXd z, search, product;
};

// A dot product over all of the unknowns is the one computed here.
struct WholeDot {
  double operator()(double local) const { return local; }
};

// Solves A x = b from x and its residual r = b - A x (both updated); stops once |r|^2 <= target2
// or after maxIterations. A solve whose rows are split among processes (solids/newmark.cpp) keeps
// the other processes' rows of r, and so of z and of the search direction, at 0 and passes
// `reduce`, which turns the dot products over its own rows into the whole ones.
template <typename Product, typename Preconditioner, typename Reduce = WholeDot>
SparseCgStats preconditionedCg(const Product& multiply, const Preconditioner& preconditioner, Eigen::VectorXd& x,
                               Eigen::VectorXd& r, double target2, int maxIterations, SparseCgWorkspace& w,
                               const Reduce& reduce = {}) {
  SparseCgStats stats;
  stats.residualNorm2 = stats.initialResidualNorm2 = reduce(parallelDot(r, r));
  if (stats.residualNorm2 <= target2) {
    stats.converged = true;
    return stats;
  }
  preconditioner.apply(r, w.z);
  w.search = w.z;
  double rz = reduce(parallelDot(r, w.z));
  while (stats.iterations < maxIterations) {
    multiply(w.search, w.product);
    const double curvature = reduce(parallelDot(w.search, w.product));
    if (!(curvature > 0.0)) break;
    ++stats.iterations;
    stats.residualNorm2 = reduce(parallelStep(rz / curvature, w.search, w.product, x, r));
    if (stats.residualNorm2 <= target2) break;
    preconditioner.apply(r, w.z);
    const double rzNext = reduce(parallelDot(r, w.z));
    parallelDirection(w.z, rzNext / rz, w.search);
    rz = rzNext;
  }
  stats.converged = stats.residualNorm2 <= target2;
  return stats;
}

}  // namespace msim::numerics
