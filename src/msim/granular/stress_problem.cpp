#include "msim/granular/stress_problem.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "msim/core/parallel.hpp"

namespace msim::granular {

void StressProblem::build(const GranularGridState& st, const FaceField& weight, double dt,
                          const std::vector<const CoupledBody*>& coupled,
                          const std::vector<std::vector<BodyFace>>& faces) {
  lattice = latticeSize(terms.front().c, st.spec.res);
  const std::size_t n = static_cast<std::size_t>(lattice.prod());
  // dt^2 (sum over terms of the stencils): the first term's straight into place, the next ones
  // added (the pair has two), then scaled, in one pass.
  poissonStencil(terms.front().c, weight, st.spec.dx, st.open, 0.0, lower, diagonal);
  for (std::size_t t = 1; t < terms.size(); ++t) {
    poissonStencil(terms[t].c, weight, st.spec.dx, st.open, 0.0, part, partDiagonal);
    parallelFor(0, n, [&](std::size_t i) {
      for (int a = 0; a < 3; ++a) lower[a][i] += part[a][i];
      diagonal[i] += partDiagonal[i];
    }, 4096);
  }
  const double dt2 = dt * dt;
  // Samples no material reaches decouple (hourglass: with a placeholder diagonal of 1 instead,
  // a thousand MPRGP steps and more per friction solve instead of about ten).
  parallelFor(0, n, [&](std::size_t i) {
    for (int a = 0; a < 3; ++a) lower[a][i] *= dt2;
    diagonal[i] *= dt2;
  }, 4096);
  decoupled.resize(n);
  parallelFor(0, n, [&](std::size_t i) { decoupled[i] = diagonal[i] > 0.0 ? 0 : 1; }, 4096);
  numerics::setDecoupledDiagonals(diagonal, [&](std::size_t i) { return decoupled[i] != 0; });
  op.setBodyWeight(dt2 * st.spec.cellVolume());
  compact.bodyWeight = dt2 * st.spec.cellVolume();
  bodies.resize(coupled.size());
  for (std::size_t k = 0; k < coupled.size(); ++k) bodyColumns(st, *coupled[k], faces[k], bodies[k]);
}

void StressProblem::bodyColumns(const GranularGridState& st, const CoupledBody& body,
                                const std::vector<BodyFace>& faces, BodyColumns& out) const {
  out.inverseMass = body.inverseMass;
  out.sample.clear();
  out.column.clear();
  const double invDx = 1.0 / st.spec.dx;
  // Only the faces some term's divergence acts on have columns.
  std::array<bool, 3> acts{};
  for (int a = 0; a < 3; ++a)
    acts[static_cast<std::size_t>(a)] = std::any_of(terms.begin(), terms.end(), [&](const StressTerm& t) {
      return t.c.a == a || (!t.c.diagonal() && t.c.b == a);
    });
  for (const BodyFace& f : faces) {
    if (!acts[static_cast<std::size_t>(f.axis)]) continue;
    for (const StressTerm& t : terms)
      forEachFaceSample(t.c, lattice, f.axis, f.face, [&](std::size_t q, double sign) {
        Vec6 g = f.direction;
        g *= f.fraction * invDx;
        out.sample.push_back(q);
        out.column.push_back(t.sign * sign * g);
      });
  }
}

StressProblem::FreeSamples StressProblem::freeSamples() const { return freeSamples(LatticeBox::whole(lattice)); }

StressProblem::FreeSamples StressProblem::freeSamples(const LatticeBox& within) const {
  // One slice of the slowest axis per task.
  const FreeSamples none{LatticeBox{lattice, IVec3::Constant(-1)}, 0};
  if (within.empty()) return none;
  return tbb::parallel_reduce(
      tbb::blocked_range<int>(within.first[2], within.last[2] + 1), none,
      [&](const tbb::blocked_range<int>& r, FreeSamples found) {
        for (int k = r.begin(); k != r.end(); ++k)
          for (int j = within.first[1]; j <= within.last[1]; ++j)
            for (int i = within.first[0]; i <= within.last[0]; ++i) {
              const Eigen::Index q = (static_cast<Eigen::Index>(k) * lattice[1] + j) * lattice[0] + i;
              if (!(lo[q] < hi[q])) continue;
              found.box.first = found.box.first.cwiseMin(IVec3(i, j, k));
              found.box.last = found.box.last.cwiseMax(IVec3(i, j, k));
              ++found.count;
            }
        return found;
      },
      [](const FreeSamples& a, const FreeSamples& b) {
        return FreeSamples{LatticeBox{a.box.first.cwiseMin(b.box.first), a.box.last.cwiseMax(b.box.last)},
                           a.count + b.count};
      });
}

int StressProblem::solve(numerics::BoundQpSettings settings, double absoluteFloor) {
  return solve(freeSamples(), settings, absoluteFloor);
}

int StressProblem::solve(const FreeSamples& found, numerics::BoundQpSettings settings, double absoluteFloor,
                         double referenceNorm) {
  x = x.cwiseMax(lo).cwiseMin(hi);
  if (found.box.empty()) return 0;
  const double boxSize = (found.box.last - found.box.first + IVec3::Ones()).cast<double>().prod();
  // The box's structured stencil is cheaper per sample than the listed rows (no indirection).
  if (static_cast<double>(found.count) < 0.5 * boxSize) return solveOnFreeSamples(found.count, settings, absoluteFloor, referenceNorm);
  return solveOnBox(found.box.first, found.box.last, found.count, settings, absoluteFloor, referenceNorm);
}

void StressProblem::holdInertSamples() {
  const std::size_t n = static_cast<std::size_t>(lattice.prod());
  bodySample_.assign(n, 0);
  for (const BodyColumns& body : bodies)
    for (std::size_t q : body.sample) bodySample_[q] = 1;
  parallelFor(0, n, [&](std::size_t i) {
    const Eigen::Index e = static_cast<Eigen::Index>(i);
    if (decoupled[i] && !bodySample_[i] && lo[e] == 0.0 && b[e] <= 0.0) hi[e] = 0.0;
  }, 4096);
}

void StressProblem::applyFloor(numerics::BoundQpSettings& settings, double absoluteFloor, double referenceNorm,
                               std::size_t n, double bNorm) {
  if (referenceNorm > 0.0 && bNorm > 0.0) settings.tolerance *= referenceNorm / bNorm;
  if (absoluteFloor > 0.0 && bNorm > 0.0)
    settings.tolerance = std::max(settings.tolerance, absoluteFloor * std::sqrt(static_cast<double>(n)) / bNorm);
}

int StressProblem::solveOnBox(const IVec3& first, const IVec3& last, std::size_t freeCount,
                              numerics::BoundQpSettings settings, double absoluteFloor, double referenceNorm) {
  const IVec3 box = last - first + IVec3::Ones();
  const std::size_t m = static_cast<std::size_t>(box.prod());
  for (auto& l : boxLower) l.resize(m);
  boxDiagonal.resize(m);
  boxToLattice.resize(m);
  subB.resize(static_cast<Eigen::Index>(m));
  subLo.resize(static_cast<Eigen::Index>(m));
  subHi.resize(static_cast<Eigen::Index>(m));
  subX.resize(static_cast<Eigen::Index>(m));
  parallelForCells<3>(box, [&](const IVec3& c, std::size_t k) {
    const std::size_t q =
        (static_cast<std::size_t>(c[2] + first[2]) * lattice[1] + c[1] + first[1]) * lattice[0] + c[0] + first[0];
    boxToLattice[k] = q;
    for (int a = 0; a < 3; ++a) boxLower[a][k] = lower[a][q];
    boxDiagonal[k] = diagonal[q];
    const Eigen::Index e = static_cast<Eigen::Index>(k), f = static_cast<Eigen::Index>(q);
    subB[e] = b[f];
    subLo[e] = lo[f];
    subHi[e] = hi[f];
    subX[e] = x[f];
  });
  op.grid().assign(box, boxLower, boxDiagonal);
  op.bodies().resize(bodies.size());
  for (std::size_t body = 0; body < bodies.size(); ++body) {
    BodyColumns& boxed = op.bodies()[body];
    boxed.inverseMass = bodies[body].inverseMass;
    boxed.sample.clear();
    boxed.column.clear();
    for (std::size_t j = 0; j < bodies[body].sample.size(); ++j) {
      const std::size_t q = bodies[body].sample[j];
      const int qx = static_cast<int>(q % lattice[0]), qy = static_cast<int>(q / lattice[0] % lattice[1]),
                qz = static_cast<int>(q / lattice[0] / lattice[1]);
      const IVec3 c = IVec3(qx, qy, qz) - first;
      if ((c.array() < 0).any() || (c.array() >= box.array()).any()) continue;
      boxed.sample.push_back((static_cast<std::size_t>(c[2]) * box[1] + c[1]) * box[0] + c[0]);
      boxed.column.push_back(bodies[body].column[j]);
    }
  }
  applyFloor(settings, absoluteFloor, referenceNorm, freeCount, subB.norm());
  // MPRGP's built-in Jacobi preconditioning: MIC(0) in face (numerics/bound_qp_mic0) takes about
  // as many iterations here, and the box bounds change the face so often that its sequential
  // refactorisations made the friction solves 4x slower (sand bed 25 x 50 x 25: 1.25 -> 0.32 s).
  const auto r = solver.solve(op, subB, subLo, subHi, subX, settings);
  parallelFor(0, m, [&](std::size_t j) { x[static_cast<Eigen::Index>(boxToLattice[j])] = subX[static_cast<Eigen::Index>(j)]; }, 4096);
  return r.iterations;
}

int StressProblem::solveOnFreeSamples(std::size_t freeCount, numerics::BoundQpSettings settings, double absoluteFloor,
                                      double referenceNorm) {
  const std::size_t n = static_cast<std::size_t>(lattice.prod());
  // Number the free samples in lattice order (a sequential scan: the numbering must not depend on
  // the thread count).
  latticeToFree.resize(n);
  freeToLattice.resize(freeCount);
  std::uint32_t next = 0;
  for (std::size_t q = 0; q < n; ++q) {
    const Eigen::Index e = static_cast<Eigen::Index>(q);
    latticeToFree[q] = lo[e] < hi[e] ? static_cast<std::int32_t>(next) : -1;
    if (lo[e] < hi[e]) freeToLattice[next++] = static_cast<std::uint32_t>(q);
  }
  const Eigen::Index m = static_cast<Eigen::Index>(freeCount);
  compact.rows.resize(freeCount);
  compact.diagonalValues.resize(freeCount);
  subB.resize(m);
  subLo.resize(m);
  subHi.resize(m);
  subX.resize(m);
  const std::array<std::size_t, 3> stride = {1, static_cast<std::size_t>(lattice[0]),
                                             static_cast<std::size_t>(lattice[0]) * static_cast<std::size_t>(lattice[1])};
  parallelFor(0, freeCount, [&](std::size_t i) {
    const std::size_t q = freeToLattice[i];
    const IVec3 c(static_cast<int>(q % stride[1]), static_cast<int>(q / stride[1] % static_cast<std::size_t>(lattice[1])),
                  static_cast<int>(q / stride[2]));
    CompactCoupledOperator::Row& row = compact.rows[i];
    double rhs = b[static_cast<Eigen::Index>(q)];
    int link = 0;
    auto connect = [&](std::size_t neighbour, double w) {
      const std::int32_t j = latticeToFree[neighbour];
      if (j >= 0) {
        row.neighbour[static_cast<std::size_t>(link)] = static_cast<std::uint32_t>(j);
        row.weight[static_cast<std::size_t>(link++)] = w;
      } else {
        rhs += w * x[static_cast<Eigen::Index>(neighbour)];  // -A_ij x_j of a held sample
      }
    };
    for (int a = 0; a < 3; ++a) {
      if (c[a] > 0) connect(q - stride[a], lower[a][q]);
      if (c[a] + 1 < lattice[a]) connect(q + stride[a], lower[a][q + stride[a]]);
    }
    for (; link < 6; ++link) {
      row.neighbour[static_cast<std::size_t>(link)] = static_cast<std::uint32_t>(i);
      row.weight[static_cast<std::size_t>(link)] = 0.0;
    }
    compact.diagonalValues[i] = diagonal[q];
    const Eigen::Index e = static_cast<Eigen::Index>(i), f = static_cast<Eigen::Index>(q);
    subB[e] = rhs;
    subLo[e] = lo[f];
    subHi[e] = hi[f];
    subX[e] = x[f];
  }, 1024);
  // Bodies: the columns of the free samples; the held samples' share of J x moves to b.
  compact.bodies.resize(bodies.size());
  for (std::size_t body = 0; body < bodies.size(); ++body) {
    const BodyColumns& all = bodies[body];
    BodyColumns& listed = compact.bodies[body];
    listed.inverseMass = all.inverseMass;
    listed.sample.clear();
    listed.column.clear();
    Vec6 held = Vec6::Zero();
    for (std::size_t j = 0; j < all.sample.size(); ++j) {
      const std::int32_t i = latticeToFree[all.sample[j]];
      if (i >= 0) {
        listed.sample.push_back(static_cast<std::size_t>(i));
        listed.column.push_back(all.column[j]);
      } else {
        held += all.column[j] * x[static_cast<Eigen::Index>(all.sample[j])];
      }
    }
    const Vec6 f = compact.bodyWeight * (all.inverseMass * held);
    for (std::size_t k = 0; k < listed.sample.size(); ++k)
      subB[static_cast<Eigen::Index>(listed.sample[k])] -= listed.column[k].dot(f);
  }
  applyFloor(settings, absoluteFloor, referenceNorm, freeCount, subB.norm());
  const auto r = solver.solve(compact, subB, subLo, subHi, subX, settings);
  parallelFor(0, freeCount, [&](std::size_t i) {
    x[static_cast<Eigen::Index>(freeToLattice[i])] = subX[static_cast<Eigen::Index>(i)];
  }, 4096);
  return r.iterations;
}

void CompactCoupledOperator::apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  parallelFor(0, rows.size(), [&](std::size_t i) {
    const Row& row = rows[i];
    double s = diagonalValues[i] * x[static_cast<Eigen::Index>(i)];
    for (int k = 0; k < 6; ++k) s -= row.weight[static_cast<std::size_t>(k)] * x[static_cast<Eigen::Index>(row.neighbour[static_cast<std::size_t>(k)])];
    y[static_cast<Eigen::Index>(i)] = s;
  }, 2048);
  addBodyProducts(bodies, bodyWeight, x, y);
}

void CompactCoupledOperator::diagonal(Eigen::VectorXd& d) const {
  d = Eigen::Map<const Eigen::VectorXd>(diagonalValues.data(), static_cast<Eigen::Index>(diagonalValues.size()));
  addBodyDiagonal(bodies, bodyWeight, d);
}

double CompactCoupledOperator::normUpperBound() const {
  const double grid = parallelMax(rows.size(), [&](std::size_t i) {
    double sum = diagonalValues[i];
    for (double w : rows[i].weight) sum += std::abs(w);
    return sum;
  });
  return grid + bodyNormBound(bodies, bodyWeight);
}

void addBodyProducts(const std::vector<BodyColumns>& bodies, double weight, const Eigen::VectorXd& x,
                     Eigen::VectorXd& y) {
  for (const BodyColumns& b : bodies) {
    const Vec6 f = weight * (b.inverseMass * b.apply(x));
    for (std::size_t k = 0; k < b.sample.size(); ++k) y[static_cast<Eigen::Index>(b.sample[k])] += b.column[k].dot(f);
  }
}

void addBodyDiagonal(const std::vector<BodyColumns>& bodies, double weight, Eigen::VectorXd& d) {
  for (const BodyColumns& b : bodies)
    for (std::size_t k = 0; k < b.sample.size(); ++k)
      d[static_cast<Eigen::Index>(b.sample[k])] += weight * b.column[k].dot(b.inverseMass * b.column[k]);
}

double bodyNormBound(const std::vector<BodyColumns>& bodies, double weight) {
  // A body's term is weight C^T M^-1 C, C the 6 x n matrix of its samples' columns (a sample's
  // entries summed); its norm is that of the 6 x 6 matrix weight M^-1/2 (C C^T) M^-1/2, computed
  // exactly. (A Gershgorin-type bound was orders of magnitude looser for light bodies, and MPRGP's
  // expansion steps, 1.9 / ||A||, shrank with it.) The sum over bodies bounds their sum.
  double bound = 0.0;
  std::vector<std::pair<std::size_t, Vec6>> entries;
  for (const BodyColumns& b : bodies) {
    entries.clear();
    for (std::size_t k = 0; k < b.sample.size(); ++k) entries.emplace_back(b.sample[k], b.column[k]);
    std::sort(entries.begin(), entries.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    Mat6 gram = Mat6::Zero();
    for (std::size_t k = 0; k < entries.size();) {
      Vec6 column = Vec6::Zero();
      const std::size_t sample = entries[k].first;
      for (; k < entries.size() && entries[k].first == sample; ++k) column += entries[k].second;
      gram.noalias() += column * column.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Mat6> mass(b.inverseMass);  // M^-1: symmetric, >= 0
    const Mat6 root = mass.eigenvectors() * mass.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal() *
                      mass.eigenvectors().transpose();
    const Eigen::SelfAdjointEigenSolver<Mat6> term(root * gram * root, Eigen::EigenvaluesOnly);
    bound += weight * std::max(term.eigenvalues().maxCoeff(), 0.0);
  }
  return bound;
}

// Sum over terms of sign * D_term x, added into force (per unit volume).
void addTerms(const std::vector<StressTerm>& terms, const std::vector<double>& x, double scale, double dx,
              const FaceField& mask, FaceField& force) {
  for (const StressTerm& t : terms) addDivergence(t.c, x, scale * t.sign, dx, mask, force);
}

void addTerms(const std::vector<StressTerm>& terms, const std::vector<double>& x, double scale, double dx,
              const FaceField& mask, FaceField& force, const LatticeBox& samples) {
  for (const StressTerm& t : terms) addDivergence(t.c, x, scale * t.sign, dx, mask, force, samples);
}

void transposeTerms(const std::vector<StressTerm>& terms, const FaceField& u, double dx, const FaceField& mask,
                    std::vector<double>& out, std::vector<double>& tmp) {
  out.assign(static_cast<std::size_t>(latticeSize(terms.front().c, u.res).prod()), 0.0);
  transposeTerms(terms, u, dx, mask, out, tmp, LatticeBox::whole(latticeSize(terms.front().c, u.res)));
}

void transposeTerms(const std::vector<StressTerm>& terms, const FaceField& u, double dx, const FaceField& mask,
                    std::vector<double>& out, std::vector<double>& tmp, const LatticeBox& samples) {
  const IVec3 lattice = latticeSize(terms.front().c, u.res);
  out.resize(static_cast<std::size_t>(lattice.prod()));
  if (samples.empty()) return;
  const std::size_t width = static_cast<std::size_t>(samples.last[0] - samples.first[0] + 1);
  forBoxRows(samples, lattice, [&](std::size_t row, int, int) { std::fill_n(out.begin() + row, width, 0.0); });
  for (const StressTerm& t : terms) {
    divergenceTranspose(t.c, u, dx, mask, tmp, samples);
    forBoxRows(samples, lattice, [&](std::size_t row, int, int) {
      for (std::size_t i = row; i < row + width; ++i) out[i] += t.sign * tmp[i];
    });
  }
}

std::array<LatticeBox, 3> termFaces(const std::vector<StressTerm>& terms, const LatticeBox& samples, const IVec3& cells) {
  std::array<LatticeBox, 3> faces;
  for (const StressTerm& t : terms)
    for (int a = 0; a < 3; ++a) faces[static_cast<std::size_t>(a)] = faces[static_cast<std::size_t>(a)].unite(facesReading(t.c, samples, cells, a));
  return faces;
}

}  // namespace msim::granular
