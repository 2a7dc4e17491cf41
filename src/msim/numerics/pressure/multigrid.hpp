#pragma once
// MultigridPreconditioner<D>: one geometric multigrid V-cycle as the preconditioner of CG
// (MGPCG, after McAdams, Sifakis & Teran 2010), for the face-weighted Poisson matrix.
//
// Hierarchy: each level halves the resolution; a coarse face's open fraction is the average of
// the 2^(D-1) fine faces it covers, and the coarse matrix is rediscretised from those fractions
// (so curved solids stay sub-cell on every level, and domain sides keep their wall/open type).
// Transfers: cell-centred (bi/tri)linear prolongation P and restriction R = (4 / 2^D) P^T; with
// the h^2-scaled operator this makes the coarse correction P (P^T A P)^-1 P^T-like in scale.
// Smoothing: red-black Gauss-Seidel, red-then-black before the coarse correction and
// black-then-red after it, and a palindromic sweep sequence on the coarsest level. Every piece is
// then the adjoint of its mirror image, so the V-cycle is a symmetric operator, as CG requires.
// The hierarchy is built once per set of solids and reused across solves.
#include <array>
#include <vector>

#include "msim/numerics/pressure/poisson_matrix.hpp"
#include "msim/numerics/pressure/preconditioner.hpp"

namespace msim::numerics {

struct MultigridSettings {
  int smoothingSweeps = 2;    // red-black sweeps before and after each coarse correction
  int coarsestSweeps = 30;    // red-black sweep pairs on the coarsest level
  int coarsestMinCells = 4;   // stop coarsening before an axis would drop below this many cells
  // Extra red-black sweeps over the cells near solids (McAdams, Sifakis & Teran 2010, "boundary
  // smoothing"): the coarse levels see an obstacle only through averaged face fractions, so the
  // error near it is smoothed worst; without them the iterations grew from 5 to 9-10 between
  // 32^3 and 128^3 with a ball in the box.
  int boundarySweeps = 2;
  int boundaryBand = 2;       // cells within this many face steps of a partly or fully closed face
};

// Face weights of the grid with half the resolution (an odd cell count rounds up: the last coarse
// cell covers one fine cell, and its side on the domain's border takes the fine border face's
// weight).
template <int D>
MacGrid<D> coarsenFaceWeights(const MacGrid<D>& fine);
// Dirichlet diagonal terms of the grid with half the resolution: the children's sum over 2^(D-1)
// (one or two children fewer in the last cell of an odd axis).
template <int D>
std::vector<float> coarsenDirichletDiagonal(const std::vector<float>& fine, const IVec<D>& fineRes);

template <int D>
class MultigridPreconditioner final : public Preconditioner {
 public:
  // `fine` (the matrix of `fineFaceWeight` and `fineDirichletDiagonal`) must outlive the
  // preconditioner. With a free surface (PoissonMatrix's Dirichlet terms) each coarse cell takes
  // the sum of its children's Dirichlet terms over 2^(D-1), the coarse face's share of them as a
  // coarse face weight is the mean of its fine faces; air cells (no coupling, no Dirichlet term)
  // have no unknown on any level.
  MultigridPreconditioner(const PoissonMatrix<D>& fine, const MacGrid<D>& fineFaceWeight,
                          const MultigridSettings& settings = {}, const std::vector<float>& fineDirichletDiagonal = {});
  void apply(const std::vector<float>& r, std::vector<float>& z) override;

  int levelCount() const { return static_cast<int>(matrices_.size()); }
  const IVec<D>& levelResolution(int level) const { return matrices_[level]->res(); }

 private:
  void vcycle(int level, const std::vector<float>& b, std::vector<float>& x);
  void smooth(int level, const std::vector<float>& b, std::vector<float>& x, int first, int sweeps);
  // Red-black sweeps over the band of level `level` starting with colour `first`.
  void smoothBand(int level, const std::vector<float>& b, std::vector<float>& x, int first);
  void findBands();
  void restrictResidual(int fineLevel);                                // r_[l] -> b_[l+1]
  void prolongAdd(int fineLevel, std::vector<float>& fineX);           // fineX += P x_[l+1]

  // Per level and axis, the 1D factors of the tensor-product transfers, tabulated once:
  // fine cell f reads coarse cells parent[f], side[f] with weights; coarse cell C reads fine
  // cells 2C-1 .. 2C+2 (indices clamped into the grid, weight 0 where outside).
  struct Transfer1D {
    std::vector<int> parent, side;
    std::vector<float> parentWeight, sideWeight;
    std::vector<std::array<int, 4>> fine;
    std::vector<std::array<float, 4>> fineWeight;
  };

  MultigridSettings settings_;
  std::vector<std::array<Transfer1D, D>> transfer_;  // transfer_[l]: between levels l and l+1
  std::vector<PoissonMatrix<D>> coarse_;           // levels 1..L-1
  std::vector<const PoissonMatrix<D>*> matrices_;  // all levels, finest first
  std::vector<std::vector<float>> b_, x_, r_;      // per level (b_ and x_ unused on level 0)
  // Per level below the coarsest: the cells near solids, split by colour (coordinate-sum parity).
  std::vector<std::array<std::vector<std::size_t>, 2>> band_;
};

}  // namespace msim::numerics
