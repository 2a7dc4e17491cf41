#include "msim/numerics/pressure/pcg.hpp"

#include "msim/core/parallel.hpp"
#include "msim/numerics/pressure/vector_ops.hpp"

namespace msim::numerics {

template <int D>
PcgStats PcgSolver<D>::solve(const PoissonMatrix<D>& A, const FloatingRegions<D>& nullSpace, Preconditioner& M,
                             std::vector<float>& b, std::vector<float>& x, const PcgSettings& settings) {
  const std::size_t n = A.size();
  for (auto* v : {&r_, &z_, &s_, &q_})
    if (v->size() != n) v->assign(n, 0.0f);
  PcgStats stats;
  nullSpace.removeMeans(b);
  const double bNorm = maxAbs(b);
  if (bNorm == 0.0) {
    std::fill(x.begin(), x.end(), 0.0f);
    stats.converged = true;
    return stats;
  }
  const double target = settings.tolerance * bNorm;
  A.residual(b, x, r_);
  double rNorm = maxAbs(r_);
  // A warm start farther from the solution than zero (the previous step's pressure after a much
  // shorter or longer step) would cost the float precision the relative tolerance needs: start
  // from zero instead.
  if (rNorm > bNorm) {
    std::fill(x.begin(), x.end(), 0.0f);
    r_ = b;
    rNorm = bNorm;
  }
  auto finish = [&] {
    nullSpace.removeMeans(x);
    stats.relativeResidual = rNorm / bNorm;
    return stats;
  };
  if (rNorm <= target) {
    stats.converged = true;
    return finish();
  }
  M.apply(r_, z_);
  nullSpace.removeMeans(z_);
  s_ = z_;
  double rho = dot(z_, r_);
  for (int it = 1; it <= settings.maxIterations; ++it) {
    A.apply(s_, q_);
    const double sq = dot(s_, q_);
    if (!(sq > 0.0)) break;  // breakdown: the search direction left the range of A
    const float alpha = static_cast<float>(rho / sq);
    parallelFor(0, n, [&](std::size_t i) {
      x[i] += alpha * s_[i];
      r_[i] -= alpha * q_[i];
    }, 4096);
    stats.iterations = it;
    rNorm = maxAbs(r_);
    if (rNorm <= target) {
      stats.converged = true;
      return finish();
    }
    M.apply(r_, z_);
    nullSpace.removeMeans(z_);
    const double rhoNew = dot(z_, r_);
    const float beta = static_cast<float>(rhoNew / rho);
    rho = rhoNew;
    parallelFor(0, n, [&](std::size_t i) { s_[i] = z_[i] + beta * s_[i]; }, 4096);
  }
  return finish();
}

template class PcgSolver<2>;
template class PcgSolver<3>;

}  // namespace msim::numerics
