#include "msim/turbulence/noise_particles.hpp"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

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
double NoiseParticles<D>::energyAt(const TurbulentEnergy<D>& energy, const Grid<float, D>* energyFloor,
                                   const Vec<D>& x) const {
  double e0 = std::max(0.0f, sampleLinear<D>(energy.energy(), x));
  if (energyFloor) e0 = std::max(e0, double(sampleLinear<D>(*energyFloor, x)));
  return e0;
}

template <int D>
void NoiseParticles<D>::advance(const MacGrid<D>& velocity, const TurbulentEnergy<D>& energy, double dt,
                                const Grid<float, D>* energyFloor) {
  std::vector<std::uint8_t> keep(position_.size(), 1);
  parallelFor(0, position_.size(), [&](std::size_t j) {
    Vec<D>& p = position_[j];
    const Vec<D> mid = p + 0.5 * dt * sampleLinear<D>(velocity, p);
    p += dt * sampleLinear<D>(velocity, mid);
    if (!inFluid(p)) {
      keep[j] = 0;
      return;
    }
    const double e0 = energyAt(energy, energyFloor, p);
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
                                   const std::vector<float>* nodeWeight, const Grid<float, D>* energyFloor) {
  const GridSpec<D>& fine = turbulent.component(0).spec();
  // Per particle and octave: amplitude A_i = s sqrt(E_i) l_i and the noise's time tap.
  const std::size_t n = position_.size();
  amplitude_.resize(n);
  timeTap_.resize(n);
  parallelFor(0, n, [&](std::size_t j) {
    const double e0 = energyAt(energy, energyFloor, position_[j]);
    for (int i = 0; i < octaves_; ++i) {
      const double l = l0_ / std::ldexp(1.0, i);
      amplitude_[j][i] = static_cast<float>(params_.intensity * std::sqrt(energy.octaveEnergy(e0, i)) * l);
      timeTap_[j][i] = tile_.timeTap(time_[j][i]);
    }
  }, 1024);
  const IVec<D> nodes = fine.res + IVec<D>::Ones();
  std::size_t nodeCount = 1, rows = 1;
  for (int d = 0; d < D; ++d) nodeCount *= static_cast<std::size_t>(nodes[d]);
  for (int d = 1; d < D; ++d) rows *= static_cast<std::size_t>(nodes[d]);
  psi_.resize(nodeCount);
  const int rowLength = nodes[0];
  const double invL0 = 1.0 / l0_, h = fine.dx;
  // Row by row of nodes along x: a particle within l_0 of the row covers a run of its nodes, over
  // which the noise's rows (the other axes and time) stay fixed, so only the x tap varies.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows, 8), [&](const tbb::blocked_range<std::size_t>& range) {
    RowScratch& scratch = rowScratch_.local();  // kept per thread from step to step
    scratch.acc.resize(static_cast<std::size_t>(rowLength));
    scratch.weights.resize(static_cast<std::size_t>(rowLength));
    scratch.rho.resize(static_cast<std::size_t>(rowLength));
    std::vector<Vecf<3>>& acc = scratch.acc;
    std::vector<float>& weights = scratch.weights;
    std::vector<float>& rho = scratch.rho;
    for (std::size_t rowIndex = range.begin(); rowIndex != range.end(); ++rowIndex) {
      Vecf<3>* psiRow = psi_.data() + rowIndex * static_cast<std::size_t>(rowLength);
      const float* weightRow = nodeWeight ? nodeWeight->data() + rowIndex * static_cast<std::size_t>(rowLength) : nullptr;
      std::fill(psiRow, psiRow + rowLength, Vecf<3>::Zero());
      // The weighted nodes' extent along the row (every node without weights).
      int markedFirst = 0, markedEnd = rowLength;
      if (weightRow) {
        while (markedFirst < rowLength && weightRow[markedFirst] == 0.0f) ++markedFirst;
        while (markedEnd > markedFirst && weightRow[markedEnd - 1] == 0.0f) --markedEnd;
      }
      if (markedFirst == markedEnd) continue;
      // The row's position across x, and the coverage cells within l_0 of it.
      Vec<D> across = Vec<D>::Zero();
      IVec<D> lowCell = IVec<D>::Zero(), highCell = IVec<D>::Zero();
      std::size_t rest = rowIndex;
      for (int d = 1; d < D; ++d) {
        across[d] = fine.origin[d] + static_cast<double>(rest % nodes[d]) * h;
        rest /= nodes[d];
        const int home = coverageCoord(across)[d];
        lowCell[d] = std::max(0, home - 1);
        highCell[d] = std::min(cells_[d] - 1, home + 1);
      }
      highCell[0] = cells_[0] - 1;
      std::fill(acc.begin(), acc.end(), Vecf<3>::Zero());
      std::fill(weights.begin(), weights.end(), 0.0f);
      // Particles are in coverage-cell order with x fastest: each line of cells along x is one run.
      IVec<D> line = lowCell;
      while (true) {
        IVec<D> last = line;
        last[0] = highCell[0];
        for (std::uint32_t j = cellStart_[coverageIndex(line)]; j < cellStart_[coverageIndex(last) + 1]; ++j) {
          const Vec<D>& p = position_[j];
          double crossSquared = 0.0;
          for (int d = 1; d < D; ++d) crossSquared += (across[d] - p[d]) * (across[d] - p[d]);
          crossSquared *= invL0 * invL0;
          if (crossSquared >= 1.0) continue;
          const double halfWidth = l0_ * std::sqrt(1.0 - crossSquared);
          const int first = std::max(markedFirst, static_cast<int>(std::ceil((p[0] - halfWidth - fine.origin[0]) / h)));
          const int end = std::min(markedEnd, static_cast<int>(std::floor((p[0] + halfWidth - fine.origin[0]) / h)) + 1);
          if (first >= end) continue;
          for (int i = first; i < end; ++i) {
            const double dx = (fine.origin[0] + i * h - p[0]) * invL0;
            const double dist = std::sqrt(std::min(1.0, dx * dx + crossSquared));
            const float r = static_cast<float>(1.0 - dist * dist * (3.0 - 2.0 * dist));
            rho[static_cast<std::size_t>(i)] = r;
            weights[static_cast<std::size_t>(i)] += r;
          }
          for (int o = 0; o < octaves_; ++o) {
            if (amplitude_[j][o] == 0.0f) continue;
            const double scale = std::ldexp(invL0, o);  // 1 / l_o
            const Vec<D> y = offset_[j] + (across - p) * scale;  // x handled per node below
            const typename NoiseTile<D>::Row noiseRow = tile_.row(y, timeTap_[j][o]);
            const double x0 = offset_[j][0] + (fine.origin[0] - p[0]) * scale, step = h * scale;
            const float amplitude = amplitude_[j][o];
            for (int i = first; i < end; ++i)
              acc[static_cast<std::size_t>(i)] += (rho[static_cast<std::size_t>(i)] * amplitude) * tile_.onRow(noiseRow, x0 + i * step);
          }
        }
        int d = 1;
        for (; d < D; ++d) {
          if (++line[d] <= highCell[d]) break;
          line[d] = lowCell[d];
        }
        if (d == D) break;
      }
      for (int i = 0; i < rowLength; ++i) {
        if (weights[static_cast<std::size_t>(i)] > 0.0f)
          psiRow[i] = acc[static_cast<std::size_t>(i)] * ((weightRow ? weightRow[i] : 1.0f) / weights[static_cast<std::size_t>(i)]);
      }
    }
  });
  curlOfNodalPotential<D>(fine, psi_, turbulent);
}

template class NoiseParticles<2>;
template class NoiseParticles<3>;

}  // namespace msim::turbulence
