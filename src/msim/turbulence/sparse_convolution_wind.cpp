#include "msim/turbulence/sparse_convolution_wind.hpp"

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/core/parallel.hpp"
#include "msim/core/rng.hpp"

namespace msim::turbulence {

namespace {

constexpr int kTableSize = 1024;
constexpr int kMaxPointsPerCell = 64;

// cos^2 taper from 1 at r <= R/2 to 0 at R, and its derivative.
double taper(double r, double reach) {
  if (r <= 0.5 * reach) return 1.0;
  if (r >= reach) return 0.0;
  const double c = std::cos(0.5 * std::numbers::pi * (r - 0.5 * reach) / (0.5 * reach));
  return c * c;
}
double taperSlope(double r, double reach) {
  if (r <= 0.5 * reach || r >= reach) return 0.0;
  const double a = 0.5 * std::numbers::pi * (r - 0.5 * reach) / (0.5 * reach);
  return -2.0 * std::cos(a) * std::sin(a) * std::numbers::pi / reach;
}

std::uint64_t mix(std::uint64_t h) {
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdull;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ull;
  return h ^ (h >> 33);
}

}  // namespace

template <int D>
SparseConvolutionWind<D>::SparseConvolutionWind(const SparseConvolutionParams& params, const std::string& where)
    : params_(params) {
  params.spectrum.validate(where);
  if (!(params.reach >= 1.0))
    throw InputError(fmt::format("{}: the kernel must reach at least one largest eddy, got {}", where, params.reach));
  if (params.pointsPerCell < 1 || params.pointsPerCell > kMaxPointsPerCell)
    throw InputError(
        fmt::format("{}: points per cell must lie in [1, {}], got {}", where, kMaxPointsPerCell, params.pointsPerCell));
  reach_ = params.reach * params.spectrum.largestEddy;
  if (params.tile > 0.0) {
    if (params.tile < 3.0 * reach_)
      throw InputError(fmt::format("{}: the tile ({} m) must hold three kernel reaches ({} m each)", where, params.tile,
                                   reach_));
    tileCells_ = static_cast<int>(std::floor(params.tile / reach_));
    reach_ = params.tile / tileCells_;  // cells divide the tile; the kernel reaches one cell
  }
  const double lambda = params.pointsPerCell / std::pow(reach_, D);
  const double k0 = params.spectrum.lowWavenumber(), k1 = params.spectrum.highWavenumber();
  // G~(k) = (2 pi)^(D/2) Phi_D(k) / (k sqrt(lambda)), Phi_D^2 = E Gamma(D/2) / (pi^(D/2) (D-1) k^(D-1)).
  const double gammaOverPi = D == 2 ? 1.0 / std::numbers::pi : 0.5 / std::numbers::pi;
  auto transform = [&](double k) {
    const double phi2 = params.spectrum.energy(k) * gammaOverPi / ((D - 1) * std::pow(k, D - 1));
    return std::pow(2.0 * std::numbers::pi, 0.5 * D) * std::sqrt(phi2) / (k * std::sqrt(lambda));
  };
  // Midpoint rule over the band, 40 points per period of the fastest oscillation (2 pi / R in k).
  const int nk = std::clamp(static_cast<int>(40.0 * (k1 - k0) * reach_ / (2.0 * std::numbers::pi)), 200, 200000);
  const double dk = (k1 - k0) / nk;
  std::vector<double> ks(nk), gs(nk);
  for (int i = 0; i < nk; ++i) {
    ks[i] = k0 + (i + 0.5) * dk;
    gs[i] = transform(ks[i]) * dk;
  }
  std::vector<double> value(kTableSize), slope(kTableSize);
  parallelFor(
      0, kTableSize,
      [&](std::size_t i) {
        const double r = reach_ * static_cast<double>(i) / (kTableSize - 1);
        double g = 0.0, gp = 0.0;
        for (int q = 0; q < nk; ++q) {
          const double k = ks[q], kr = k * r;
          if constexpr (D == 3) {
            if (r == 0.0) {
              g += gs[q] * k * k;
            } else {
              const double s = std::sin(kr), c = std::cos(kr);
              g += gs[q] * k * s / r;
              gp += gs[q] * k * (kr * c - s) / (r * r);
            }
          } else {
            g += gs[q] * k * std::cyl_bessel_j(0.0, kr);
            gp -= gs[q] * k * k * std::cyl_bessel_j(1.0, kr);
          }
        }
        const double norm = D == 3 ? 1.0 / (2.0 * std::numbers::pi * std::numbers::pi) : 1.0 / (2.0 * std::numbers::pi);
        value[i] = norm * g;
        slope[i] = norm * gp;
      },
      16);
  // The tapered kernel's slope, and its scale: <|u|^2> = lambda (D - 1) int G_T'^2 dV.
  slope_.resize(kTableSize);
  double integral = 0.0;
  const double dr = reach_ / (kTableSize - 1);
  for (int i = 0; i < kTableSize; ++i) {
    const double r = dr * i;
    slope_[i] = slope[i] * taper(r, reach_) + value[i] * taperSlope(r, reach_);
    const double shell = D == 3 ? 4.0 * std::numbers::pi * r * r : 2.0 * std::numbers::pi * r;
    const double w = (i == 0 || i == kTableSize - 1) ? 0.5 : 1.0;  // trapezoid
    integral += w * slope_[i] * slope_[i] * shell * dr;
  }
  const double variance = lambda * (D - 1) * integral;
  const double scale = std::sqrt(2.0 * params.spectrum.kineticEnergy() / variance);
  for (double& s : slope_) s *= scale;

  if (tileCells_ > 0) {
    // The tile's impulses, cell by cell from one stream each (the same draws the open field makes
    // for the cells with those indices).
    std::size_t cells = 1;
    for (int d = 0; d < D; ++d) cells *= static_cast<std::size_t>(tileCells_);
    tileOffsets_.resize(cells * params.pointsPerCell);
    tileWeights_.resize(cells * params.pointsPerCell);
    for (std::size_t cell = 0; cell < cells; ++cell) {
      std::uint64_t h = params.seed;
      std::size_t rest = cell;
      for (int d = 0; d < D; ++d) {
        h = mix(h ^ (static_cast<std::uint64_t>(rest % tileCells_) + 0x9e3779b97f4a7c15ull * (d + 1)));
        rest /= tileCells_;
      }
      Rng rng = Rng(params.seed).split(h);
      for (int p = 0; p < params.pointsPerCell; ++p) {
        Vec<D>& x = tileOffsets_[cell * params.pointsPerCell + p];
        for (int d = 0; d < D; ++d) x[d] = rng.uniform() * reach_;
        Vec3& w = tileWeights_[cell * params.pointsPerCell + p];
        w.setZero();
        for (int d = 0; d < (D == 3 ? 3 : 1); ++d) w[d] = rng.normal();
      }
    }
  }
}

template <int D>
double SparseConvolutionWind<D>::kernelSlope(double r) const {
  if (!(r < reach_)) return 0.0;
  const double g = r / reach_ * (kTableSize - 1);
  const int i = std::min(static_cast<int>(g), kTableSize - 2);
  const double f = g - i;
  return (1.0 - f) * slope_[i] + f * slope_[i + 1];
}

template <int D>
template <typename F>
void SparseConvolutionWind<D>::forEachImpulse(const IVec<D>& c, F&& f) const {
  Vec<D> corner;
  for (int d = 0; d < D; ++d) corner[d] = c[d] * reach_;
  if (tileCells_ > 0) {
    std::size_t cell = 0;
    for (int d = D - 1; d >= 0; --d) cell = cell * tileCells_ + static_cast<std::size_t>(((c[d] % tileCells_) + tileCells_) % tileCells_);
    const std::size_t first = cell * static_cast<std::size_t>(params_.pointsPerCell);
    for (int p = 0; p < params_.pointsPerCell; ++p) f(corner + tileOffsets_[first + p], tileWeights_[first + p]);
    return;
  }
  std::uint64_t h = params_.seed;
  for (int d = 0; d < D; ++d)
    h = mix(h ^ (static_cast<std::uint64_t>(static_cast<std::uint32_t>(c[d])) + 0x9e3779b97f4a7c15ull * (d + 1)));
  Rng rng = Rng(params_.seed).split(h);
  for (int p = 0; p < params_.pointsPerCell; ++p) {
    Vec<D> x;
    for (int d = 0; d < D; ++d) x[d] = corner[d] + rng.uniform() * reach_;
    Vec3 w = Vec3::Zero();
    for (int d = 0; d < (D == 3 ? 3 : 1); ++d) w[d] = rng.normal();
    f(x, w);
  }
}

template <int D>
Vec<D> SparseConvolutionWind<D>::velocity(const Vec<D>& x) const {
  IVec<D> base;
  for (int d = 0; d < D; ++d) base[d] = static_cast<int>(std::floor(x[d] / reach_));
  Vec<D> u = Vec<D>::Zero();
  for (int n = 0; n < (D == 3 ? 27 : 9); ++n) {
    IVec<D> c = base;
    int rest = n;
    for (int d = 0; d < D; ++d) {
      c[d] += rest % 3 - 1;
      rest /= 3;
    }
    forEachImpulse(c, [&](const Vec<D>& p, const Vec3& w) {
      const Vec<D> r = x - p;
      const double dist = r.norm();
      if (!(dist > 0.0) || dist >= reach_) return;
      const double g = kernelSlope(dist) / dist;  // G'(r) r^ = g r
      if constexpr (D == 3) {
        u += g * r.cross(w);
      } else {
        u += w[0] * g * Vec2(r.y(), -r.x());
      }
    });
  }
  return u;
}

template class SparseConvolutionWind<2>;
template class SparseConvolutionWind<3>;

}  // namespace msim::turbulence
