#pragma once
// PcgSolver<D>: preconditioned conjugate gradients for the face-weighted pressure matrix, in the
// form of Bridson's fluid notes (fig. 4.1): convergence is declared when the max-norm of the
// residual falls below tolerance * max-norm of the right-hand side. For the projection the
// residual is exactly the remaining (face-weighted) divergence, so the tolerance bounds the
// divergence left in the velocity. Work vectors are kept across solves.
#include <vector>

#include "msim/numerics/pressure/floating_regions.hpp"
#include "msim/numerics/pressure/poisson_matrix.hpp"
#include "msim/numerics/pressure/preconditioner.hpp"

namespace msim::numerics {

struct PcgSettings {
  double tolerance = 1e-5;  // relative max-norm residual
  int maxIterations = 500;
};

struct PcgStats {
  int iterations = 0;
  double relativeResidual = 0.0;  // |b - A x|_inf / |b|_inf at exit (0 when b = 0)
  bool converged = false;
};

template <int D>
class PcgSolver {
 public:
  // Solves A x = b starting from x (warm start; from zero when x's residual exceeds b). b must
  // vanish on excluded cells; its mean is removed on each floating region (the compatibility
  // condition), and so is x's at exit.
  PcgStats solve(const PoissonMatrix<D>& A, const FloatingRegions<D>& nullSpace, Preconditioner& M,
                 std::vector<float>& b, std::vector<float>& x, const PcgSettings& settings);

 private:
  std::vector<float> r_, z_, s_, q_;
};

}  // namespace msim::numerics
