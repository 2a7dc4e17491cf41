#include "msim/solids/newmark.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>


#include "msim/solids/altitude_spring.hpp"

namespace msim::solids {

// The step's matrix is A = M + h sum_s c_s (d d^T) on each spring's particles (weights -1 and 1,
// the altitude springs' by their weights), c_s = b_s and, with implicit springs, + h k_s / l0_s;
// rhs = M v + h F_e. It is applied without being assembled (conjugate gradients with a diagonal
// preconditioner): the terms are gathered once per solve, and nothing is allocated once the
// buffers have grown. Pinned particles keep `from`: their unknowns stay fixed, so their columns act
// through the start residual and their rows drop out.
NewmarkStats NewmarkStepper::solveHalfStep(const MassSpringSystem& system, const std::vector<Vec3>& at,
                                           const std::vector<Vec3>& from, double h, std::vector<Vec3>& out) {
  const std::size_t n = system.size();
  system.explicitForces(at, forces_);
  terms_.clear();
  const auto addTerm = [&](const int* nodes, const double* weights, int count, const Vec3& direction, double c) {
    if (c == 0.0) return;
    Term t;
    t.count = count;
    for (int i = 0; i < count; ++i) {
      t.node[i] = nodes[i];
      t.weight[i] = weights[i];
    }
    t.direction = direction;
    t.coefficient = c;
    terms_.push_back(t);
  };
  // Damping along each spring, and with implicit springs the stiffness k / l0 along it (ch. 5.5).
  for (const Spring& s : system.springs) {
    const Vec3 delta = at[s.b] - at[s.a];
    const double length = delta.norm();
    if (!(length > 0.0)) continue;
    const int nodes[2] = {s.a, s.b};
    const double weights[2] = {-1.0, 1.0};
    addTerm(nodes, weights, 2, delta / length,
            h * (s.damping + (settings_.implicitSprings ? h * s.stiffness / s.restLength : 0.0)));
  }
  for (const TetrahedronSpring& t : system.tetrahedra) {
    const AltitudeChoice choice = chooseAltitude({at[t.v[0]], at[t.v[1]], at[t.v[2]], at[t.v[3]]});
    if (choice.candidate < 0) continue;
    const double l0 = t.restAltitude[static_cast<std::size_t>(choice.candidate)];
    addTerm(t.v.data(), choice.weights.data(), 4, choice.normal,
            h * (t.damping + (settings_.implicitSprings ? h * t.stiffness / l0 : 0.0)));
  }
  // y = A u on the free particles (pinned rows zero).
  const auto apply = [&](const std::vector<Vec3>& u, std::vector<Vec3>& y) {
    for (std::size_t p = 0; p < n; ++p) y[p] = system.mass[p] * u[p];
    for (const Term& t : terms_) {
      double along = 0.0;
      for (int i = 0; i < t.count; ++i) along += t.weight[i] * u[static_cast<std::size_t>(t.node[i])].dot(t.direction);
      const Vec3 f = t.coefficient * along * t.direction;
      for (int i = 0; i < t.count; ++i) y[static_cast<std::size_t>(t.node[i])] += t.weight[i] * f;
    }
    for (std::size_t p = 0; p < n; ++p)
      if (system.pinned[p]) y[p].setZero();
  };
  inverseDiagonal_.assign(n, Vec3::Zero());
  for (std::size_t p = 0; p < n; ++p) inverseDiagonal_[p] = Vec3::Constant(system.mass[p]);
  for (const Term& t : terms_)
    for (int i = 0; i < t.count; ++i)
      inverseDiagonal_[static_cast<std::size_t>(t.node[i])] +=
          t.coefficient * t.weight[i] * t.weight[i] * t.direction.cwiseProduct(t.direction);
  for (Vec3& d : inverseDiagonal_) d = d.cwiseInverse();

  out = from;
  residual_.resize(n);
  product_.resize(n);
  search_.resize(n);
  precond_.resize(n);
  apply(out, product_);
  double rhsNorm2 = 0.0;
  for (std::size_t p = 0; p < n; ++p) {
    if (system.pinned[p]) {
      residual_[p].setZero();
      continue;
    }
    const Vec3 rhs = system.mass[p] * from[p] + h * forces_[p];
    rhsNorm2 += rhs.squaredNorm();
    residual_[p] = rhs - product_[p];
  }
  const auto dot = [&](const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
    double sum = 0.0;
    for (std::size_t p = 0; p < n; ++p) sum += a[p].dot(b[p]);
    return sum;
  };
  const double target2 = settings_.cgTolerance * settings_.cgTolerance * rhsNorm2;
  NewmarkStats stats;
  double residualNorm2 = dot(residual_, residual_);
  for (std::size_t p = 0; p < n; ++p) precond_[p] = inverseDiagonal_[p].cwiseProduct(residual_[p]);
  search_ = precond_;
  double rz = dot(residual_, precond_);
  while (residualNorm2 > target2 && stats.iterations < settings_.cgMaxIterations) {
    apply(search_, product_);
    const double curvature = dot(search_, product_);
    if (!(curvature > 0.0)) break;
    const double alpha = rz / curvature;
    for (std::size_t p = 0; p < n; ++p) {
      out[p] += alpha * search_[p];
      residual_[p] -= alpha * product_[p];
      precond_[p] = inverseDiagonal_[p].cwiseProduct(residual_[p]);
    }
    const double rzNext = dot(residual_, precond_);
    const double beta = rzNext / rz;
    rz = rzNext;
    for (std::size_t p = 0; p < n; ++p) search_[p] = precond_[p] + beta * search_[p];
    residualNorm2 = dot(residual_, residual_);
    ++stats.iterations;
  }
  stats.converged = residualNorm2 <= target2;
  return stats;
}

NewmarkStats NewmarkStepper::step(MassSpringSystem& system, double dt, const BodyContact* bodies,
                                   const SelfRepulsion* repulsion) {
  if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument("Newmark step: dt must be > 0");
  const double h = 0.5 * dt;
  const std::size_t n = system.size();
  start_ = system.v;
  NewmarkStats first = solveHalfStep(system, system.x, start_, h, half_);
  if (repulsion) {
    inverseMasses(system.mass, system.pinned, inverseMass_);
    first.repulsions = repulsion->repelPositionVelocity(system.x, half_, inverseMass_, dt);
  }
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
  if (repulsion) repulsion->repelEndVelocity(system.x, system.v, inverseMass_);
  first.iterations += second.iterations;
  first.converged = first.converged && second.converged;
  first.contacts = static_cast<int>(std::count_if(touched_.begin(), touched_.end(), [](int b) { return b >= 0; }));
  return first;
}

}  // namespace msim::solids
