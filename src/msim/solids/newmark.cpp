#include "msim/solids/newmark.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>


#include "msim/core/parallel.hpp"
#include "msim/solids/altitude_spring.hpp"

namespace msim::solids {

namespace {

// Iterations a solve needs before its convergence rate tells whether the multigrid hierarchy has aged.
constexpr int kRateSample = 8;
// applyElastic's chunks: a small cloth (a few thousand springs) runs in one, where the threads' start
// would cost more than they save; the product is the same either way.
constexpr std::size_t kTermGrain = 8192;

}  // namespace

// Half step i of the scheme solves M v' = M v + h F(x + c v') - h D v' for v', where x is the
// solve's base (x(n), then x(n+1/2)), c = dt the reach of the position update x(n+1) = x(n) +
// dt v(n+1/2) and D the damping along the springs. Elasticity linearised at x_k = x + c v_k
// (v_0 = 0: at the base, as the seed) gives the matrix A = M + h sum_s (c_s d d^T + c'_s (I - d d^T))
// on each spring's particles (weights -1 and 1, the altitude springs' by their weights), with
// c_s = b_s and, with implicit springs, + c k_s / l0_s (the seed's "Delta t k / l0", ch. 5.5);
// c'_s = c T_s / L_s for a stretched edge spring with implicit springs, else 0; and
// rhs = M v + h F(x_k) + h c K_k v_k, K_k the elastic part. Further Newton iterations
// (`newtonIterations`) take the springs' directions and tensions where the last solve moves the
// particles to. The terms are gathered, and A assembled in symmetric 3 x 3 blocks
// (newmark_matrix.hpp), once per iteration; nothing is allocated once the buffers have grown.
// Pinned particles keep `from`: their unknowns stay fixed, so their columns act through the start
// residual and their rows drop out.
void NewmarkStepper::gatherTerms(const MassSpringSystem& system, const std::vector<Vec3>& at, double h, double reach) {
  terms_.clear();
  shortestSpring_ = std::numeric_limits<double>::infinity();
  const auto addTerm = [&](const int* nodes, const double* weights, int count, const Vec3& direction, double damping,
                           double along, double across) {
    if (damping == 0.0 && along == 0.0 && across == 0.0) return;
    SpringTerm t;
    t.count = count;
    for (int i = 0; i < count; ++i) {
      t.node[i] = nodes[i];
      t.weight[i] = weights[i];
    }
    t.direction = direction;
    t.coefficient = h * (damping + along);
    t.stiffness = h * along;
    t.sideways = h * across;
    terms_.push_back(t);
  };
  // Damping along each spring, and with implicit springs the stiffness k / l0 along it (ch. 5.5)
  // and, for a stretched spring, the stiffness T / L = (k / l0)(1 - l0 / L) across it that its
  // tension gives when it turns (the rest of the force's Jacobian; the seed freezes the direction
  // and leaves it explicit, which bounds the step of a swinging cloth by 2 sqrt(L mu / T)).
  // A compressed spring's sideways stiffness is negative (buckling) and stays explicit, which keeps
  // A positive definite.
  for (const Spring& s : system.springs) {
    const Vec3 delta = at[s.b] - at[s.a];
    const double length = delta.norm();
    if (!(length > 0.0)) continue;
    const int nodes[2] = {s.a, s.b};
    const double weights[2] = {-1.0, 1.0};
    shortestSpring_ = std::min(shortestSpring_, s.restLength);
    const double along = reach * s.stiffness / s.restLength;
    const double across = settings_.tensionAcross ? along * std::max(0.0, 1.0 - s.restLength / length) : 0.0;
    addTerm(nodes, weights, 2, delta / length, s.damping, along, across);
  }
  for (const TetrahedronSpring& t : system.tetrahedra) {
    const AltitudeChoice choice = chooseAltitude({at[t.v[0]], at[t.v[1]], at[t.v[2]], at[t.v[3]]});
    if (choice.candidate < 0) continue;
    const double l0 = t.restAltitude[static_cast<std::size_t>(choice.candidate)];
    shortestSpring_ = std::min(shortestSpring_, l0);
    addTerm(t.v.data(), choice.weights.data(), 4, choice.normal, t.damping, reach * t.stiffness / l0, 0.0);
  }
  // The terms' particles are the same from one linearisation to the next unless a spring vanished or
  // an altitude spring chose another candidate: the incidence (and the matrix's slots for it) is
  // rebuilt only then.
  const bool sameParticles =
      incidenceStart_.size() == system.size() + 1 && termParticles_.size() == terms_.size() &&
      std::equal(terms_.begin(), terms_.end(), termParticles_.begin(), [](const SpringTerm& t, const TermParticles& known) {
        return t.count == known.count && t.node == known.node;
      });
  if (!sameParticles) {
    termParticles_.resize(terms_.size());
    for (std::size_t k = 0; k < terms_.size(); ++k) termParticles_[k] = {terms_[k].count, terms_[k].node};
    gatherIncidence(system.size());
    ++incidenceVersion_;
  }
  // Split among processes, each assembles and inverts its own rows only (its products read no other).
  matrix_.assemble(system, terms_, incidenceStart_, incidence_, incidenceVersion_, split_);
  if (settings_.preconditioner == SolvePreconditioner::Jacobi) {
    if (split_) jacobi_.setup(matrix_.matrix(), split_->owned());
    else jacobi_.setup(matrix_.matrix());
  }
}

void NewmarkStepper::gatherIncidence(std::size_t particles) {
  incidenceStart_.assign(particles + 1, 0);
  for (const SpringTerm& t : terms_)
    for (int i = 0; i < t.count; ++i) ++incidenceStart_[static_cast<std::size_t>(t.node[i]) + 1];
  for (std::size_t p = 0; p < particles; ++p) incidenceStart_[p + 1] += incidenceStart_[p];
  incidence_.resize(static_cast<std::size_t>(incidenceStart_[particles]));
  std::vector<int>& next = incidenceFill_;
  next.assign(incidenceStart_.begin(), incidenceStart_.end() - 1);
  for (std::size_t k = 0; k < terms_.size(); ++k)
    for (int i = 0; i < terms_[k].count; ++i)
      incidence_[static_cast<std::size_t>(next[static_cast<std::size_t>(terms_[k].node[i])]++)] = {static_cast<int>(k), i};
  termForces_.resize(terms_.size());
}

// Two passes on all cores: each term's elastic force from the particles it joins, then each
// particle's sum over its terms in the terms' order (no two threads write one particle; the same
// sums whatever the thread count).
void NewmarkStepper::applyElastic(const double* u, double* y) const {
  parallelFor(0, terms_.size(), [&](std::size_t k) {
    const SpringTerm& t = terms_[k];
    Vec3 relative = Vec3::Zero();
    for (int i = 0; i < t.count; ++i) relative += t.weight[i] * Eigen::Map<const Vec3>(u + 3 * t.node[i]);
    const double along = relative.dot(t.direction);
    termForces_[k] = t.stiffness * along * t.direction + t.sideways * (relative - along * t.direction);
  }, kTermGrain);
  parallelFor(0, incidenceStart_.size() - 1, [&](std::size_t p) {
    Vec3 sum = Vec3::Zero();
    for (int j = incidenceStart_[p]; j < incidenceStart_[p + 1]; ++j) {
      const auto& [term, slot] = incidence_[static_cast<std::size_t>(j)];
      sum += terms_[static_cast<std::size_t>(term)].weight[static_cast<std::size_t>(slot)] * termForces_[static_cast<std::size_t>(term)];
    }
    Eigen::Map<Vec3>(y + 3 * p) += sum;
  }, kTermGrain / 2);
}

NewmarkStats NewmarkStepper::solveHalfStep(const MassSpringSystem& system, const std::vector<Vec3>& base,
                                           const std::vector<Vec3>& from, double h, std::vector<Vec3>& out) {
  const std::size_t n = system.size();
  const double reach = settings_.implicitSprings ? 2.0 * h : 0.0;
  const int iterations = settings_.implicitSprings ? std::max(1, settings_.newtonIterations) : 1;
  NewmarkStats stats;
  out.resize(n);
  for (std::size_t p = 0; p < n; ++p)
    if (system.pinned[p]) out[p] = from[p];
  residual_.resize(n);
  product_.resize(n);
  linearisedAt_.resize(n);
  // The solve's tolerance is relative to the right-hand side seen from the particles' mean motion:
  // the scheme is unchanged by a uniform translation (springs act on differences), and a yardstick
  // that grew with M v would let a fast-moving cloth stop short and lose speed with every step (a
  // cloth sliding at 2.6 m/s slowed 5% more than friction does at 16 steps per frame).
  const Vec3 meanVelocity = system.meanVelocity(from);
  for (int k = 0; k < iterations; ++k) {
    // x_k = base + c v_k, with v_0 = 0 and v_k the last solve's answer.
    for (std::size_t p = 0; p < n; ++p) linearisedAt_[p] = k == 0 ? base[p] : base[p] + reach * out[p];
    system.explicitForces(linearisedAt_, forces_);
    gatherTerms(system, linearisedAt_, h, reach);
    // rhs = M v + h F(x_k) + h c K_k v_k (product_ holds h c K_k v_k), residual = rhs - A out.
    for (Vec3& y : product_) y.setZero();
    if (k > 0) applyElastic(out.data()->data(), product_.data()->data());
    double rhsNorm2 = 0.0;
    for (std::size_t p = 0; p < n; ++p) {
      if (system.pinned[p]) continue;
      residual_[p] = system.mass[p] * from[p] + h * forces_[p] + product_[p];
      rhsNorm2 += (residual_[p] - system.mass[p] * meanVelocity).squaredNorm();
    }
    // Split among processes, only this process's rows of the residual are used (the others' rows of
    // the matrix are not assembled here).
    if (split_) matrix_.matrix().multiplyRows(out.data()->data(), product_.data()->data(), split_->owned());
    else matrix_.matrix().multiply(out.data()->data(), product_.data()->data());
    for (std::size_t p = 0; p < n; ++p) residual_[p] = system.pinned[p] ? Vec3::Zero() : Vec3(residual_[p] - product_[p]);
    if (k + 1 < iterations) previous_ = out;
    const NewmarkStats solve = conjugateGradients(system, h, rhsNorm2, out);
    stats.iterations += solve.iterations;
    stats.converged = stats.converged && solve.converged;
    stats.preconditionerSetups += solve.preconditionerSetups;
    ++stats.linearisations;
    if (k + 1 < iterations) {
      // Converged once the answer moves the linearisation point by less than newtonTolerance of the
      // shortest spring.
      double change = 0.0;
      for (std::size_t p = 0; p < n; ++p) change = std::max(change, (out[p] - previous_[p]).squaredNorm());
      if (reach * std::sqrt(change) <= settings_.newtonTolerance * shortestSpring_) break;
    }
  }
  return stats;
}

void NewmarkStepper::setSplit(const ParticleSplit* split) {
  if (split && settings_.preconditioner != SolvePreconditioner::Jacobi)
    throw std::invalid_argument("Newmark step: a solve split among processes needs the block-Jacobi preconditioner");
  split_ = split;
}

// Solves A out = rhs from the residual rhs - A out already in residual_.
NewmarkStats NewmarkStepper::conjugateGradients(const MassSpringSystem& system, double h, double rhsNorm2,
                                                 std::vector<Vec3>& out) {
  const auto unknowns = static_cast<Eigen::Index>(3 * system.size());
  unknowns_ = Eigen::Map<const Eigen::VectorXd>(out.data()->data(), unknowns);
  residualVector_ = Eigen::Map<const Eigen::VectorXd>(residual_.data()->data(), unknowns);
  const double target2 = settings_.cgTolerance * settings_.cgTolerance * rhsNorm2;
  NewmarkStats stats;
  numerics::SparseCgStats solve;
  const numerics::SymmetricBlockMatrix& A = matrix_.matrix();
  const auto product = [&A](const Eigen::VectorXd& u, Eigen::VectorXd& y) { A.multiply(u, y); };
  if (split_) {
    // Selle ch. 8.2: this process's rows of r, z and the search direction (the others' stay 0:
    // block-Jacobi keeps rows apart), the search direction's rows shared before each product, the
    // dot products summed over the processes; x's other rows stay put and come from their owners.
    for (std::size_t p = 0; p < system.size(); ++p)
      if (!split_->owns(static_cast<int>(p))) residualVector_.segment<3>(static_cast<Eigen::Index>(3 * p)).setZero();
    const auto splitProduct = [&](const Eigen::VectorXd& u, Eigen::VectorXd& y) {
      sharedSearch_ = u;
      split_->shareOwned(sharedSearch_.data());
      y.setZero(unknowns);
      A.multiplyRows(sharedSearch_.data(), y.data(), split_->owned());
    };
    solve = numerics::preconditionedCg(splitProduct, jacobi_, unknowns_, residualVector_, target2, settings_.cgMaxIterations,
                                       workspace_, [this](double local) { return split_->sum(local); });
    split_->shareOwned(unknowns_.data());
  } else if (settings_.preconditioner == SolvePreconditioner::Multigrid) {
    const bool setup = stale_ || multigridParticles_ != system.size() || std::abs(h - multigridH_) > 0.25 * multigridH_;
    if (setup) {
      // The coarse levels carry each aggregate's rigid motions: translations, and rotations, which
      // springs that are not stretched barely resist (a slack or folded cloth).
      Vec3 center = Vec3::Zero();
      for (const Vec3& p : linearisedAt_) center += p;
      center /= static_cast<double>(std::max<std::size_t>(1, linearisedAt_.size()));
      multigrid_.setup(A.expanded(), numerics::rigidModes(linearisedAt_, center));
      multigridParticles_ = system.size();
      multigridH_ = h;
      stale_ = false;
      ++stats.preconditionerSetups;
    }
    solve = numerics::preconditionedCg(product, multigrid_, unknowns_, residualVector_, target2, settings_.cgMaxIterations, workspace_);
    // The first solve of at least kRateSample iterations after the setup measures the hierarchy's
    // rate (fewer, as when a Newton iteration starts near its answer, say little).
    if (setup) multigridRate_ = 0.0;
    if (solve.iterations >= kRateSample) {
      const double rate = solve.digitsPerIteration();
      if (multigridRate_ == 0.0) multigridRate_ = rate;
      else if (rate > 0.25 * multigridRate_) stale_ = true;
    }
  } else {
    solve = numerics::preconditionedCg(product, jacobi_, unknowns_, residualVector_, target2, settings_.cgMaxIterations, workspace_);
  }
  Eigen::Map<Eigen::VectorXd>(out.data()->data(), unknowns) = unknowns_;
  stats.iterations = solve.iterations;
  stats.converged = solve.converged;
  return stats;
}

NewmarkStats NewmarkStepper::step(MassSpringSystem& system, double dt, const BodyContact* bodies,
                                   SelfRepulsion* repulsion) {
  if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument("Newmark step: dt must be > 0");
  const double h = 0.5 * dt;
  const std::size_t n = system.size();
  start_ = system.v;
  // The first solve starts from v(n) plus the last step's solved change over its first half,
  // scaled to this step (exact for a steady acceleration; contact, repulsion and collisions that
  // changed velocities after that solve are not extrapolated): in the collision loop's short inner
  // steps a fifth fewer iterations. Steps solved with Newton iterations (frame-sized ones) start
  // from v(n): a frame's change predicts the next one's poorly (a swinging cloth turns within a
  // few frames), and where the Newton loop stops depends on where it starts.
  half_ = start_;
  const bool extrapolate = !settings_.implicitSprings || settings_.newtonIterations <= 1;
  if (extrapolate && lastChange_.size() == n && lastDt_ > 0.0) {
    const double ratio = dt / lastDt_;
    for (std::size_t p = 0; p < n; ++p)
      if (!system.pinned[p]) half_[p] += ratio * lastChange_[p];
  }
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
  // The second solve starts from the first one's answer: both approximate v(n+1/2).
  const NewmarkStats second = solveHalfStep(system, mid_, start_, h, half_);
  lastChange_.resize(n);
  for (std::size_t p = 0; p < n; ++p) lastChange_[p] = half_[p] - start_[p];
  lastDt_ = dt;
  for (std::size_t p = 0; p < n; ++p) {
    system.v[p] = 2.0 * half_[p] - start_[p];
    if (touched_[p] >= 0) system.v[p] = bodies->gamma(static_cast<std::size_t>(touched_[p]), system.x[p], system.v[p]);
  }
  if (repulsion) repulsion->repelEndVelocity(system.x, system.v, inverseMass_);
  first.iterations += second.iterations;
  first.linearisations += second.linearisations;
  first.preconditionerSetups += second.preconditionerSetups;
  first.converged = first.converged && second.converged;
  first.contacts = static_cast<int>(std::count_if(touched_.begin(), touched_.end(), [](int b) { return b >= 0; }));
  return first;
}

}  // namespace msim::solids
