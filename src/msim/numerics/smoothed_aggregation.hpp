#pragma once
// Smoothed-aggregation algebraic multigrid (Vanek, Mandel & Brezina 1996, "Algebraic multigrid by
// smoothed aggregation for second and fourth order elliptic problems") as a preconditioner for
// conjugate gradients on symmetric positive definite systems whose unknowns come in blocks of b
// per node (b = 3 for the velocity of a particle). It needs no grid: the hierarchy comes from the
// matrix alone, so it serves meshes of any shape.
//
// Setup, level by level: nodes are grouped into aggregates of strongly connected neighbours
// (||A_ij|| >= theta sqrt(||A_ii|| ||A_jj||), block Frobenius norms); the tentative prolongator P0
// gives each aggregate a coarse unknown per near-null mode, the mode restricted to its nodes and
// orthonormalised (by default the constants of each component, the translations, which diffusion
// and springs leave unresisted; for springs in 3D also the rotations, which springs that are not
// stretched barely resist: without them the coarse levels cannot follow a slack or folded sheet);
// one damped block-Jacobi step smooths it, P = (I - omega D^-1 A) P0 with
// omega = 4 / (3 rho(D^-1 A)); the coarse matrix is the Galerkin product P^T A P. Coarsening stops
// at a few nodes, solved directly (sparse LDL^T). Nodes without strong neighbours (a pinned
// particle's identity row) stay out of the coarse levels: the smoother alone solves their rows.
//
// apply() is one V-cycle with the same number of damped block-Jacobi sweeps before and after each
// coarse correction, a symmetric positive definite operator as conjugate gradients need.
#include <memory>
#include <vector>

#include <Eigen/SparseCholesky>
#include <Eigen/Sparse>

#include "msim/numerics/block_jacobi.hpp"

namespace msim::numerics {

struct AggregationSettings {
  int blockSize = 1;                // unknowns per node on the finest level, 1-6
  double strengthThreshold = 0.08;  // theta of the strong-connection test (the paper's epsilon)
  int coarsestNodes = 64;           // a level with at most this many nodes is solved directly
  int maxLevels = 16;
  int smoothingSweeps = 1;          // damped block-Jacobi sweeps before and after each coarse correction
};

class SmoothedAggregation {
 public:
  using Matrix = SparseRowMatrix;

  explicit SmoothedAggregation(const AggregationSettings& settings = {});

  // Builds the hierarchy for A (square, symmetric positive definite, its size a multiple of the
  // block size); std::invalid_argument otherwise. nearNullSpace: 1-6 columns, a row per unknown,
  // the motions A barely resists (for springs in 3D the three translations and three rotations,
  // rigidModes); each aggregate gets as many coarse unknowns. Empty: the b translations.
  void setup(const Matrix& A, const Eigen::MatrixXd& nearNullSpace = {});
  bool ready() const { return !levels_.empty(); }
  // z = one V-cycle on r, an approximation of A^-1 r (setup first).
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;

  int levels() const { return static_cast<int>(levels_.size()); }
  // Nonzeros of all levels over those of the finest: the work of a cycle relative to a product with A.
  double operatorComplexity() const;

 private:
  struct Level {
    Matrix A;
    int blockSize = 1;                  // unknowns per node: b on the finest level, the modes' count below
    Matrix P, R;                        // prolongation from the next coarser level, and its transpose
    BlockJacobi jacobi;                 // D^-1 of the b x b diagonal blocks
    double weight = 0.0;                // the smoother's damping, 4 / (3 rho(D^-1 A))
    mutable Eigen::VectorXd x, b, residual, correction;
  };

  void cycle(std::size_t level) const;
  void smooth(const Level& level) const;  // x += weight D^-1 (b - A x)

  AggregationSettings settings_;
  std::vector<Level> levels_;
  std::unique_ptr<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>> coarsest_;  // null: the coarsest is smoothed
};

// The six rigid motions of points in 3D, a row per coordinate (3 per point): the three translations
// and the rotations about the axes through `center`, the near-null space of springs.
Eigen::MatrixXd rigidModes(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& center);

}  // namespace msim::numerics
