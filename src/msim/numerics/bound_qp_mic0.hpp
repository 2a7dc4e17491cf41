#pragma once
// MIC(0) preconditioning "in face" for MPRGP on face-weighted grid Poisson operators.
//
// Narain (2011, ch. 4.4) solves the crowd pressure LCP with MPRGP (Dostál & Schöberl, Comput.
// Optim. Appl. 30:23-43, 2005) preconditioned by MIC(0). MPRGP preconditions only its CG steps,
// and only on the current face: z_F = M_FF^{-1} g_F with M_FF a preconditioner of the reduced
// matrix A_FF (Dostál, Optimal Quadratic Programming Algorithms, 2009). A_FF of a grid Poisson
// matrix is again a grid Poisson matrix whose couplings to the held (p = 0) cells are removed,
// so its modified incomplete Cholesky factor is Bridson's MIC(0) (Bridson & Mueller-Fischer,
// SIGGRAPH 2007 fluid notes, fig. 4.2) on the free cells with those couplings dropped; it removes
// most of the low-frequency error that Jacobi leaves, which is what limits MPRGP's CG phases.
//
// The stencil is given as D + 1 arrays over the cells (x fastest, as MacGrid/Grid lay them out):
// lowerWeight[a][i] >= 0 is the weight w of the face between cell i and i - e_a (for cells on
// the lower domain side, the boundary face: it only enters the diagonal), and diagonal[i] > 0.
// The operator is
//   (A x)_i = diagonal[i] x_i - sum_a w_a(i) x_{i - e_a} - sum_a w_a(i + e_a) x_{i + e_a},
// with the neighbours outside the grid dropped (Dirichlet faces and solid walls are folded into
// the diagonal by the caller), e.g. PoissonMatrix<D>'s lowerWeight() and diag() in double.
// msim_numerics cannot link msim_pressure, so this header is self-contained.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/numerics/bound_qp.hpp"

namespace msim::numerics {

// The matrix-free operator above as a QpOperator for BoundQpSolver.
template <int D>
class GridPoissonQpOperator final : public QpOperator {
 public:
  // Throws std::invalid_argument unless every res[a] >= 1, every array has prod(res) entries,
  // the weights are >= 0 and the diagonal is > 0.
  GridPoissonQpOperator(const IVec<D>& res, std::array<std::vector<double>, D> lowerWeight,
                        std::vector<double> diagonal);
  Eigen::Index size() const override { return static_cast<Eigen::Index>(diagonal_.size()); }
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override;
  void diagonal(Eigen::VectorXd& d) const override;
  // Gershgorin: max_i (|a_ii| + sum_j |a_ij|).
  double normUpperBound() const override { return normBound_; }
  // Replaces the stencil by one of the same resolution, copying into the existing storage (no
  // allocation), for operators that change every time step (e.g. the crowd pressure, whose face
  // weights are the density). Same checks as the constructor.
  void assign(const std::array<std::vector<double>, D>& lowerWeight, const std::vector<double>& diagonal);
  // The same for a stencil of another resolution (e.g. the bounding box of the cells a problem
  // needs): the storage only grows past its largest size so far.
  void assign(const IVec<D>& res, const std::array<std::vector<double>, D>& lowerWeight,
              const std::vector<double>& diagonal);
  const IVec<D>& resolution() const { return res_; }

 private:
  void computeNormBound();

  IVec<D> res_;
  std::array<std::size_t, D> stride_{};
  std::array<std::vector<double>, D> lower_;
  std::vector<double> diagonal_;
  double normBound_ = 0.0;
};

struct GridMic0Settings {
  double tau = 0.97;    // fraction of the dropped fill-in moved onto the diagonal (Bridson)
  double sigma = 0.25;  // a pivot below sigma * A_ii falls back to A_ii (Bridson's safety factor)
};

// M_FF = L L^T, the MIC(0) factor of A_FF. setFace() compares the mask (O(n)) and, only when it
// differs from the last one, rebuilds the list of free cells and refactors over them (O(|F|); no
// allocation after construction): MPRGP announces a face after every expansion and proportioning
// step, and the face often does not change. apply() is a forward and a backward triangular solve
// over the free cells only, sequential in x-fastest order, O(|F|) plus clearing z.
template <int D>
class GridMic0FacePreconditioner final : public QpFacePreconditioner {
 public:
  // Same stencil data and checks as GridPoissonQpOperator; throws std::invalid_argument also for
  // tau outside [0, 1] or sigma outside [0, 1]. Until the first setFace() every cell is free.
  GridMic0FacePreconditioner(const IVec<D>& res, std::array<std::vector<double>, D> lowerWeight,
                             std::vector<double> diagonal, const GridMic0Settings& settings = {});
  // Throws std::invalid_argument if free.size() differs from the number of cells.
  void setFace(const std::vector<std::uint8_t>& free) override;
  // z_F = (L L^T)^{-1} g_F, z = 0 off the face. g and z must have one entry per cell.
  void apply(const Eigen::VectorXd& g, Eigen::VectorXd& z) override;
  // Number of factorisations so far (the constructor's included); setFace() with an unchanged
  // mask does not add one.
  int factorizations() const { return factorizations_; }
  // Replaces the stencil (same resolution, no allocation; same checks as the constructor). The
  // factor is rebuilt lazily, on the next setFace() or apply(), whatever the mask.
  void assign(const std::array<std::vector<double>, D>& lowerWeight, const std::vector<double>& diagonal);
  // The same for a stencil of another resolution; a new resolution frees every cell (as after
  // construction). The storage only grows past its largest size so far.
  void assign(const IVec<D>& res, const std::array<std::vector<double>, D>& lowerWeight,
              const std::vector<double>& diagonal);

 private:
  void factor();
  // freeList_ and neighbours_ from free_ (one pass in cell order).
  void listFreeCells();

  IVec<D> res_;
  std::array<std::size_t, D> stride_{};
  std::array<std::vector<double>, D> lower_;
  std::vector<double> diagonal_;
  GridMic0Settings settings_;
  std::vector<std::uint8_t> free_;
  std::vector<double> precon_;  // 1 / L_ii on the face, 0 off it
  std::vector<std::size_t> freeList_;  // the free cells in increasing order
  // Per free cell, which neighbours exist: bit a the lower one on axis a, bit D + a the upper one
  // (kept with the list, so the sweeps need no coordinates, i.e. no divisions).
  std::vector<std::uint8_t> neighbours_;
  std::vector<double> q_;       // L q = g (meaningful on the face only)
  int factorizations_ = 0;
  bool stale_ = false;          // stencil replaced since the last factorisation
};

}  // namespace msim::numerics
