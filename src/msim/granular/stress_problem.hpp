#pragma once
// One quadratic program of the granular stress (Narain 2011 eqs. 5.13, 5.20, 5.44-5.46 with the
// body terms of 5.25-5.26): a stress variable on its lattice (stress_lattice.hpp), the operator
// dt^2 (D^T W D + V sum_bodies J^T M^-1 J), bounds, and its MPRGP solve on the box of the samples
// that can move, or on the list of those samples when they fill less than half of the box. The
// staggered sequence of these problems is stress_solver.hpp.
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "msim/granular/grid_state.hpp"
#include "msim/granular/stress_lattice.hpp"
#include "msim/numerics/bound_qp.hpp"
#include "msim/numerics/bound_qp_mic0.hpp"

namespace msim::granular {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// A stress variable acting through one or two components with a sign: the pressure is
// -(D_x + D_y + D_z) p, the pair of ch. 5.5.1 is s_xx = -s_yy / 2 + d, s_zz = -s_yy / 2 - d, so d
// acts as +D_xx - D_zz; the others act as themselves.
struct StressTerm {
  StressComponent c;
  double sign;
};

// The rank-6 part of a body: J x = sum_q column[q] x_q over the samples its faces touch
// (J = G Phi_s D of eqs. 5.21/5.22, G_f = [e_a; r_f x e_a] the generalized direction of face f).
struct BodyColumns {
  std::vector<std::size_t> sample;
  std::vector<Vec6> column;
  Mat6 inverseMass;
  Vec6 apply(const Eigen::VectorXd& x) const {
    Vec6 y = Vec6::Zero();
    for (std::size_t k = 0; k < sample.size(); ++k) y += column[k] * x[static_cast<Eigen::Index>(sample[k])];
    return y;
  }
};

// The bodies' part of an operator, V_c sum_b J_b^T M_b^-1 J_b times `weight`: y += it x, d += its
// diagonal, and a bound of its norm (the sum of the bodies' exact norms).
void addBodyProducts(const std::vector<BodyColumns>& bodies, double weight, const Eigen::VectorXd& x,
                     Eigen::VectorXd& y);
void addBodyDiagonal(const std::vector<BodyColumns>& bodies, double weight, Eigen::VectorXd& d);
double bodyNormBound(const std::vector<BodyColumns>& bodies, double weight);

// dt^2 (D^T W D + V_c sum_b J_b^T M_b^-1 J_b): the grid Poisson part plus the bodies.
class CoupledOperator final : public numerics::QpOperator {
 public:
  CoupledOperator() : grid_(IVec3::Ones(), {std::vector<double>(1, 0.0), {0.0}, {0.0}}, {1.0}) {}
  numerics::GridPoissonQpOperator<3>& grid() { return grid_; }
  std::vector<BodyColumns>& bodies() { return bodies_; }
  void setBodyWeight(double w) { bodyWeight_ = w; }

  Eigen::Index size() const override { return grid_.size(); }
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override {
    grid_.apply(x, y);
    addBodyProducts(bodies_, bodyWeight_, x, y);
  }
  void diagonal(Eigen::VectorXd& d) const override {
    grid_.diagonal(d);
    addBodyDiagonal(bodies_, bodyWeight_, d);
  }
  double normUpperBound() const override { return grid_.normUpperBound() + bodyNormBound(bodies_, bodyWeight_); }

 private:
  numerics::GridPoissonQpOperator<3> grid_;
  std::vector<BodyColumns> bodies_;
  double bodyWeight_ = 0.0;
};

// The same operator restricted to a list of samples (those free to move): each row is its
// diagonal and up to six links to other listed samples (an absent link points at the row itself
// with weight 0, so the product has no branches), plus the bodies.
class CompactCoupledOperator final : public numerics::QpOperator {
 public:
  struct Row {
    std::array<std::uint32_t, 6> neighbour;
    std::array<double, 6> weight;  // A_ij = -weight
  };
  std::vector<double> diagonalValues;
  std::vector<Row> rows;
  std::vector<BodyColumns> bodies;  // in listed-sample indices
  double bodyWeight = 0.0;

  Eigen::Index size() const override { return static_cast<Eigen::Index>(rows.size()); }
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override;
  void diagonal(Eigen::VectorXd& d) const override;
  double normUpperBound() const override;
};

// One quadratic program of the staggered sequence, with its storage kept between steps.
struct StressProblem {
  std::vector<StressTerm> terms;
  IVec3 lattice = IVec3::Zero();
  std::array<std::vector<double>, 3> lower, part;  // the whole lattice's stencil
  std::vector<double> diagonal, partDiagonal;
  std::vector<std::uint8_t> decoupled;  // per sample: no face weight reaches it (from build)
  std::vector<BodyColumns> bodies;  // J of each body, in whole-lattice sample indices
  Eigen::VectorXd b, lo, hi, x;     // whole lattice
  // The solve runs on a box of the lattice or on the list of its free samples (see solve()).
  CoupledOperator op;               // box
  CompactCoupledOperator compact;   // list
  numerics::BoundQpSolver solver;
  std::array<std::vector<double>, 3> boxLower;
  std::vector<double> boxDiagonal;
  std::vector<std::size_t> boxToLattice;
  Eigen::VectorXd subB, subLo, subHi, subX;  // the restricted problem (box or list)
  std::vector<std::uint32_t> freeToLattice;
  std::vector<std::int32_t> latticeToFree;  // -1 for samples held at a bound

  // Builds dt^2 (sum_terms D^T W D) for face weights W, and the bodies' columns from their faces
  // (faces[k]: collectBodyFaces of coupled[k]).
  void build(const GranularGridState& st, const FaceField& weight, double dt,
             const std::vector<const CoupledBody*>& coupled, const std::vector<std::vector<BodyFace>>& faces);
  void bodyColumns(const GranularGridState& st, const CoupledBody& body, const std::vector<BodyFace>& faces,
                   BodyColumns& out) const;
  // Solves on the bounding box of the samples whose bounds leave room (lo < hi): the others are
  // fixed at their bound, which is 0 for the friction (no pressure, no friction) - the friction
  // lives only where the material is packed, often a small part of the grid. Samples outside the
  // box count as Dirichlet neighbours at 0 (the stencil keeps their links in the diagonal).
  // When fewer than half the samples of the box are free, the solve runs on the list of free
  // samples instead (CompactCoupledOperator), with the held ones' products moved to b.
  // absoluteFloor: a projected-gradient norm per sqrt(free sample) below which the solve stops
  // even if the relative tolerance is not met (0: relative only). Returns the MPRGP iterations.
  int solve(numerics::BoundQpSettings settings, double absoluteFloor = 0.0);
  // The samples with room (lo < hi): their bounding box and their number. A solve sets x to its
  // bounds outside the box (0 for the friction) and reads b only inside it.
  struct FreeSamples {
    LatticeBox box;
    std::size_t count = 0;
  };
  FreeSamples freeSamples() const;
  // The same when every sample with room lies in `within`.
  FreeSamples freeSamples(const LatticeBox& within) const;
  // Symmetric bounds -bound(i, q) <= x_i <= bound(i, q) for the samples q (index i) in `box`, 0
  // elsewhere (the friction's, eq. 5.15). Only the box and the last call's box are visited.
  template <typename Bound>
  void setBounds(const LatticeBox& box, const Bound& bound);
  // Where the last setBounds may have left nonzero bounds.
  const LatticeBox& boundsBox() const { return boundsBox_; }
  // solve() with the free samples already found (freeSamples() of the current bounds).
  // referenceNorm > 0: the relative tolerance refers to this norm of b instead of the norm over
  // the samples solved for (holdInertSamples keeps the threshold of the whole grid so).
  int solve(const FreeSamples& found, numerics::BoundQpSettings settings, double absoluteFloor = 0.0,
            double referenceNorm = 0.0);
  // Holds at 0 the samples whose solution is 0 whatever the others do: decoupled (no face weight,
  // no body), lower bound 0 and b <= 0 (their own term 1/2 d x^2 - b x is least at 0 on x >= 0).
  // In the pressure problems these are the cells without material around them, most of the grid
  // in a splash or a collapsing column; the solve then runs on the rest.
  void holdInertSamples();

 private:
  int solveOnBox(const IVec3& first, const IVec3& last, std::size_t freeCount, numerics::BoundQpSettings settings,
                 double absoluteFloor, double referenceNorm);
  int solveOnFreeSamples(std::size_t freeCount, numerics::BoundQpSettings settings, double absoluteFloor,
                         double referenceNorm);
  // The relative tolerance referred to referenceNorm (if > 0) and raised to the absolute floor for
  // n free samples (see solve()); bNorm: the norm of the restricted problem's b.
  static void applyFloor(numerics::BoundQpSettings& settings, double absoluteFloor, double referenceNorm, std::size_t n,
                         double bNorm);
  LatticeBox boundsBox_;                  // setBounds
  std::vector<std::uint8_t> bodySample_;  // holdInertSamples scratch
};

template <typename Bound>
void StressProblem::setBounds(const LatticeBox& box, const Bound& bound) {
  const Eigen::Index n = static_cast<Eigen::Index>(lattice.prod());
  if (lo.size() != n || hi.size() != n) {
    lo = Eigen::VectorXd::Zero(n);
    hi = Eigen::VectorXd::Zero(n);
    boundsBox_ = {};
  }
  const std::size_t width = static_cast<std::size_t>(std::max(0, box.last[0] - box.first[0] + 1));
  forBoxRows(boundsBox_, lattice, [&](std::size_t row, int, int) {
    const std::size_t oldWidth = static_cast<std::size_t>(boundsBox_.last[0] - boundsBox_.first[0] + 1);
    for (std::size_t i = row; i < row + oldWidth; ++i) lo[static_cast<Eigen::Index>(i)] = hi[static_cast<Eigen::Index>(i)] = 0.0;
  });
  forBoxRows(box, lattice, [&](std::size_t row, int y, int z) {
    for (std::size_t k = 0; k < width; ++k) {
      const double b = bound(row + k, IVec3(box.first[0] + static_cast<int>(k), y, z));
      lo[static_cast<Eigen::Index>(row + k)] = -b;
      hi[static_cast<Eigen::Index>(row + k)] = b;
    }
  });
  boundsBox_ = box;
}

// Sum over terms of sign * D_term x, added into force (per unit volume).
void addTerms(const std::vector<StressTerm>& terms, const std::vector<double>& x, double scale, double dx,
              const FaceField& mask, FaceField& force);
// The same for an x that is 0 outside `samples`: only the faces reading those samples change.
void addTerms(const std::vector<StressTerm>& terms, const std::vector<double>& x, double scale, double dx,
              const FaceField& mask, FaceField& force, const LatticeBox& samples);
// out = sum over terms of sign * D_term^T u (tmp: scratch).
void transposeTerms(const std::vector<StressTerm>& terms, const FaceField& u, double dx, const FaceField& mask,
                    std::vector<double>& out, std::vector<double>& tmp);
// The same for the samples in `samples` only (out sized to the lattice, its other entries left
// as they were); reads u on the faces of termFaces(terms, samples, ...) only.
void transposeTerms(const std::vector<StressTerm>& terms, const FaceField& u, double dx, const FaceField& mask,
                    std::vector<double>& out, std::vector<double>& tmp, const LatticeBox& samples);
// Per axis, the faces whose divergence of the terms reads a sample in `samples`.
std::array<LatticeBox, 3> termFaces(const std::vector<StressTerm>& terms, const LatticeBox& samples, const IVec3& cells);

}  // namespace msim::granular
