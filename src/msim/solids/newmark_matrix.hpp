#pragma once
// The matrix of the Newmark step's linear solves (newmark.hpp), assembled in 3 x 3 blocks so that
// conjugate gradients can run on all cores and be preconditioned by multigrid: the masses on the
// diagonal plus, for each spring term, w_i w_j (c d d^T + c' (I - d d^T)) on its particles i, j.
// Pinned particles' unknowns stay fixed, so their rows and columns become the identity. The
// sparsity pattern (each particle with its springs' and tetrahedra's neighbours) is built once per
// mesh; assembly then only writes values.
#include <array>
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/numerics/sparse_ops.hpp"
#include "msim/solids/mass_spring.hpp"

namespace msim::solids {

// A linearised spring in a half step's matrix: with r = sum_i w_i u_i over its nodes, it adds
// c (r . d) d + c' (r - (r . d) d), weighted w_i, on each node i.
struct SpringTerm {
  std::array<int, 4> node{};
  std::array<double, 4> weight{};
  int count = 0;
  Vec3 direction = Vec3::Zero();
  double coefficient = 0.0;  // c: h (b + c k / l0) along d
  double stiffness = 0.0;    // its elastic part, h c k / l0
  double sideways = 0.0;     // c': h c T / L across d
};

class NewmarkMatrix {
 public:
  // Writes M + the terms into the matrix (the pattern is rebuilt when the mesh changed).
  void assemble(const MassSpringSystem& system, const std::vector<SpringTerm>& terms);
  const numerics::SparseRowMatrix& matrix() const { return matrix_; }

 private:
  void buildPattern(const MassSpringSystem& system);
  // The position of block (i, j)'s first entry in row 3 i's values.
  int blockOffset(int i, int j) const;

  numerics::SparseRowMatrix matrix_;
  std::vector<int> neighbourStart_, neighbours_;  // per particle, sorted, itself included
  std::size_t particles_ = 0, springs_ = 0, tetrahedra_ = 0;
};

}  // namespace msim::solids
