#include "msim/turbulence/noise_particles.hpp"

#include <algorithm>
#include <cmath>

#include "msim/core/interpolation.hpp"
#include "msim/core/parallel.hpp"
#include "msim/core/rng.hpp"

namespace msim::turbulence {

namespace {
constexpr int kMostPerCell = 3;
}  // namespace

template <int D>
NoiseParticles<D>::NoiseParticles(const GridSpec<D>& coarse, const TurbulentEnergy<D>& energy, double fineDx,
                                  const NoiseParticleParams& params, const Grid<float, D>* solid)
    : coarse_(coarse), l0_(energy.largestEddy()), params_(params), tile_(params.seed) {
  if (solid) solid_.emplace(*solid);
  if (params.octaves > 0) {
    octaves_ = std::min(params.octaves, kMaxOctaves);
  } else {
    octaves_ = 1;  // octave i's shortest wavelength l_i / 2 should span two fine cells
    while (octaves_ < kMaxOctaves && l0_ / std::ldexp(1.0, octaves_) >= 4.0 * fineDx) ++octaves_;
  }
  for (int d = 0; d < D; ++d)
    cells_[d] = std::max(1, static_cast<int>(std::ceil(coarse.res[d] * coarse.dx / l0_ - 1e-9)));
  refill(0);
}

template <int D>
bool NoiseParticles<D>::inFluid(const Vec<D>& x) const {
  IVec<D> c;
  for (int d = 0; d < D; ++d) {
    const double s = (x[d] - coarse_.origin[d]) / coarse_.dx;
    if (!(s >= 0.0 && s < coarse_.res[d])) return false;
    c[d] = static_cast<int>(s);
  }
  return !solid_ || (*solid_)(c) <= 0.5f;
}

template <int D>
IVec<D> NoiseParticles<D>::coverageCoord(const Vec<D>& x) const {
  IVec<D> c;
  for (int d = 0; d < D; ++d)
    c[d] = std::clamp(static_cast<int>(std::floor((x[d] - coarse_.origin[d]) / l0_)), 0, cells_[d] - 1);
  return c;
}

template <int D>
std::size_t NoiseParticles<D>::coverageIndex(const IVec<D>& c) const {
  std::size_t index = 0;
  for (int d = D - 1; d >= 0; --d) index = index * cells_[d] + static_cast<std::size_t>(c[d]);
  return index;
}

template <int D>
void NoiseParticles<D>::refill(std::uint64_t step) {
  // Bucket by coverage cell (stable counting sort), keep at most kMostPerCell per cell (in index
  // order), add one where a fluid cell has none; the arrays end up in cell order.
  std::size_t cellCount = 1;
  for (int d = 0; d < D; ++d) cellCount *= static_cast<std::size_t>(cells_[d]);
  const std::size_t n = position_.size();
  oldCell_.resize(n);
  oldStart_.assign(cellCount + 1, 0);
  for (std::size_t j = 0; j < n; ++j) {
    oldCell_[j] = static_cast<std::uint32_t>(coverageIndex(coverageCoord(position_[j])));
    ++oldStart_[oldCell_[j] + 1];
  }
  for (std::size_t c = 0; c < cellCount; ++c) oldStart_[c + 1] += oldStart_[c];
  oldOrder_.resize(n);
  cellStart_.assign(oldStart_.begin(), oldStart_.end());  // fill cursors, rebuilt below
  for (std::size_t j = 0; j < n; ++j) oldOrder_[cellStart_[oldCell_[j]]++] = static_cast<std::uint32_t>(j);

  nextPosition_.clear();
  nextOffset_.clear();
  nextTime_.clear();
  const Rng base(params_.seed ^ 0x2545f4914f6cdd1dull);
  for (std::size_t cell = 0; cell < cellCount; ++cell) {
    cellStart_[cell] = static_cast<std::uint32_t>(nextPosition_.size());
    const std::uint32_t first = oldStart_[cell], last = std::min<std::uint32_t>(oldStart_[cell + 1], first + kMostPerCell);
    for (std::uint32_t q = first; q < last; ++q) {
      const std::uint32_t j = oldOrder_[q];
      nextPosition_.push_back(position_[j]);
      nextOffset_.push_back(offset_[j]);
      nextTime_.push_back(time_[j]);
    }
    if (first != last) continue;
    Rng r = base.split(step * 0x9E3779B97F4A7C15ull + cell);
    Vec<D> x;
    std::size_t rest = cell;
    for (int d = 0; d < D; ++d) {
      const double lo = coarse_.origin[d] + static_cast<double>(rest % cells_[d]) * l0_;
      const double hi = std::min(lo + l0_, coarse_.origin[d] + coarse_.res[d] * coarse_.dx);
      x[d] = lo + r.uniform() * (hi - lo);
      rest /= cells_[d];
    }
    if (!inFluid(x)) continue;
    Vec<D> o;
    for (int d = 0; d < D; ++d) o[d] = r.uniform(0.0, NoiseTile<D>::kSide);
    std::array<double, kMaxOctaves> t{};
    for (double& v : t) v = r.uniform(0.0, NoiseTile<D>::kPeriod);
    nextPosition_.push_back(x);
    nextOffset_.push_back(o);
    nextTime_.push_back(t);
  }
  cellStart_[cellCount] = static_cast<std::uint32_t>(nextPosition_.size());
  position_.swap(nextPosition_);
  offset_.swap(nextOffset_);
  time_.swap(nextTime_);
}

template <int D>
void NoiseParticles<D>::advance(const MacGrid<D>& velocity, const TurbulentEnergy<D>& energy, double dt) {
  const auto& e = energy.energy();
  std::vector<std::uint8_t> keep(position_.size(), 1);
  parallelFor(0, position_.size(), [&](std::size_t j) {
    Vec<D>& p = position_[j];
    const Vec<D> mid = p + 0.5 * dt * sampleLinear<D>(velocity, p);
    p += dt * sampleLinear<D>(velocity, mid);
    if (!inFluid(p)) {
      keep[j] = 0;
      return;
    }
    const double e0 = std::max(0.0f, sampleLinear<D>(e, p));
    for (int i = 0; i < octaves_; ++i) {
      const double ei = energy.octaveEnergy(e0, i);
      if (ei > 0.0) time_[j][i] += dt * std::sqrt(ei) / (l0_ / std::ldexp(1.0, i));  // dt / tau_i
    }
  }, 256);
  std::size_t kept = 0;
  for (std::size_t j = 0; j < position_.size(); ++j) {
    if (!keep[j]) continue;
    position_[kept] = position_[j];
    offset_[kept] = offset_[j];
    time_[kept] = time_[j];
    ++kept;
  }
  position_.resize(kept);
  offset_.resize(kept);
  time_.resize(kept);
  refill(++steps_);
}

template <int D>
void NoiseParticles<D>::synthesize(const TurbulentEnergy<D>& energy, MacGrid<D>& turbulent,
                                   const std::vector<std::uint8_t>* nodeMask) {
  const GridSpec<D>& fine = turbulent.component(0).spec();
  // Per particle and octave: amplitude A_i = sqrt(E_i) l_i.
  const std::size_t n = position_.size();
  std::vector<std::array<float, kMaxOctaves>> amplitude(n);
  parallelFor(0, n, [&](std::size_t j) {
    const double e0 = std::max(0.0f, sampleLinear<D>(energy.energy(), position_[j]));
    for (int i = 0; i < octaves_; ++i) {
      const double l = l0_ / std::ldexp(1.0, i);
      amplitude[j][i] = static_cast<float>(std::sqrt(energy.octaveEnergy(e0, i)) * l);
    }
  }, 1024);
  const IVec<D> nodes = fine.res + IVec<D>::Ones();
  std::size_t nodeCount = 1;
  for (int d = 0; d < D; ++d) nodeCount *= static_cast<std::size_t>(nodes[d]);
  psi_.resize(nodeCount);
  std::vector<Vecf<3>>& psi = psi_;
  constexpr int kComponents = D == 3 ? 3 : 1;
  const double invL0 = 1.0 / l0_;
  parallelFor(0, nodeCount, [&](std::size_t a) {
    psi[a].setZero();
    if (nodeMask && !(*nodeMask)[a]) return;
    Vec<D> x;
    std::size_t rest = a;
    for (int d = 0; d < D; ++d) {
      x[d] = fine.origin[d] + static_cast<double>(rest % nodes[d]) * fine.dx;
      rest /= nodes[d];
    }
    const IVec<D> home = coverageCoord(x);
    double acc[3] = {0.0, 0.0, 0.0}, weights = 0.0;
    for (int k = 0; k < (D == 3 ? 27 : 9); ++k) {
      IVec<D> c = home;
      int r = k;
      bool inside = true;
      for (int d = 0; d < D; ++d) {
        c[d] += r % 3 - 1;
        r /= 3;
        inside &= c[d] >= 0 && c[d] < cells_[d];
      }
      if (!inside) continue;
      const std::size_t cell = coverageIndex(c);
      for (std::uint32_t j = cellStart_[cell]; j < cellStart_[cell + 1]; ++j) {  // particles are in cell order
        const Vec<D> rel = x - position_[j];
        const double dist = rel.norm() * invL0;
        if (dist >= 1.0) continue;
        const double rho = 1.0 - dist * dist * (3.0 - 2.0 * dist);
        weights += rho * rho;
        for (int i = 0; i < octaves_; ++i) {
          if (amplitude[j][i] == 0.0f) continue;
          const double scale = std::ldexp(invL0, i);  // 1 / l_i
          const Vec<D> y = offset_[j] + rel * scale;
          const double w = rho * amplitude[j][i];
          for (int comp = 0; comp < kComponents; ++comp) acc[comp] += w * tile_.component(comp, y, time_[j][i]);
        }
      }
    }
    if (weights > 0.0) {
      const double norm = 1.0 / std::sqrt(weights);
      for (int comp = 0; comp < kComponents; ++comp) psi[a][comp] = static_cast<float>(acc[comp] * norm);
    }
  }, 256);
  curlOfNodalPotential<D>(fine, psi, turbulent);
}

template class NoiseParticles<2>;
template class NoiseParticles<3>;

}  // namespace msim::turbulence
