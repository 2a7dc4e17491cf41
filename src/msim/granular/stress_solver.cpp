#include "msim/granular/stress_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Geometry>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "msim/core/parallel.hpp"
#include "msim/core/timer.hpp"

namespace msim::granular {

struct StressSolver::Impl {
  StressProblem pressure;
  std::array<StressProblem, 5> friction;  // up diagonal, the other pair, and the three off-diagonals
  FaceField kappa, weightP, weightS, weightB, force, flux, velocity0;
  std::vector<double> tmp, tmp2, var, cellScratch, cellBound;
  std::vector<std::vector<BodyFace>> bodyFaces;  // collectBodyFaces of each body, this step
  std::vector<Vec6> bodyVelocity;  // current V~ of each body with the current stresses
};

StressSolver::StressSolver(StressSolverSettings settings) : impl_(std::make_shared<Impl>()), settings_(settings) {
  if (settings_.upAxis < 0 || settings_.upAxis > 2) throw std::invalid_argument("StressSolver: upAxis must be 0, 1 or 2");
  Impl& m = *impl_;
  m.pressure.terms = {{StressComponent::Diagonal(0), -1.0}, {StressComponent::Diagonal(1), -1.0},
                      {StressComponent::Diagonal(2), -1.0}};
  const int u = settings_.upAxis, a = (u + 1) % 3, c = (u + 2) % 3;
  m.friction[0].terms = {{StressComponent::Diagonal(u), 1.0}};
  m.friction[1].terms = {{StressComponent::Diagonal(std::min(a, c)), 1.0}, {StressComponent::Diagonal(std::max(a, c)), -1.0}};
  m.friction[2].terms = {{StressComponent::OffDiagonal(0, 1), 1.0}};
  m.friction[3].terms = {{StressComponent::OffDiagonal(1, 2), 1.0}};
  m.friction[4].terms = {{StressComponent::OffDiagonal(0, 2), 1.0}};
}

const std::vector<double>& StressSolver::stress(const StressComponent& c) const {
  static constexpr int kOffIndex[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
  return s_[static_cast<std::size_t>(kOffIndex[c.a][c.b])];
}

namespace {

// The friction bound of sample q of component c (eq. 5.15) from the cell bounds alpha p: a
// diagonal sample is its cell; an edge sample takes the mean over the cells around it. Slip walls:
// the edges on a domain wall normal to a slip axis carry the wall's tangential friction (the
// off-diagonal components there act only on the faces beside the wall); their bound is 0.
double sampleBound(const StressComponent& c, const IVec3& cells, const std::vector<double>& cell, const IVec3& q,
                   unsigned slipWalls) {
  if (c.diagonal()) return cell[(static_cast<std::size_t>(q[2]) * cells[1] + q[1]) * cells[0] + q[0]];
  for (int w : {c.a, c.b})
    if ((slipWalls >> w & 1u) != 0 && (q[w] == 0 || q[w] == cells[w])) return 0.0;
  double sum = 0.0;
  int count = 0;
  for (int da = -1; da <= 0; ++da)
    for (int db = -1; db <= 0; ++db) {
      IVec3 k = q;
      k[c.a] += da;
      k[c.b] += db;
      if (k[c.a] < 0 || k[c.b] < 0 || k[c.a] >= cells[c.a] || k[c.b] >= cells[c.b]) continue;
      sum += cell[(static_cast<std::size_t>(k[2]) * cells[1] + k[1]) * cells[0] + k[0]];
      ++count;
    }
  return count ? sum / count : 0.0;
}

// The box of the cells where v is positive (empty if none), one slice of z per task.
LatticeBox positiveCells(const std::vector<double>& v, const IVec3& cells) {
  return tbb::parallel_reduce(
      tbb::blocked_range<int>(0, cells[2]), LatticeBox{},
      [&](const tbb::blocked_range<int>& r, LatticeBox box) {
        for (int z = r.begin(); z != r.end(); ++z)
          for (int y = 0; y < cells[1]; ++y)
            for (int x = 0; x < cells[0]; ++x)
              if (v[(static_cast<std::size_t>(z) * cells[1] + y) * cells[0] + x] > 0.0)
                box = box.unite(LatticeBox{IVec3(x, y, z), IVec3(x, y, z)});
        return box;
      },
      [](const LatticeBox& a, const LatticeBox& b) { return a.unite(b); });
}

// out = w * v, face by face.
void weightedFaces(const FaceField& w, const FaceField& v, FaceField& out) {
  for (int a = 0; a < 3; ++a)
    for (std::size_t i = 0; i < v.values[a].size(); ++i) out.values[a][i] = w.values[a][i] * v.values[a][i];
}

}  // namespace

// Face coefficients: kappa = (1 - phi_s) / rho (velocity per impulse density, eq. 5.27; capped
// for sparse faces, see minimumFaceFraction), the pressure weight phi kappa (eqs. 5.8, 5.47), the
// friction energy weight phi rho kappa^2 and its linear weight phi rho kappa (eqs. 5.16-5.19,
// 5.49-5.50). Faces without material have kappa = 0: no stress reaches them.
void StressSolver::faceCoefficients(const GranularGridState& st, const std::vector<const CoupledBody*>& bodies,
                                    double minimumFaceFraction, Impl& m) {
  for (FaceField* f : {&m.kappa, &m.weightP, &m.weightS, &m.weightB}) f->reset(st.spec.res);
  // The faces away from the bodies first (phi_s = 0), then those of each body's box again with
  // the covered fraction of every body there.
  auto coefficients = [&](int a, std::size_t i, double solid) {
    const double rho = st.rhoFace.values[a][i], phi = st.phiFace.values[a][i];
    if (st.open.values[a][i] == 0.0 || !(rho > 0.0) || !(phi > 0.0)) return;
    const double k = std::max(0.0, 1.0 - solid) * phi / (rho * std::max(phi, minimumFaceFraction));
    m.kappa.values[a][i] = k;
    m.weightP.values[a][i] = phi * k;
    m.weightS.values[a][i] = phi * rho * k * k;
    m.weightB.values[a][i] = phi * rho * k;
  };
  for (int a = 0; a < 3; ++a) {
    parallelFor(0, m.kappa.values[a].size(), [&](std::size_t i) { coefficients(a, i, 0.0); }, 4096);
    for (const CoupledBody* body : bodies) {
      const LatticeBox box = body->faces(a);
      forBoxRows(box, m.kappa.size(a), [&](std::size_t row, int y, int z) {
        for (int x = box.first[0]; x <= box.last[0]; ++x)
          coefficients(a, row + static_cast<std::size_t>(x - box.first[0]), coveredFaceFraction(bodies, a, IVec3(x, y, z)));
      });
    }
  }
}

void StressSolver::solve(const GranularGridState& st, double dt, FaceField& velocity,
                         const std::vector<const CoupledBody*>& bodies) {
  Impl& m = *impl_;
  const double correctionSeconds = stats_.correctionSeconds;
  const int correctionIterations = stats_.correctionIterations;
  stats_ = {};
  stats_.correctionSeconds = correctionSeconds;
  stats_.correctionIterations = correctionIterations;
  const std::size_t cells = st.spec.cellCount();
  const double dx = st.spec.dx, vc = st.spec.cellVolume();
  const int up = settings_.upAxis;
  const int pa = std::min((up + 1) % 3, (up + 2) % 3), pc = std::max((up + 1) % 3, (up + 2) % 3);
  // Warm start from the last step's stress when the grid is the same, else from zero.
  if (p_.size() != cells) p_.assign(cells, 0.0);
  const std::array<StressComponent, 6> comps = {StressComponent::Diagonal(0),       StressComponent::Diagonal(1),
                                                StressComponent::Diagonal(2),       StressComponent::OffDiagonal(0, 1),
                                                StressComponent::OffDiagonal(0, 2), StressComponent::OffDiagonal(1, 2)};
  for (std::size_t k = 0; k < 6; ++k) {
    const std::size_t n = static_cast<std::size_t>(latticeSize(comps[k], st.spec.res).prod());
    if (s_[k].size() != n || !settings_.friction) {
      s_[k].assign(n, 0.0);
      sBox_[k] = {};
    }
  }
  // The storage of each friction problem's variable: up, the pair (a, c), xy, yz, xz.
  const std::array<std::size_t, 5> slot = {static_cast<std::size_t>(up), static_cast<std::size_t>(pa), 3, 5, 4};

  for (FaceField* f : {&m.force, &m.flux}) f->reset(st.spec.res);
  faceCoefficients(st, bodies, settings_.minimumFaceFraction, m);
  m.velocity0 = velocity;  // v^n + dt f_ext / rho: the state without stress
  m.cellScratch.assign(cells, 0.0);

  // Bookkeeping by the total stress force density F on the faces (-grad p + div s): the grain
  // velocity is v0 + dt kappa F and each body's V0 + dt V_c M^-1 sum_f phi_s G_f F_f (eq. 5.23).
  // A problem removes its own variable's share of F, solves, and adds the new share back.
  addTerms(m.pressure.terms, p_, 1.0, dx, st.open, m.force);
  for (std::size_t k = 0; k < 6; ++k) addDivergence(comps[k], s_[k], 1.0, dx, st.open, m.force, sBox_[k]);
  auto grainVelocity = [&] {
    for (int a = 0; a < 3; ++a)
      parallelFor(0, velocity.values[a].size(), [&](std::size_t i) {
        velocity.values[a][i] = m.velocity0.values[a][i] + dt * m.kappa.values[a][i] * m.force.values[a][i];
      }, 4096);
  };
  // The same, times the face weights w, into m.flux, on the faces `faces` only (per axis).
  auto weightedGrainVelocity = [&](const FaceField& w, const std::array<LatticeBox, 3>& faces) {
    for (int a = 0; a < 3; ++a) {
      const LatticeBox& box = faces[static_cast<std::size_t>(a)];
      const std::size_t width = static_cast<std::size_t>(box.last[0] - box.first[0] + 1);
      forBoxRows(box, velocity.size(a), [&](std::size_t row, int, int) {
        for (std::size_t i = row; i < row + width; ++i) {
          velocity.values[a][i] = m.velocity0.values[a][i] + dt * m.kappa.values[a][i] * m.force.values[a][i];
          m.flux.values[a][i] = w.values[a][i] * velocity.values[a][i];
        }
      });
    }
  };

  // Each body's faces, with phi_s and G_f = [e_a; r_f x e_a].
  m.bodyFaces.resize(bodies.size());
  for (std::size_t k = 0; k < bodies.size(); ++k) collectBodyFaces(st, *bodies[k], m.bodyFaces[k]);
  auto bodyImpulse = [&](std::size_t k) {
    Vec6 j = Vec6::Zero();
    for (const BodyFace& bf : m.bodyFaces[k]) j += (bf.fraction * bf.direction) * m.force.values[bf.axis][bf.index];
    return (dt * vc * j).eval();
  };
  auto bodyVelocities = [&] {
    m.bodyVelocity.resize(bodies.size());
    for (std::size_t k = 0; k < bodies.size(); ++k)
      m.bodyVelocity[k] = bodies[k]->velocity + bodies[k]->inverseMass * bodyImpulse(k);
  };

  numerics::BoundQpSettings qp;
  qp.tolerance = settings_.tolerance;
  qp.maxIterations = settings_.maxIterations;
  m.pressure.build(st, m.weightP, dt, bodies, m.bodyFaces);
  // Friction operators do not depend on p: built once per step.
  if (settings_.friction)
    for (StressProblem& pr : m.friction) pr.build(st, m.weightS, dt, bodies, m.bodyFaces);

  std::vector<double>& var = m.var;
  for (int iteration = 0; iteration < settings_.staggeredIterations; ++iteration) {
    if (settings_.friction) {
      ScopedTimer t(stats_.frictionSeconds);
      // Bounds |s_ij| <= alpha p (eq. 5.15): the cells' alpha p, and the box of the cells where
      // it is positive; no friction sample outside what reads that box has room.
      m.cellBound.resize(cells);
      parallelFor(0, cells, [&](std::size_t i) { m.cellBound[i] = st.alpha[i] * p_[i]; }, 4096);
      const LatticeBox pressed = positiveCells(m.cellBound, st.spec.res);
      for (std::size_t k = 0; k < m.friction.size(); ++k) {
        StressProblem& pr = m.friction[k];
        const std::vector<double>& sUp = s_[static_cast<std::size_t>(up)];
        // The pair keeps s_a and s_c within the bounds given s_up.
        const StressComponent& c = pr.terms.front().c;
        LatticeBox room = pressed;
        if (!c.diagonal() && !room.empty()) {
          room.last[c.a] += 1;  // an edge reads the cells below it along a and b too
          room.last[c.b] += 1;
        }
        pr.setBounds(room.intersect(LatticeBox::whole(pr.lattice)), [&](std::size_t i, const IVec3& q) {
          const double half = k == 1 ? 0.5 * std::abs(sUp[i]) : 0.0;
          return std::max(0.0, sampleBound(c, st.spec.res, m.cellBound, q, settings_.slipWalls) - half);
        });
        const Eigen::Index n = pr.lo.size();
        // The new variable lives on the samples with room (the others are held at 0), so only
        // the faces reading those samples, or the old ones, take part in the bookkeeping below.
        const StressProblem::FreeSamples found = pr.freeSamples(pr.boundsBox());
        const std::size_t pa_ = static_cast<std::size_t>(pa), pc_ = static_cast<std::size_t>(pc);
        // Remove this variable's share of F (v~|_{s_c = 0} of eq. 5.46). The pair removes both
        // its components and puts back their trace-free part -s_up / 2 for the current s_up.
        if (k == 1) {
          const LatticeBox old = sBox_[static_cast<std::size_t>(up)].unite(sBox_[pa_]).unite(sBox_[pc_]);
          for (int axis : {pa, pc}) {
            std::vector<double>& s = s_[static_cast<std::size_t>(axis)];
            parallelFor(0, cells, [&](std::size_t i) { m.cellScratch[i] = -0.5 * sUp[i] - s[i]; }, 4096);
            addDivergence(StressComponent::Diagonal(axis), m.cellScratch, 1.0, dx, st.open, m.force, old);
          }
          var.resize(cells);
          parallelFor(0, cells, [&](std::size_t i) { var[i] = 0.5 * (s_[pa_][i] - s_[pc_][i]); }, 4096);
        } else {
          addTerms(pr.terms, s_[slot[k]], -1.0, dx, st.open, m.force, sBox_[slot[k]]);
        }
        // The variable: the pair's d, or the component itself (solved in place).
        std::vector<double>& variable = k == 1 ? var : s_[slot[k]];
        bodyVelocities();
        // Linear term dt (D^T phi (1 - phi_s) v~ + J^T V~) (eqs. 5.19, 5.26, 5.50), negated for
        // the solver's 1/2 x^T A x - b^T x, on the free samples (the solve reads no other).
        weightedGrainVelocity(m.weightB, termFaces(pr.terms, found.box, st.spec.res));
        transposeTerms(pr.terms, m.flux, dx, st.open, m.tmp, m.tmp2, found.box);
        pr.b.resize(n);
        if (!found.box.empty())
          parallelForCells<3>(found.box.last - found.box.first + IVec3::Ones(), [&](const IVec3& q, std::size_t) {
            const IVec3 at = q + found.box.first;
            const std::size_t i = (static_cast<std::size_t>(at[2]) * pr.lattice[1] + at[1]) * pr.lattice[0] + at[0];
            pr.b[static_cast<Eigen::Index>(i)] = -dt * m.tmp[i];
          });
        for (std::size_t b = 0; b < bodies.size(); ++b) {
          const BodyColumns& bc = pr.bodies[b];
          for (std::size_t j = 0; j < bc.sample.size(); ++j)
            pr.b[static_cast<Eigen::Index>(bc.sample[j])] -= dt * bc.column[j].dot(m.bodyVelocity[b]);
        }
        pr.x = Eigen::Map<const Eigen::VectorXd>(variable.data(), n);
        // A friction gradient of dt / dx * delta_v per sample is a velocity error of about
        // delta_v: below velocityTolerance the solve has nothing left worth removing (at rest the
        // relative tolerance would chase particle noise to ever smaller absolute levels).
        stats_.frictionIterations += pr.solve(found, qp, dt / dx * settings_.velocityTolerance);
        variable.assign(pr.x.data(), pr.x.data() + pr.x.size());
        addTerms(pr.terms, variable, 1.0, dx, st.open, m.force, found.box);
        if (k == 1) {
          parallelFor(0, cells, [&](std::size_t i) {
            s_[pa_][i] = -0.5 * sUp[i] + var[i];
            s_[pc_][i] = -0.5 * sUp[i] - var[i];
          }, 4096);
          sBox_[pa_] = sBox_[pc_] = sBox_[static_cast<std::size_t>(up)].unite(found.box);
        } else {
          sBox_[slot[k]] = found.box;
        }
      }
    }
    ScopedTimer t(stats_.pressureSeconds);
    StressProblem& pr = m.pressure;
    // Remove the pressure's share, then predict phi + phi_s without it (eqs. 5.7-5.8, 5.25):
    // phi* = phi^n - dt div(phi v~) = phi^n + dt sum_a D_a^T (phi v~).
    addTerms(pr.terms, p_, -1.0, dx, st.open, m.force);
    grainVelocity();
    bodyVelocities();
    weightedFaces(st.phiFace, velocity, m.flux);
    transposeTerms(pr.terms, m.flux, dx, st.open, m.tmp, m.tmp2);  // = div(phi v~)
    pr.b.resize(static_cast<Eigen::Index>(cells));
    // Unilateral: phi^{n+1} <= 1 (eq. 5.10). Bilateral cells (at least half full): phi^{n+1} =
    // min(phi^n, 1), i.e. div(phi v) = 0 unless overfull, with p free.
    auto bilateralCell = [&](std::size_t i) { return settings_.bilateral && st.phi[i] >= 0.5; };
    pr.lo.resize(static_cast<Eigen::Index>(cells));
    pr.hi.resize(static_cast<Eigen::Index>(cells));
    parallelFor(0, cells, [&](std::size_t i) {
      const Eigen::Index e = static_cast<Eigen::Index>(i);
      pr.b[e] = st.phi[i] - dt * m.tmp[i] - (bilateralCell(i) ? std::min(st.phi[i], 1.0) : 1.0);
      pr.lo[e] = bilateralCell(i) ? -std::numeric_limits<double>::infinity() : 0.0;
      pr.hi[e] = std::numeric_limits<double>::infinity();
    }, 4096);
    // Bodies: + phi_s^{n+1}|p=0 = phi_s^n + dt J1^T V~ (the columns carry the pressure's -1).
    for (std::size_t b = 0; b < bodies.size(); ++b) {
      const BodyColumns& bc = pr.bodies[b];
      forEachInBox(bodies[b]->cells, st.spec.res, [&](std::size_t i, const IVec3& q) {
        pr.b[static_cast<Eigen::Index>(i)] += bodies[b]->cellFractionAt(q);
      });
      for (std::size_t j = 0; j < bc.sample.size(); ++j)
        pr.b[static_cast<Eigen::Index>(bc.sample[j])] -= dt * bc.column[j].dot(m.bodyVelocity[b]);
    }
    pr.x = Eigen::Map<const Eigen::VectorXd>(p_.data(), static_cast<Eigen::Index>(cells));
    // Cells without material around them keep p = 0 and drop out of the solve; its stopping
    // threshold stays tolerance * ||b|| over the whole grid, as when they were solved for.
    const double referenceNorm = pr.b.norm();
    pr.holdInertSamples();
    stats_.pressureIterations += pr.solve(pr.freeSamples(), qp, 0.0, referenceNorm);
    std::copy(pr.x.data(), pr.x.data() + pr.x.size(), p_.begin());
    addTerms(pr.terms, p_, 1.0, dx, st.open, m.force);
  }
  grainVelocity();
  impulses_.resize(bodies.size());
  for (std::size_t k = 0; k < bodies.size(); ++k) impulses_[k] = bodyImpulse(k);
  stats_.activePressureCells = static_cast<int>(std::count_if(p_.begin(), p_.end(), [](double p) { return p > 0.0; }));
}

const FaceField& StressSolver::correctDensity(GranularGridState& st, const std::vector<const CoupledBody*>& bodies) {
  Impl& m = *impl_;
  ScopedTimer t(stats_.correctionSeconds);
  const std::size_t cells = st.spec.cellCount();
  // The pressure problem with dt = 1 and no velocity (eq. 5.14, Delta x = -grad y / rho).
  for (FaceField* f : {&m.force, &m.flux}) f->reset(st.spec.res);
  faceCoefficients(st, bodies, settings_.minimumFaceFraction, m);
  StressProblem& pr = m.pressure;
  // Bodies do not move in the correction: only the grid part, with their volume in the constraint.
  pr.build(st, m.weightP, 1.0, {}, {});
  pr.b.resize(static_cast<Eigen::Index>(cells));
  // phi + phi_s - 1: phi - 1 away from the bodies, then the cells of their boxes.
  parallelFor(0, cells, [&](std::size_t i) { pr.b[static_cast<Eigen::Index>(i)] = st.phi[i] - 1.0; }, 4096);
  for (const CoupledBody* body : bodies)
    forEachInBox(body->cells, st.spec.res, [&](std::size_t i, const IVec3& q) {
      pr.b[static_cast<Eigen::Index>(i)] = st.phi[i] + coveredCellFraction(bodies, q) - 1.0;
    });
  displacement_.reset(st.spec.res);
  stats_.correctionIterations = 0;
  if (!(pr.b.maxCoeff() > 0.0)) return displacement_;
  pr.lo = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(cells));
  pr.hi = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(cells), std::numeric_limits<double>::infinity());
  pr.x = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(cells));
  numerics::BoundQpSettings qp;
  qp.tolerance = settings_.tolerance;
  qp.maxIterations = settings_.maxIterations;
  const double referenceNorm = pr.b.norm();  // as in the pressure solve
  pr.holdInertSamples();
  stats_.correctionIterations = pr.solve(pr.freeSamples(), qp, 0.0, referenceNorm);
  m.var.assign(pr.x.data(), pr.x.data() + pr.x.size());
  addTerms(pr.terms, m.var, 1.0, st.spec.dx, st.open, m.force);
  weightedFaces(m.kappa, m.force, displacement_);
  weightedFaces(st.phiFace, displacement_, m.flux);
  // phi <- phi - div(phi Delta x) (eq. 5.14).
  transposeTerms(pr.terms, m.flux, st.spec.dx, st.open, m.tmp, m.tmp2);
  for (std::size_t i = 0; i < cells; ++i) st.phi[i] -= m.tmp[i];
  return displacement_;
}

}  // namespace msim::granular
