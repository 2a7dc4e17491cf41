#pragma once
// Turbulent wind by spatial synthesis (Stam 1995, ch. 3.3.3, sparse convolution after Lewis
// 1989): random impulses at Poisson points convolved with a kernel whose spectrum makes the field's
// spectrum the Kolmogorov one. Unlike the spectral lattice (spectral_wind.hpp) it is evaluated
// anywhere without a lattice, need not repeat (or repeats with any tile), and costs nothing up
// front beyond tabulating the kernel; each evaluation sums the impulses within the kernel's reach.
//
// Incompressibility: Stam convolves vector white noise with the matrix kernel H = F^-1[Phi P]
// (eq. 3.13). Truncating that kernel to a finite reach breaks div u = 0. Here the impulses w_j
// (standard normal vectors; scalars in 2D) build a vector potential (a stream function in 2D)
//   psi(x) = sum_j G(|x - x_j|) w_j,     u = curl psi = sum_j G'(r_j) r^_j x w_j
// (2D: u = sum_j w_j G'(r_j) (r_y, -r_x) / r_j), divergence-free for any kernel, truncated or not.
// Its spectrum is lambda k^2 |G~(k)|^2 / (2 pi)^D P(k) (lambda the points per unit volume), which is
// Phi_D(k)^2 P(k) of eq. 3.13 when G~(k) = (2 pi)^(D/2) Phi_D(k) / (k sqrt(lambda)). G is the radial
// inverse transform of G~ (3D: G(r) = 1/(2 pi^2 r) int G~ k sin(kr) dk; 2D: 1/(2 pi) int G~ k J_0(kr) dk),
// tabulated by quadrature and tapered to zero between R/2 and its reach R (cos^2), then scaled so
// that <|u|^2> is the spectrum's 2 int E dk (the taper removes a little of it).
#include <cstdint>
#include <string>
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/turbulence/kolmogorov_spectrum.hpp"

namespace msim::turbulence {

struct SparseConvolutionParams {
  KolmogorovSpectrum spectrum;
  double reach = 2.0;       // kernel reach R in largest eddies (R = reach L); >= 1
  int pointsPerCell = 4;    // Poisson points per cell of side R (Lewis: a fixed count per cell)
  double tile = 0.0;        // > 0: the points repeat with this period (a tileable field); >= 3 R
  std::uint64_t seed = 0;
};

template <int D>
class SparseConvolutionWind {
 public:
  // InputError naming `where` for a bad spectrum, reach < 1, pointsPerCell outside [1, 64], or a
  // tile shorter than three reaches (the cells around a point must be distinct).
  SparseConvolutionWind(const SparseConvolutionParams& params, const std::string& where = "wind");

  // Velocity [m/s] at x [m].
  Vec<D> velocity(const Vec<D>& x) const;

  double reach() const { return reach_; }
  // The tapered, scaled kernel's derivative G'(r) (for tests).
  double kernelSlope(double r) const;

 private:
  // f(position, weight) for the impulses of cell c (their randoms from the cell wrapped into the
  // tile when there is one, their positions in c itself). The weight is a vector in 3D, a scalar
  // (first component) in 2D.
  template <typename F>
  void forEachImpulse(const IVec<D>& c, F&& f) const;

  SparseConvolutionParams params_;
  double reach_ = 0.0;     // R [m]: cells have this side (rounded down to divide the tile)
  int tileCells_ = 0;      // cells per tile side (0: no tile)
  std::vector<double> slope_;  // G'(r) at r = i R / (n - 1)
  // Tiled: the impulses of every cell of the tile (pointsPerCell each, cell-major), drawn once;
  // positions relative to their cell's corner.
  std::vector<Vec<D>> tileOffsets_;
  std::vector<Vec3> tileWeights_;
};

extern template class SparseConvolutionWind<2>;
extern template class SparseConvolutionWind<3>;

}  // namespace msim::turbulence
