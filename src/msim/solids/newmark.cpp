#include "msim/solids/newmark.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/Sparse>

#include "msim/solids/altitude_spring.hpp"

namespace msim::solids {

NewmarkStats NewmarkStepper::solveHalfStep(const MassSpringSystem& system, const std::vector<Vec3>& at,
                                           const std::vector<Vec3>& from, double h, std::vector<Vec3>& out) {
  const std::size_t n = system.size();
  system.explicitForces(at, forces_);
  // A = M + h sum_s c_s (d d^T) on the spring's two particles (minus across them), c_s = b_s and,
  // with implicit springs, + h k_s / l0_s (the same along each tetrahedron's altitude, spread by
  // its weights); rhs = M v + h F_e. Pinned particles keep `from`: their rows are M v = M v_from
  // and their columns move to the right-hand side.
  Eigen::VectorXd rhs(3 * static_cast<Eigen::Index>(n));
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(3 * n + 36 * system.springs.size());
  for (std::size_t p = 0; p < n; ++p) {
    for (int k = 0; k < 3; ++k) {
      const auto row = static_cast<Eigen::Index>(3 * p + k);
      entries.emplace_back(row, row, system.mass[p]);
      rhs[row] = system.mass[p] * from[p][k] + (system.pinned[p] ? 0.0 : h * forces_[p][k]);
    }
  }
  // c (sum_i w_i v_i) . n along n on the nodes, node i getting w_i of it: the block c w_i w_j n n^T.
  auto addAlong = [&](const int* nodes, const double* weights, int count, const Vec3& n, double c) {
    if (c == 0.0) return;
    for (int i = 0; i < count; ++i) {
      const auto pi = static_cast<std::size_t>(nodes[i]);
      if (system.pinned[pi]) continue;
      for (int j = 0; j < count; ++j) {
        const auto pj = static_cast<std::size_t>(nodes[j]);
        const double w = c * weights[i] * weights[j];
        for (int r = 0; r < 3; ++r)
          for (int k = 0; k < 3; ++k) {
            const double value = w * n[r] * n[k];
            const auto row = static_cast<Eigen::Index>(3 * pi + r);
            if (system.pinned[pj])
              rhs[row] -= value * from[pj][k];
            else
              entries.emplace_back(row, static_cast<Eigen::Index>(3 * pj + k), value);
          }
      }
    }
  };
  // Damping along each spring, and with implicit springs the stiffness k / l0 along it (ch. 5.5).
  for (const Spring& s : system.springs) {
    const Vec3 delta = at[s.b] - at[s.a];
    const double length = delta.norm();
    if (!(length > 0.0)) continue;
    const int nodes[2] = {s.a, s.b};
    const double weights[2] = {-1.0, 1.0};
    addAlong(nodes, weights, 2, delta / length,
             h * (s.damping + (settings_.implicitSprings ? h * s.stiffness / s.restLength : 0.0)));
  }
  for (const TetrahedronSpring& t : system.tetrahedra) {
    const AltitudeChoice choice = chooseAltitude({at[t.v[0]], at[t.v[1]], at[t.v[2]], at[t.v[3]]});
    if (choice.candidate < 0) continue;
    const double l0 = t.restAltitude[static_cast<std::size_t>(choice.candidate)];
    addAlong(t.v.data(), choice.weights.data(), 4, choice.normal,
             h * (t.damping + (settings_.implicitSprings ? h * t.stiffness / l0 : 0.0)));
  }
  Eigen::SparseMatrix<double> a(rhs.size(), rhs.size());
  a.setFromTriplets(entries.begin(), entries.end());
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> cg;
  cg.setTolerance(settings_.cgTolerance);
  cg.setMaxIterations(settings_.cgMaxIterations);
  cg.compute(a);
  Eigen::VectorXd guess(rhs.size());
  for (std::size_t p = 0; p < n; ++p)
    for (int k = 0; k < 3; ++k) guess[static_cast<Eigen::Index>(3 * p + k)] = from[p][k];
  const Eigen::VectorXd solution = cg.solveWithGuess(rhs, guess);
  out.resize(n);
  for (std::size_t p = 0; p < n; ++p)
    out[p] = system.pinned[p] ? from[p] : Vec3(solution[static_cast<Eigen::Index>(3 * p)],
                                               solution[static_cast<Eigen::Index>(3 * p + 1)],
                                               solution[static_cast<Eigen::Index>(3 * p + 2)]);
  NewmarkStats stats;
  stats.iterations = static_cast<int>(cg.iterations());
  stats.converged = cg.info() == Eigen::Success;
  return stats;
}

NewmarkStats NewmarkStepper::step(MassSpringSystem& system, double dt, const BodyContact* bodies) {
  if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument("Newmark step: dt must be > 0");
  const double h = 0.5 * dt;
  const std::size_t n = system.size();
  start_ = system.v;
  NewmarkStats first = solveHalfStep(system, system.x, start_, h, half_);
  mid_.resize(n);
  touched_.assign(n, -1);
  for (std::size_t p = 0; p < n; ++p) {
    Vec3 next = system.x[p] + dt * half_[p];
    if (bodies && !system.pinned[p]) {
      next = bodies->move(system.x[p], half_[p], dt, touched_[p]);
      if (touched_[p] >= 0) start_[p] = bodies->gamma(static_cast<std::size_t>(touched_[p]), next, start_[p]);
    }
    mid_[p] = 0.5 * (system.x[p] + next);
    system.x[p] = next;
  }
  const NewmarkStats second = solveHalfStep(system, mid_, start_, h, half_);
  for (std::size_t p = 0; p < n; ++p) {
    system.v[p] = 2.0 * half_[p] - start_[p];
    if (touched_[p] >= 0) system.v[p] = bodies->gamma(static_cast<std::size_t>(touched_[p]), system.x[p], system.v[p]);
  }
  first.iterations += second.iterations;
  first.converged = first.converged && second.converged;
  first.contacts = static_cast<int>(std::count_if(touched_.begin(), touched_.end(), [](int b) { return b >= 0; }));
  return first;
}

}  // namespace msim::solids
