#pragma once
// A turbulent wind placed in a scene (Stam ch. 6.3.2, T18): a spectral lattice (spectral_wind.hpp)
// or a spatial synthesis (sparse_convolution_wind.hpp, frozen in time) anchored at an origin and
// carried by a mean wind U, after the seed's translated turbulence (ch. 6.3.2: for a constant
// large-scale flow u_1 the turbulence is u_2(x - u_1 t, t)) and Taylor's frozen-turbulence
// hypothesis: u(x, t) = U + u'(x - origin - U t, t).
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <variant>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/linear_taps.hpp"
#include "msim/core/parallel.hpp"
#include "msim/core/vec.hpp"
#include "msim/turbulence/sparse_convolution_wind.hpp"
#include "msim/turbulence/spectral_wind.hpp"

namespace msim::turbulence {

template <int D>
class TurbulentWind {
 public:
  TurbulentWind(SpectralWind<D> lattice, const Vec<D>& origin, const Vec<D>& meanVelocity)
      : field_(std::move(lattice)), origin_(origin), mean_(meanVelocity) {
    double fastest = 0.0;
    for (const auto& u : std::get<SpectralWind<D>>(field_).samples()) fastest = std::max(fastest, double(u.norm()));
    maxSpeed_ = mean_.norm() + fastest;
  }
  // A spatial synthesis has no largest sample: its speed is bounded by five times its rms (its
  // impulses are Gaussian), `speedRms` [m/s].
  TurbulentWind(SparseConvolutionWind<D> field, double speedRms, const Vec<D>& origin, const Vec<D>& meanVelocity)
      : field_(std::move(field)), origin_(origin), mean_(meanVelocity), maxSpeed_(meanVelocity.norm() + 5.0 * speedRms) {}

  // Velocity [m/s] at x [m], time t [s].
  Vec<D> velocity(const Vec<D>& x, double t) const {
    const Vec<D> carried = x - origin_ - mean_ * t;
    if (const auto* lattice = std::get_if<SpectralWind<D>>(&field_)) return mean_ + lattice->velocity(carried, t);
    return mean_ + std::get<SparseConvolutionWind<D>>(field_).velocity(carried);
  }
  // Calls f(lin, w) for every sample of `grid` (cell centres or one face component), w being
  // component `axis` of velocity(position, t) (up to float rounding). For a lattice, it is blended
  // to time t once and the wrapped lattice coordinates are tabulated per axis, so each sample costs
  // one D-linear lookup (8 reads in 3D) instead of velocity()'s 2^(D+1).
  template <typename T, typename F>
  void forEachSample(const Grid<T, D>& grid, int axis, double t, F&& f) const;

  // Bound on |velocity| anywhere [m/s] (a lattice: interpolation never exceeds its largest sample).
  double maxSpeed() const { return maxSpeed_; }
  // The spectral lattice, or null for a spatial synthesis.
  const SpectralWind<D>* lattice() const { return std::get_if<SpectralWind<D>>(&field_); }
  const Vec<D>& meanVelocity() const { return mean_; }

 private:
  std::variant<SpectralWind<D>, SparseConvolutionWind<D>> field_;
  Vec<D> origin_, mean_;
  double maxSpeed_ = 0.0;
};

template <int D>
template <typename T, typename F>
void TurbulentWind<D>::forEachSample(const Grid<T, D>& grid, int axis, double t, F&& f) const {
  const SpectralWind<D>* lattice = this->lattice();
  if (!lattice) {
    parallelForCells<D>(grid.size(), [&](const IVec<D>& c, std::size_t lin) {
      f(lin, static_cast<float>(velocity(grid.position(c), t)[axis]));
    });
    return;
  }
  const int m = lattice->params().resolution;
  std::vector<float> slice;
  lattice->componentAt(axis, t, slice);
  // Per axis d and grid index i: the wrapped lattice tap, for the position shifted by the mean wind.
  std::array<std::vector<LinearTap>, D> taps;
  const Vec<D> first = grid.position(IVec<D>::Zero()) - origin_ - mean_ * t;
  const double h = lattice->cellSize();
  std::size_t stride = 1;
  for (int d = 0; d < D; ++d) {
    taps[d].resize(static_cast<std::size_t>(grid.size()[d]));
    for (int i = 0; i < grid.size()[d]; ++i) taps[d][i] = periodicTap((first[d] + i * grid.spec().dx) / h, m, stride);
    stride *= static_cast<std::size_t>(m);
  }
  const float mean = static_cast<float>(mean_[axis]);
  parallelForCells<D>(grid.size(), [&](const IVec<D>& c, std::size_t lin) {
    std::array<LinearTap, D> at;
    for (int d = 0; d < D; ++d) at[d] = taps[d][static_cast<std::size_t>(c[d])];
    f(lin, mean + blendCorners<D>(at, slice.data()));
  });
}

}  // namespace msim::turbulence
