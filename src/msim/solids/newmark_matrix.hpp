#pragma once
// The matrix of the Newmark step's linear solves (newmark.hpp) in symmetric 3 x 3 blocks of floats
// (numerics/symmetric_block_matrix.hpp, the off-diagonal ones rounded to float): the masses on the diagonal plus, for each spring term,
// w_i w_j (c d d^T + c' (I - d d^T)) on its particles i, j. Conjugate gradients multiply by it on
// all cores, block-Jacobi and multigrid are set up from it. Pinned particles' unknowns stay fixed,
// so their rows become the identity and their columns drop out. The sparsity pattern (each
// particle with its springs' and tetrahedra's neighbours) is built once per mesh; assembly then
// only writes values, each particle's row from the terms it takes part in, in parallel.
#include <array>
#include <span>
#include <utility>
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/numerics/symmetric_block_matrix.hpp"
#include "msim/solids/mass_spring.hpp"
#include "msim/solids/particle_split.hpp"

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
  // Writes M + the terms into the matrix (the pattern is rebuilt when the mesh changed). The terms
  // each particle takes part in come as CSR by particle: incidence[incidenceStart[p] ..
  // incidenceStart[p + 1]) = (term, the particle's place among the term's nodes). Where each of
  // those terms' blocks goes in the particle's row is looked up once per `incidenceVersion` (the
  // caller changes it whenever the incidence changes) and kept.
  // With a split among processes, only this process's rows (the others keep their last values).
  void assemble(const MassSpringSystem& system, const std::vector<SpringTerm>& terms, std::span<const int> incidenceStart,
                std::span<const std::pair<int, int>> incidence, long incidenceVersion, const ParticleSplit* split = nullptr);
  const numerics::SymmetricBlockMatrix& matrix() const { return matrix_; }

 private:
  void buildPattern(const MassSpringSystem& system);

  using Block = numerics::SymmetricBlock<double>;
  numerics::SymmetricBlockMatrix matrix_;
  std::vector<Block> exact_;  // the off-diagonal blocks before rounding, assemble's scratch
  std::size_t particles_ = 0, springs_ = 0, tetrahedra_ = 0;
  // Per incidence entry (particle p, term), per node q of the term: the off-diagonal entry (p, q)
  // of the pattern, -1 for p itself; for incidenceVersion_.
  std::vector<std::array<int, 4>> slots_;
  long incidenceVersion_ = -1;
};

}  // namespace msim::solids
