#pragma once
// PoissonMatrix<D>: the matrix-free, face-weighted pressure Poisson operator on a cell-centred grid,
//
//   (A p)_i = sum over the 2D faces f of cell i of  w_f (p_i - p_nb(f)),
//
// where w_f in [0,1] is the open (fluid) fraction of face f. This is the variational form of
// Selle's step 3 (ch. 3.2, "solve lap p = div u* / dt") due to Batty, Bertails & Bridson (2007):
// minimising the kinetic energy of the projected flow weighted by the fluid volume of each face
// gives the symmetric matrix above. A face on a solid wall has w = 0 (Neumann); a face on an open
// domain side keeps its weight and couples to a ghost pressure of 0 (Dirichlet). A cell whose
// faces all have w = 0 is inside the solid and has no unknown (its row is zero).
//
// Storage is D + 2 floats per cell: the weight of each cell's lower face per axis (the upper face
// of cell i is the lower face of i + e_a), the diagonal, and its inverse (0 for excluded cells).
#include <array>
#include <cstddef>
#include <vector>

#include "msim/core/mac_grid.hpp"

namespace msim::numerics {

template <int D>
class PoissonMatrix {
 public:
  PoissonMatrix() = default;
  // faceWeight: the weight of every face including the domain boundary faces (MacGrid layout).
  explicit PoissonMatrix(const MacGrid<D>& faceWeight);
  // With Dirichlet conditions inside the domain (a free surface): faceWeight couples the cells
  // that have unknowns, and dirichletDiagonal[i] >= 0 adds the terms of cell i's faces towards
  // pressures that are given (w_f / theta_f for a ghost-fluid interface at the fraction theta_f of
  // the way to the neighbour's centre). A cell with no coupling and no Dirichlet term has no unknown.
  PoissonMatrix(const MacGrid<D>& faceWeight, const std::vector<float>& dirichletDiagonal);

  const IVec<D>& res() const { return res_; }
  std::size_t size() const { return diag_.size(); }
  std::size_t stride(int axis) const { return stride_[axis]; }
  const std::vector<float>& diag() const { return diag_; }
  const std::vector<float>& invDiag() const { return invDiag_; }
  // Weight of the face between cell i and cell i - e_axis (the domain face when i is on the lower side).
  const std::vector<float>& lowerWeight(int axis) const { return lower_[axis]; }

  // y = A x.
  void apply(const std::vector<float>& x, std::vector<float>& y) const;
  // r = b - A x.
  void residual(const std::vector<float>& b, const std::vector<float>& x, std::vector<float>& r) const;
  // One Gauss-Seidel update of the cells whose coordinate sum has parity `colour`. Cells of one
  // colour only couple to the other colour, so the half sweep is exact in parallel.
  void gaussSeidel(const std::vector<float>& b, std::vector<float>& x, int colour) const;
  // gaussSeidel(colour first) followed by gaussSeidel(1 - first), with the same result, in one
  // pass over memory.
  void gaussSeidelPair(const std::vector<float>& b, std::vector<float>& x, int first) const;
  // One Gauss-Seidel update of each listed cell. The cells must not couple to each other (one
  // colour of a red-black split), so the updates run in parallel and their order is irrelevant.
  void relaxCells(const std::vector<float>& b, std::vector<float>& x, const std::vector<std::size_t>& cells) const;

 private:
  void relaxRow(const std::vector<float>& b, std::vector<float>& x, int colour, std::size_t row) const;

  IVec<D> res_ = IVec<D>::Zero();
  std::array<std::size_t, D> stride_{};
  std::array<std::vector<float>, D> lower_;
  std::vector<float> diag_;
  std::vector<float> invDiag_;
  std::vector<float> zeroRow_;  // stands in for the neighbours beyond the domain (ghost p = 0)
};

}  // namespace msim::numerics
