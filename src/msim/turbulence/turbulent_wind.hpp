#pragma once
// A spectral wind placed in a scene (Stam ch. 6.3.2, T18): the periodic lattice anchored at an
// origin and carried by a mean wind U, after the seed's translated turbulence (ch. 6.3.2: for a
// constant large-scale flow u_1 the turbulence is u_2(x - u_1 t, t)) and Taylor's frozen-turbulence
// hypothesis: u(x, t) = U + u'(x - origin - U t, t).
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>
#include <utility>

#include "msim/core/grid.hpp"
#include "msim/core/linear_taps.hpp"
#include "msim/core/parallel.hpp"
#include "msim/core/vec.hpp"
#include "msim/turbulence/spectral_wind.hpp"

namespace msim::turbulence {

template <int D>
class TurbulentWind {
 public:
  TurbulentWind(SpectralWind<D> lattice, const Vec<D>& origin, const Vec<D>& meanVelocity)
      : lattice_(std::move(lattice)), origin_(origin), mean_(meanVelocity) {
    double fastest = 0.0;
    for (const auto& u : lattice_.samples()) fastest = std::max(fastest, double(u.norm()));
    maxSpeed_ = mean_.norm() + fastest;
  }

  // Velocity [m/s] at x [m], time t [s].
  Vec<D> velocity(const Vec<D>& x, double t) const { return mean_ + lattice_.velocity(x - origin_ - mean_ * t, t); }
  // Calls f(lin, w) for every sample of `grid` (cell centres or one face component), w being
  // component `axis` of velocity(position, t) (up to float rounding). The lattice is blended to
  // time t once and the wrapped lattice coordinates are tabulated per axis, so each sample costs
  // one D-linear lookup (8 reads in 3D) instead of velocity()'s 2^(D+1).
  template <typename T, typename F>
  void forEachSample(const Grid<T, D>& grid, int axis, double t, F&& f) const;

  // Bound on |velocity| anywhere (interpolation never exceeds the largest sample) [m/s].
  double maxSpeed() const { return maxSpeed_; }
  const SpectralWind<D>& lattice() const { return lattice_; }
  const Vec<D>& meanVelocity() const { return mean_; }

 private:
  SpectralWind<D> lattice_;
  Vec<D> origin_, mean_;
  double maxSpeed_ = 0.0;
};

template <int D>
template <typename T, typename F>
void TurbulentWind<D>::forEachSample(const Grid<T, D>& grid, int axis, double t, F&& f) const {
  const int m = lattice_.params().resolution;
  std::vector<float> slice;
  lattice_.componentAt(axis, t, slice);
  // Per axis d and grid index i: the wrapped lattice tap, for the position shifted by the mean wind.
  std::array<std::vector<LinearTap>, D> taps;
  const Vec<D> first = grid.position(IVec<D>::Zero()) - origin_ - mean_ * t;
  const double h = lattice_.cellSize();
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
