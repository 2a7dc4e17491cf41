#include "msim/numerics/bound_qp.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include <tbb/parallel_for.h>

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

namespace {

// Vector loops of MPRGP: fixed blocks of kBlock entries, run in parallel when n >= kParallelMin.
// Reductions keep one partial per block and combine them in block order, so every sum is the same
// whatever the thread count (and whether the loop ran in parallel or not).
constexpr Eigen::Index kBlock = 4096;
constexpr Eigen::Index kParallelMin = 3 * kBlock;

Eigen::Index blockCount(Eigen::Index n) { return (n + kBlock - 1) / kBlock; }

// f(begin, end) over the blocks of [0, n).
template <typename F>
void forBlocks(Eigen::Index n, const F& f) {
  const Eigen::Index blocks = blockCount(n);
  if (n >= kParallelMin)
    tbb::parallel_for(Eigen::Index(0), blocks, [&](Eigen::Index b) { f(b * kBlock, std::min(n, (b + 1) * kBlock)); });
  else
    for (Eigen::Index b = 0; b < blocks; ++b) f(b * kBlock, std::min(n, (b + 1) * kBlock));
}

// Within a block, entry i's terms go into lane (i - begin) % kLanes, and the lanes are combined in
// lane order at the block's end: kLanes independent chains where one running sum would wait for
// each addition to finish (on problems that fit in cache, such as the crowd's friction with a few
// thousand unknowns, that wait bounds the loops: 8 lanes take about 15% off its solve), in an
// order that does not depend on the thread count.
constexpr int kLanes = 8;

// K reductions in one pass: term(i) returns entry i's K terms (and may update entry i of the
// work vectors), combined with combine(k, total, term) from init; the blocks' results are
// combined in block order.
template <int K, typename Term, typename Combine>
std::array<double, K> reduceBlocks(Eigen::Index n, std::vector<double>& partial, const std::array<double, K>& init,
                                   const Term& term, const Combine& combine) {
  const Eigen::Index blocks = blockCount(n);
  partial.resize(static_cast<std::size_t>(blocks * K));
  forBlocks(n, [&](Eigen::Index begin, Eigen::Index end) {
    std::array<std::array<double, kLanes>, K> lanes;
    for (int k = 0; k < K; ++k) lanes[k].fill(init[k]);
    const auto add = [&](Eigen::Index i, int lane) {
      const std::array<double, K> t = term(i);
      for (int k = 0; k < K; ++k) lanes[k][lane] = combine(k, lanes[k][lane], t[k]);
    };
    Eigen::Index i = begin;
    for (; i + kLanes <= end; i += kLanes)
      for (int lane = 0; lane < kLanes; ++lane) add(i + lane, lane);
    for (int lane = 0; i < end; ++i, ++lane) add(i, lane);
    for (int k = 0; k < K; ++k) {
      double acc = init[k];
      for (int lane = 0; lane < kLanes; ++lane) acc = combine(k, acc, lanes[k][lane]);
      partial[static_cast<std::size_t>((begin / kBlock) * K + k)] = acc;
    }
  });
  std::array<double, K> total = init;
  for (Eigen::Index b = 0; b < blocks; ++b)
    for (int k = 0; k < K; ++k) total[k] = combine(k, total[k], partial[static_cast<std::size_t>(b * K + k)]);
  return total;
}

constexpr auto kAdd = [](int, double a, double b) { return a + b; };

// The chopped gradient of an entry off the face: min(g, 0) at its lower bound (a negative g pushes
// it up into the box), max(g, 0) at its upper bound, 0 if both bounds coincide (it cannot move).
inline double choppedGradient(double l, double u, double pi, double gi) {
  return l == u ? 0.0 : pi <= l ? std::min(gi, 0.0) : pi >= u ? std::max(gi, 0.0) : 0.0;
}

}  // namespace

void BoundQpSolver::setFace(const Eigen::VectorXd& p, QpFacePreconditioner& preconditioner) {
  forBlocks(p.size(), [&](Eigen::Index begin, Eigen::Index end) {
    for (Eigen::Index i = begin; i < end; ++i) free_[i] = p[i] > lower_[i] && p[i] < upper_[i] ? 1 : 0;
  });
  preconditioner.setFace(free_);
}

double BoundQpSolver::dot(const Eigen::VectorXd& x, const Eigen::VectorXd& y) {
  const double* const X = x.data();
  const double* const Y = y.data();
  return reduceBlocks<1>(x.size(), partial_, {0.0}, [&](Eigen::Index i) { return std::array<double, 1>{X[i] * Y[i]}; },
                         kAdd)[0];
}

BoundQpResult BoundQpSolver::solve(const QpOperator& A, const Eigen::VectorXd& b, Eigen::VectorXd& p,
                                   const BoundQpSettings& settings, QpFacePreconditioner* preconditioner) {
  return solveBox(A, b, nullptr, nullptr, p, settings, preconditioner);
}

BoundQpResult BoundQpSolver::solve(const QpOperator& A, const Eigen::VectorXd& b, const Eigen::VectorXd& lower,
                                   const Eigen::VectorXd& upper, Eigen::VectorXd& p, const BoundQpSettings& settings,
                                   QpFacePreconditioner* preconditioner) {
  if (lower.size() != A.size() || upper.size() != A.size())
    throw std::invalid_argument("BoundQpSolver: operator has size " + std::to_string(A.size()) + ", bounds " +
                                std::to_string(lower.size()) + " and " + std::to_string(upper.size()));
  for (Eigen::Index i = 0; i < lower.size(); ++i)
    if (!(lower[i] <= upper[i]))
      throw std::invalid_argument("BoundQpSolver: bounds of entry " + std::to_string(i) + " are NaN or lower > upper");
  return solveBox(A, b, &lower, &upper, p, settings, preconditioner);
}

BoundQpResult BoundQpSolver::solveBox(const QpOperator& A, const Eigen::VectorXd& b, const Eigen::VectorXd* lower,
                                      const Eigen::VectorXd* upper, Eigen::VectorXd& p,
                                      const BoundQpSettings& settings, QpFacePreconditioner* preconditioner) {
  const Eigen::Index n = A.size();
  if (b.size() != n || p.size() != n)
    throw std::invalid_argument("BoundQpSolver: operator has size " + std::to_string(n) + ", b " +
                                std::to_string(b.size()) + ", p " + std::to_string(p.size()));
  boxed_ = lower != nullptr;
  if (!boxed_ && zeros_.size() != n) {
    zeros_.setZero(n);
    infinities_.setConstant(n, std::numeric_limits<double>::infinity());
  }
  lower_ = boxed_ ? lower->data() : zeros_.data();
  upper_ = boxed_ ? upper->data() : infinities_.data();
  if (!(settings.tolerance >= 0.0) || !(settings.gamma > 0.0) || settings.maxIterations < 0 ||
      !(settings.alphaBar >= 0.0) || !(settings.alphaBarFactor > 0.0 && settings.alphaBarFactor <= 2.0))
    throw std::invalid_argument("BoundQpSolver: invalid settings (need tolerance >= 0, gamma > 0, "
                                "maxIterations >= 0, alphaBar >= 0, 0 < alphaBarFactor <= 2)");

  BoundQpResult result;
  const double bNorm = std::sqrt(dot(b, b));
  if (bNorm == 0.0 && !boxed_) {
    // A is positive definite, so f(p) >= 0 = f(0) on p >= 0: the solution is p = 0 exactly.
    p.setZero();
    result.converged = true;
    result.activeCount = static_cast<int>(n);
    return result;
  }
  const double alphaBar = settings.alphaBar > 0.0 ? settings.alphaBar : settings.alphaBarFactor / A.normUpperBound();
  if (!(alphaBar > 0.0) || !std::isfinite(alphaBar))
    throw std::invalid_argument("BoundQpSolver: expansion step length is not a positive number");
  double threshold = settings.tolerance * bNorm;  // b = 0 (box bounds): set from the first gradient
  const double gamma2 = settings.gamma * settings.gamma;

  // Size the work vectors once per problem size; the iteration below does not allocate.
  free_.resize(static_cast<std::size_t>(n));
  g_.resize(n);
  z_.resize(n);
  d_.resize(n);
  Ad_.resize(n);
  const bool jacobi = !preconditioner && settings.preconditioning == BoundQpPreconditioning::Jacobi;
  if (jacobi) {
    A.diagonal(invDiagonal_);
    if (invDiagonal_.size() != n || !(invDiagonal_.minCoeff() > 0.0))
      throw std::invalid_argument("BoundQpSolver: Jacobi preconditioning needs a positive diagonal of size n");
    invDiagonal_ = invDiagonal_.cwiseInverse();
  }
  // The loops below go through raw pointers: the vectors do not move during the solve, and the
  // compiler then keeps the addresses in registers instead of reloading them for every entry.
  double* const P = p.data();
  double* const G = g_.data();
  double* const Z = z_.data();
  double* const Dv = d_.data();
  double* const AD = Ad_.data();
  const double* const B = b.data();
  const double* const L = lower_;
  const double* const U = upper_;
  std::uint8_t* const F = free_.data();
  const double* const J = jacobi ? invDiagonal_.data() : nullptr;
  const double invAlphaBar = 1.0 / alphaBar;
  // z_i without a face preconditioner: Jacobi (or none) on the face, 0 off it (for a diagonal M,
  // M_FF^{-1} = (M^{-1})_FF, so it needs no refactoring when the face changes).
  const auto diagonallyPreconditioned = [&](Eigen::Index i) { return F[i] ? (J ? G[i] * J[i] : G[i]) : 0.0; };
  // The step along -d at which entry i reaches the bound d moves it towards (none when d_i = 0).
  constexpr double inf = std::numeric_limits<double>::infinity();
  // Both quotients are formed and one selected (no branch, as gradientSums below).
  const auto reach = [P, L, U, Dv](Eigen::Index i) {
    const double di = Dv[i], toLower = (P[i] - L[i]) / di, toUpper = (P[i] - U[i]) / di;
    return di > 0.0 ? toLower : di < 0.0 ? toUpper : inf;
  };

  // Warm start projected onto the feasible set.
  forBlocks(n, [&](Eigen::Index begin, Eigen::Index end) {
    for (Eigen::Index i = begin; i < end; ++i) P[i] = std::clamp(P[i], L[i], U[i]);
  });
  auto updateGradient = [&] {
    A.apply(p, g_);
    forBlocks(n, [&](Eigen::Index begin, Eigen::Index end) {
      for (Eigen::Index i = begin; i < end; ++i) G[i] -= B[i];
    });
    ++result.operatorApplications;
  };
  // After a step that may change the free set, restart CG from the new preconditioned free
  // gradient (the face changed, so the old conjugate directions are no longer A_FF-conjugate).
  auto restart = [&] {
    if (preconditioner) {  // it needs the whole face before it can apply
      setFace(p, *preconditioner);
      preconditioner->apply(g_, z_);
      forBlocks(n, [&](Eigen::Index begin, Eigen::Index end) {
        for (Eigen::Index i = begin; i < end; ++i) Dv[i] = Z[i];
      });
      return;
    }
    // Diagonal (or no) preconditioning is entrywise: the face, z and d in one pass.
    forBlocks(n, [&](Eigen::Index begin, Eigen::Index end) {
      for (Eigen::Index i = begin; i < end; ++i) {
        F[i] = P[i] > L[i] && P[i] < U[i] ? 1 : 0;
        Dv[i] = Z[i] = diagonallyPreconditioned(i);
      }
    });
  };
  updateGradient();
  restart();

  // Free gradient phi (g on F), chopped gradient beta (min(g, 0) at a lower bound, max(g, 0) at
  // an upper one), and the reduced free gradient phi~_i = min((p_i - l_i) / alphaBar, phi_i)
  // (max((p_i - u_i) / alphaBar, phi_i) when phi_i < 0), whose product with phi measures how far
  // a fixed-length projected step along phi can go before it is cut by the bounds: entry i's
  // share of ||phi||^2, ||beta||^2 and phi~^T phi.
  // Both cases are computed and one is selected, without a branch per entry (free and bound
  // entries alternate unpredictably); the selected values are those of the case alone. The hot
  // closures hold the pointers by value, so that the loops keep them in registers (captured by
  // reference they were loaded again for every entry).
  auto gradientSums = [G, F, P, L, U, invAlphaBar](Eigen::Index i) {
    const double gi = G[i];
    const bool onFace = F[i] != 0;
    const double reducedGi =
        gi > 0.0 ? std::min((P[i] - L[i]) * invAlphaBar, gi) : std::max((P[i] - U[i]) * invAlphaBar, gi);
    const double phi = onFace ? gi : 0.0, beta = onFace ? 0.0 : choppedGradient(L[i], U[i], P[i], gi);
    return std::array<double, 3>{phi * phi, beta * beta, onFace ? reducedGi * gi : 0.0};
  };
  // The sums of the current iterate, when the last step computed them in one of its own passes.
  std::optional<std::array<double, 3>> nextSums;
  while (true) {
    const std::array<double, 3> sums =
        nextSums ? *nextSums
                 : reduceBlocks<3>(n, partial_, {0.0, 0.0, 0.0}, gradientSums, kAdd);
    nextSums.reset();
    const double phi2 = sums[0], beta2 = sums[1], reducedPhi = sums[2];
    result.projectedGradientNorm = std::sqrt(phi2 + beta2);
    if (result.iterations == 0 && bNorm == 0.0) threshold = settings.tolerance * result.projectedGradientNorm;
    if (result.projectedGradientNorm <= threshold) {
      result.converged = true;
      break;
    }
    if (result.iterations >= settings.maxIterations) break;
    ++result.iterations;

    if (beta2 <= gamma2 * reducedPhi) {
      // Proportional iterate: a CG step on the face, unless it would leave the box.
      A.apply(d_, Ad_);
      ++result.operatorApplications;
      const auto step = reduceBlocks<3>(n, partial_, {0.0, 0.0, inf}, [Dv, AD, G, reach](Eigen::Index i) {
        return std::array<double, 3>{Dv[i] * AD[i], G[i] * Dv[i], reach(i)};
      }, [](int k, double a, double v) { return k == 2 ? std::min(a, v) : a + v; });
      const double dAd = step[0];
      const double alphaCg = step[1] / dAd;  // exact line search; d is zero off the face
      const double alphaFeasible = step[2];

      if (alphaCg <= alphaFeasible) {
        // The clamp only removes round-off when alphaCg is within an ulp of alphaFeasible.
        auto advance = [&](Eigen::Index i) {
          P[i] = std::clamp(P[i] - alphaCg * Dv[i], L[i], U[i]);
          G[i] -= alphaCg * AD[i];
        };
        // Next direction A-conjugate to the previous one (Dostál & Schöberl 2005, CG step):
        // d = z - (z^T A d / d^T A d) d. Without a face preconditioner z is entrywise, so the step,
        // z and z^T A d take one pass, and the new direction and the next iteration's gradient
        // sums another (the same sums, block by block, as separate passes: bitwise equal).
        double zAd;
        if (preconditioner) {
          forBlocks(n, [&](Eigen::Index begin, Eigen::Index end) {
            for (Eigen::Index i = begin; i < end; ++i) advance(i);
          });
          preconditioner->apply(g_, z_);
          zAd = dot(z_, Ad_);
        } else {
          zAd = reduceBlocks<1>(n, partial_, {0.0}, [&](Eigen::Index i) {
            advance(i);
            Z[i] = diagonallyPreconditioned(i);
            return std::array<double, 1>{Z[i] * AD[i]};
          }, kAdd)[0];
        }
        const double conj = zAd / dAd;
        nextSums = reduceBlocks<3>(n, partial_, {0.0, 0.0, 0.0}, [Dv, Z, conj, gradientSums](Eigen::Index i) {
          Dv[i] = Z[i] - conj * Dv[i];
          return gradientSums(i);
        }, kAdd);
        ++result.cgSteps;
      } else {
        // Expansion: the largest feasible step along d, then a fixed-length step alphaBar along
        // the free gradient at that point, projected onto the box. With alphaBar <= 2/||A|| this
        // decreases f and may add several constraints at once (unlike active-set CG). Entries
        // that reached a bound stay there (d and the free gradient are zero off the face).
        forBlocks(n, [&](Eigen::Index begin, Eigen::Index end) {
          for (Eigen::Index i = begin; i < end; ++i) {
            const double pi = std::clamp(P[i] - alphaFeasible * Dv[i], L[i], U[i]);
            const double gi = G[i] - alphaFeasible * AD[i];
            P[i] = pi > L[i] && pi < U[i] ? std::clamp(pi - alphaBar * gi, L[i], U[i]) : pi;
          }
        });
        updateGradient();
        restart();
        ++result.expansionSteps;
      }
    } else {
      // Proportioning: the chopped gradient dominates, so the active set is wrong; an exact line
      // search along -beta releases the constraints whose multipliers have the wrong sign, cut
      // where an entry would cross its other bound (box constraints only).
      forBlocks(n, [&](Eigen::Index begin, Eigen::Index end) {
        for (Eigen::Index i = begin; i < end; ++i) Dv[i] = F[i] ? 0.0 : choppedGradient(L[i], U[i], P[i], G[i]);
      });
      A.apply(d_, Ad_);
      ++result.operatorApplications;
      double alpha = beta2 / dot(d_, Ad_);  // g^T beta = beta^T beta
      if (boxed_)
        alpha = std::min(alpha, reduceBlocks<1>(n, partial_, {inf}, [&](Eigen::Index i) {
          return std::array<double, 1>{reach(i)};
        }, [](int, double a, double v) { return std::min(a, v); })[0]);
      forBlocks(n, [&](Eigen::Index begin, Eigen::Index end) {
        for (Eigen::Index i = begin; i < end; ++i) {
          P[i] = std::clamp(P[i] - alpha * Dv[i], L[i], U[i]);
          G[i] -= alpha * AD[i];
        }
      });
      restart();
      ++result.proportioningSteps;
    }
  }

  result.relativeProjectedGradient = bNorm > 0.0 ? result.projectedGradientNorm / bNorm : 0.0;
  result.activeCount = static_cast<int>(reduceBlocks<1>(n, partial_, {0.0}, [&](Eigen::Index i) {
    return std::array<double, 1>{P[i] == L[i] || P[i] == U[i] ? 1.0 : 0.0};
  }, kAdd)[0]);
  return result;
}

}  // namespace msim::numerics
