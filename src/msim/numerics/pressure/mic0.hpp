#pragma once
// Mic0Preconditioner<D>: modified incomplete Cholesky, MIC(0), of the face-weighted Poisson
// matrix, as in Bridson & Mueller-Fischer's fluid notes (SIGGRAPH 2007 course, fig. 4.2). A = L L^T
// is approximated with L restricted to A's sparsity; the "modified" variant moves the dropped
// fill-in onto the diagonal (scaled by tau) so row sums are preserved, which removes most of the
// low-frequency error IC(0) leaves. tau = 0.97 rather than 1 and the safety factor sigma (a pivot
// below sigma * A_ii falls back to A_ii) keep the factorisation stable near solids.
// The triangular solves are sequential in the natural (x-fastest) order.
#include <vector>

#include "msim/numerics/pressure/poisson_matrix.hpp"
#include "msim/numerics/pressure/preconditioner.hpp"

namespace msim::numerics {

struct Mic0Settings {
  double tau = 0.97;    // fraction of the dropped fill-in moved onto the diagonal
  double sigma = 0.25;  // safety factor on the pivots
};

template <int D>
class Mic0Preconditioner final : public Preconditioner {
 public:
  // `matrix` must outlive the preconditioner.
  Mic0Preconditioner(const PoissonMatrix<D>& matrix, const Mic0Settings& settings = {});
  void apply(const std::vector<float>& r, std::vector<float>& z) override;

 private:
  const PoissonMatrix<D>* matrix_;
  std::vector<float> precon_;  // 1 / L_ii (0 for excluded cells)
  std::vector<float> q_;       // solution of L q = r
};

}  // namespace msim::numerics
