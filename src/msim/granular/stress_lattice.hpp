#pragma once
// The staggered storage of Narain (2011) Fig. 5.8 and the finite differences that turn a stress
// component into forces on the velocity faces.
//
// Velocity component a lives on the faces normal to axis a (face index q is the lower face of
// cell q). The stress sigma = -p I + s (eq. 5.1) is stored as:
//   diagonal components s_aa and the pressure p at cell centres,
//   off-diagonal components s_ab (a < b) on the cell edges parallel to the third axis c, at the
//   corner (q_a - 1/2, q_b - 1/2) of cell q in the a-b plane: (res_a + 1) x (res_b + 1) x res_c.
// The force density div(s) on face-a q is
//   (s_aa(q) - s_aa(q - e_a)) / dx + sum_{b != a} (s_ab(q + e_b) - s_ab(q)) / dx,
// with the edge index q read in the lattice of s_ab (first-order differences, ch. 5.5). The
// pressure force -grad p is minus the diagonal term of every axis.
//
// Every component's quadratic program (eqs. 5.10, 5.18, 5.45) has the form dt^2 D^T C D with C
// diagonal over faces, and two samples of one component touch a common face only as a pair
// with opposite signs, so dt^2 D^T C D is a 7-point grid Poisson operator on the component's own
// lattice; poissonStencil() returns it in the form numerics::GridPoissonQpOperator takes (a
// matrix-free operator for MPRGP).
#include <array>
#include <cstddef>
#include <vector>

#include <tbb/parallel_for.h>

#include "msim/core/vec.hpp"

namespace msim::granular {

// One value per face of each axis, x fastest (the MacGrid<3> layout: res + e_a faces along a).
struct FaceField {
  IVec3 res = IVec3::Zero();  // cells
  std::array<std::vector<double>, 3> values;

  FaceField() = default;
  explicit FaceField(const IVec3& cells, double value = 0.0);
  IVec3 size(int axis) const;
  std::size_t index(int axis, const IVec3& q) const;
  void fill(double value);
  // Zeroes the field for a grid of `cells`, keeping the storage when the size is unchanged (the
  // per-step scratch of the solver does not reallocate).
  void reset(const IVec3& cells);
};

// A stress component: Diagonal(a) at cells (a = b), OffDiagonal(a, b) with a < b on edges.
struct StressComponent {
  int a = 0, b = 0;
  bool diagonal() const { return a == b; }
  static StressComponent Diagonal(int axis) { return {axis, axis}; }
  static StressComponent OffDiagonal(int a, int b) { return {a < b ? a : b, a < b ? b : a}; }
};

// Samples of a component's lattice along each axis for a grid of `cells`.
IVec3 latticeSize(const StressComponent& c, const IVec3& cells);

// An axis-aligned box of lattice samples (or faces), first..last inclusive; empty when last < first
// on some axis. The solver tracks where each stress component may be nonzero with one, so that the
// bookkeeping around a friction solve touches only that part of the grid.
struct LatticeBox {
  IVec3 first = IVec3::Zero(), last = IVec3::Constant(-1);
  static LatticeBox whole(const IVec3& size) { return {IVec3::Zero(), size - IVec3::Ones()}; }
  bool empty() const { return (last.array() < first.array()).any(); }
  LatticeBox intersect(const LatticeBox& o) const { return {first.cwiseMax(o.first), last.cwiseMin(o.last)}; }
  LatticeBox unite(const LatticeBox& o) const {
    if (empty()) return o;
    if (o.empty()) return *this;
    return {first.cwiseMin(o.first), last.cwiseMax(o.last)};
  }
};

// f(index of the row's first element, y, z) for each x-row of `box` in a grid of size n (the row
// spans box.first[0]..box.last[0]), the z slices in parallel. Nothing for an empty box.
template <typename F>
void forBoxRows(const LatticeBox& box, const IVec3& n, const F& f) {
  if (box.empty()) return;
  const std::size_t slices = static_cast<std::size_t>(box.last[2] - box.first[2] + 1);
  tbb::parallel_for(std::size_t(0), slices, [&](std::size_t dz) {
    const int z = box.first[2] + static_cast<int>(dz);
    for (int y = box.first[1]; y <= box.last[1]; ++y)
      f((static_cast<std::size_t>(z) * n[1] + y) * n[0] + box.first[0], y, z);
  });
}

// The faces of `axis` (in the face grid of `cells`) whose divergence of c reads a sample in
// `samples`: empty if c does not act on faces of that axis.
LatticeBox facesReading(const StressComponent& c, const LatticeBox& samples, const IVec3& cells, int axis);

// Calls f(sample index, sign) for the (at most two) samples of component c whose difference
// gives div(s) on face-`faceAxis` f (D_c's row of that face, times dx): nothing if the component
// does not act on faces of that axis.
template <typename F>
void forEachFaceSample(const StressComponent& c, const IVec3& lattice, int faceAxis, const IVec3& f, F&& fn);

// force += scale * D_c s on every face (div of the component, per unit volume). Faces whose mask
// entry is 0 (walls) are left untouched.
void addDivergence(const StressComponent& c, const std::vector<double>& s, double scale, double dx,
                   const FaceField& mask, FaceField& force);
// The same for an s that is 0 outside `samples`: only the faces reading those samples are visited
// (bitwise what the whole pass gives, which adds 0 elsewhere).
void addDivergence(const StressComponent& c, const std::vector<double>& s, double scale, double dx,
                   const FaceField& mask, FaceField& force, const LatticeBox& samples);
// out = D_c^T u (u on faces; masked faces count as 0). out is resized to the lattice.
void divergenceTranspose(const StressComponent& c, const FaceField& u, double dx, const FaceField& mask,
                         std::vector<double>& out);
// The same for the samples in `samples` only (out is resized to the lattice; its other entries are
// left as they were). It reads u on facesReading(c, samples, ...) only.
void divergenceTranspose(const StressComponent& c, const FaceField& u, double dx, const FaceField& mask,
                         std::vector<double>& out, const LatticeBox& samples);

// The Poisson form of D_c^T W D_c for face weights W (>= 0; masked faces count as 0): for each
// lattice axis the weight of the link between sample q and q - e_axis, and the diagonal. Samples
// no face weight reaches get diagonal `isolated` (they decouple; the callers hold them at 0).
void poissonStencil(const StressComponent& c, const FaceField& weight, double dx, const FaceField& mask,
                    double isolated, std::array<std::vector<double>, 3>& lowerWeight, std::vector<double>& diagonal);

template <typename F>
void forEachFaceSample(const StressComponent& c, const IVec3& lattice, int faceAxis, const IVec3& f, F&& fn) {
  int diffAxis = -1;
  if (c.diagonal() && faceAxis == c.a) diffAxis = c.a;
  if (!c.diagonal() && faceAxis == c.a) diffAxis = c.b;
  if (!c.diagonal() && faceAxis == c.b) diffAxis = c.a;
  if (diffAxis < 0) return;
  // Diagonal: s(f) - s(f - e_a). OffDiagonal: s(f + e_diff) - s(f).
  IVec3 hi = f, lo = f;
  if (c.diagonal())
    lo[diffAxis] -= 1;
  else
    hi[diffAxis] += 1;
  auto visit = [&](const IVec3& q, double sign) {
    if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= lattice[0] || q[1] >= lattice[1] || q[2] >= lattice[2]) return;
    fn((static_cast<std::size_t>(q[2]) * lattice[1] + q[1]) * lattice[0] + q[0], sign);
  };
  visit(hi, 1.0);
  visit(lo, -1.0);
}

}  // namespace msim::granular
