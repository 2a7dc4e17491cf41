#include "msim/fluid/liquid/flip_particles.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <stdexcept>
#include <utility>

#include "msim/core/interpolation.hpp"
#include "msim/core/parallel.hpp"
#include "msim/core/rng.hpp"

namespace msim::fluid {

namespace {

template <int D>
Vecf<D> insideDomain(const GridSpec<D>& spec, Vecf<D> x) {
  const double margin = 1e-3 * spec.dx;
  for (int a = 0; a < D; ++a)
    x[a] = static_cast<float>(
        std::clamp(double(x[a]), spec.origin[a] + margin, spec.origin[a] + spec.res[a] * spec.dx - margin));
  return x;
}

}  // namespace

template <int D>
FlipParticles<D>::FlipParticles(const GridSpec<D>& spec, int perCell, std::uint64_t seed)
    : spec_(spec), perCell_(perCell > 0 ? perCell : (1 << D)), seed_(seed), radius_(0.5 * spec.dx),
      owned_{IVec<D>::Zero(), spec.res} {}

template <int D>
void FlipParticles<D>::setBlock(const BlockPlacement<D>& placement, const IndexBox<D>& owned) {
  placement_ = placement;
  owned_ = owned;
}

template <int D>
void FlipParticles<D>::appendRowsTo(const std::vector<double>& rows, std::vector<Vecf<D>>& positions,
                                    std::vector<Vecf<D>>& velocities) {
  for (std::size_t at = 0; at + kRowWidth <= rows.size(); at += kRowWidth) {
    Vecf<D> x, v;
    for (int a = 0; a < D; ++a) {
      x[a] = static_cast<float>(rows[at + a]);
      v[a] = static_cast<float>(rows[at + D + a]);
    }
    positions.push_back(x);
    velocities.push_back(v);
  }
}

template <int D>
void FlipParticles<D>::appendRows(const std::vector<double>& rows) {
  appendRowsTo(rows, positions_, velocities_);
}

template <int D>
void FlipParticles<D>::setNeighbours(const std::vector<double>& rows) {
  neighbours_ = rows.size() / kRowWidth;
  withNeighbours_.assign(positions_.begin(), positions_.end());
  withNeighboursV_.assign(velocities_.begin(), velocities_.end());
  appendRowsTo(rows, withNeighbours_, withNeighboursV_);
}

template <int D>
std::span<const Vecf<D>> FlipParticles<D>::readPositions() const {
  return neighbours_ > 0 ? std::span<const Vecf<D>>(withNeighbours_) : std::span<const Vecf<D>>(positions_);
}

template <int D>
std::span<const Vecf<D>> FlipParticles<D>::readVelocities() const {
  return neighbours_ > 0 ? std::span<const Vecf<D>>(withNeighboursV_) : std::span<const Vecf<D>>(velocities_);
}

template <int D>
void FlipParticles<D>::seed(const Grid<float, D>& phi, const Grid<float, D>& solid, const MacGrid<D>& velocity) {
  positions_.clear();
  velocities_.clear();
  for (std::size_t cell = 0; cell < phi.count(); ++cell) {
    const IVec<D> c = phi.coord(cell);
    if (!(phi[cell] < 0.5f * spec_.dx) || solid[cell] > 0.5f || !owned_.contains(c)) continue;  // the surface cells too
    Rng rng = Rng(seed_).split(placement_.globalIndex(c, cell));
    for (int k = 0; k < perCell_; ++k) {
      Vec<D> x;
      // Stratified when perCell is 2^D: one particle per sub-cell, jittered by up to 0.05 dx about
      // its centre. A full sub-cell of jitter makes the rebuilt surface bumpy, and a still tank
      // then sloshes at 0.1-0.2 m/s (2D, 40^2).
      for (int a = 0; a < D; ++a) {
        const double sub = perCell_ == (1 << D) ? 0.5 * ((k >> a) & 1) + 0.25 + 0.1 * (rng.uniform() - 0.5) : rng.uniform();
        x[a] = spec_.origin[a] + (c[a] + sub) * spec_.dx;
      }
      if (!(sampleLinear<D>(phi, x) < 0.0f)) continue;
      positions_.push_back(x.template cast<float>());
      velocities_.push_back(sampleLinear<D>(velocity, x).template cast<float>());
    }
  }
}

template <int D>
void FlipParticles<D>::assign(std::vector<Vecf<D>> positions, std::vector<Vecf<D>> velocities) {
  if (velocities.size() != positions.size())
    throw std::invalid_argument("FLIP particles: positions and velocities differ in length");
  positions_ = std::move(positions);
  velocities_ = std::move(velocities);
}

template <int D>
void FlipParticles<D>::advect(const MacGrid<D>& velocity, double dt, const Grid<float, D>* solidDistance,
                              const Grid<float, D>& solid, const numerics::DomainSides<D>& sides) {
  flagged_.assign(positions_.size(), 0);
  parallelFor(0, positions_.size(), [&](std::size_t p) {
    const Vec<D> x = positions_[p].template cast<double>();
    const Vec<D> mid = insideDomain<D>(spec_, Vec<D>(x + 0.5 * dt * sampleLinear<D>(velocity, x)).template cast<float>())
                           .template cast<double>();
    const Vec<D> free = x + dt * sampleLinear<D>(velocity, mid);
    for (int a = 0; a < D; ++a) {
      const double lo = spec_.origin[a], hi = lo + spec_.res[a] * spec_.dx;
      if ((sides.side[a][0] == numerics::DomainSide::Open && free[a] < lo) ||
          (sides.side[a][1] == numerics::DomainSide::Open && free[a] > hi))
        flagged_[p] = 1;
    }
    Vec<D> next = insideDomain<D>(spec_, free.template cast<float>()).template cast<double>();
    auto inSolidCell = [&](const Vec<D>& y) { return solid[spec_.clampedCellIndex(y.template cast<float>())] > 0.5f; };
    if (solidDistance) {
      const double d = sampleLinear<D>(*solidDistance, next);
      if (d < 0.0 || inSolidCell(next)) {
        // Out along the distance's gradient: to just outside the surface, then on by quarter cells
        // out of a cell whose centre is inside. Where that does not get out (a corner), the
        // particle stays where it was.
        Vec<D> g;
        const double h = 0.5 * spec_.dx;
        for (int a = 0; a < D; ++a) {
          Vec<D> up = next, down = next;
          up[a] += h;
          down[a] -= h;
          g[a] = (sampleLinear<D>(*solidDistance, up) - sampleLinear<D>(*solidDistance, down)) / (2.0 * h);
        }
        const double norm = g.norm();
        if (norm > 0.0) {
          const Vec<D> n = g / norm;
          if (d < 0.0) next -= (d - 1e-3 * spec_.dx) * n;
          for (int k = 0; k < 4 && inSolidCell(next); ++k) next += 0.25 * spec_.dx * n;
          next = insideDomain<D>(spec_, next.template cast<float>()).template cast<double>();
        }
        if (norm == 0.0 || sampleLinear<D>(*solidDistance, next) < 0.0 || inSolidCell(next)) next = x;
      }
    }
    positions_[p] = next.template cast<float>();
  });
  removeFlagged();
}

template <int D>
std::size_t FlipParticles<D>::removeFlagged() {
  std::size_t kept = 0;
  for (std::size_t p = 0; p < positions_.size(); ++p) {
    if (flagged_[p]) continue;
    positions_[kept] = positions_[p];
    velocities_[kept] = velocities_[p];
    ++kept;
  }
  const std::size_t removed = positions_.size() - kept;
  positions_.resize(kept);
  velocities_.resize(kept);
  return removed;
}

template <int D>
std::size_t FlipParticles<D>::removeInside(const Grid<float, D>& region) {
  flagged_.assign(positions_.size(), 0);
  parallelFor(0, positions_.size(), [&](std::size_t p) { flagged_[p] = sampleLinear<D>(region, positions_[p].template cast<double>()) < 0.0f; });
  return removeFlagged();
}

template <int D>
std::size_t FlipParticles<D>::emit(const Grid<float, D>& region, const Grid<float, D>& solid, const Vecf<D>& velocity,
                                   std::uint64_t round) {
  parallelFor(0, positions_.size(), [&](std::size_t p) {
    if (sampleLinear<D>(region, positions_[p].template cast<double>()) < 0.0f) velocities_[p] = velocity;
  });
  bucketByCell(positions_);
  const std::size_t before = positions_.size();
  for (std::size_t cell = 0; cell < region.count(); ++cell) {
    const IVec<D> c = region.coord(cell);
    if (!(region[cell] < 0.0f) || solid[cell] > 0.5f || !owned_.contains(c)) continue;
    const int have = static_cast<int>(cellStart_[cell + 1] - cellStart_[cell]);
    if (2 * have >= perCell_) continue;  // refilled when half empty: fuller cells hold the flux at v A
    Rng rng = Rng(seed_ ^ (round * 0x9E3779B97F4A7C15ull)).split(placement_.globalIndex(c, cell));
    for (int k = have; k < perCell_; ++k) {
      Vecf<D> x;
      for (int a = 0; a < D; ++a) x[a] = static_cast<float>(spec_.origin[a] + (c[a] + rng.uniform()) * spec_.dx);
      positions_.push_back(x);
      velocities_.push_back(velocity);
    }
  }
  return positions_.size() - before;
}

template <int D>
void FlipParticles<D>::toGrid(MacGrid<D>& velocity) {
  splatter_.splat(readPositions(), readVelocities(), velocity, TransferKernel::Linear, SplatMode::Normalized, 0.0f);
}

template <int D>
void FlipParticles<D>::fromGrid(const MacGrid<D>& updated, const MacGrid<D>& before, double flipRatio) {
  gatheredNew_.resize(positions_.size());
  gatheredOld_.resize(positions_.size());
  gather<D, 2>({&updated, &before}, std::span<const Vecf<D>>(positions_), TransferKernel::Linear,
               {std::span<Vecf<D>>(gatheredNew_), std::span<Vecf<D>>(gatheredOld_)});
  const float r = static_cast<float>(flipRatio);
  parallelFor(0, positions_.size(), [&](std::size_t p) {
    velocities_[p] = r * (velocities_[p] + gatheredNew_[p] - gatheredOld_[p]) + (1.0f - r) * gatheredNew_[p];
  });
}

template <int D>
void FlipParticles<D>::bucketByCell(std::span<const Vecf<D>> x) const {
  // A counting sort by cell (core's BucketSort keeps a histogram per block and bucket, too large
  // with a bucket per cell).
  const std::size_t cells = spec_.cellCount();
  cellStart_.assign(cells + 1, 0);
  cellOf_.resize(x.size());
  parallelFor(0, x.size(), [&](std::size_t p) { cellOf_[p] = static_cast<std::uint32_t>(spec_.clampedCellIndex(x[p])); });
  for (const std::uint32_t c : cellOf_) ++cellStart_[c + 1];
  for (std::size_t c = 0; c < cells; ++c) cellStart_[c + 1] += cellStart_[c];
  order_.resize(x.size());
  next_.assign(cellStart_.begin(), cellStart_.end() - 1);
  for (std::size_t p = 0; p < x.size(); ++p) order_[next_[cellOf_[p]]++] = static_cast<std::uint32_t>(p);
}

template <int D>
void FlipParticles<D>::surface(Grid<float, D>& phi, double bandCells) const {
  if (!phi.sameLayout(Grid<float, D>(spec_))) throw std::invalid_argument("FLIP surface: phi must be cell-centred");
  const std::span<const Vecf<D>> particles = readPositions();
  bucketByCell(particles);
  const float band = static_cast<float>(bandCells * spec_.dx);
  const double R = 4.0 * radius_;  // kernel radius: 2 dx
  const int reach = 2;             // cells within R of a cell centre
  auto count = [&](std::size_t cell) { return cellStart_[cell + 1] - cellStart_[cell]; };
  parallelForCells(phi, [&](const IVec<D>& c, std::size_t cell) {
    IVec<D> lo, hi;
    for (int a = 0; a < D; ++a) {
      lo[a] = std::max(0, c[a] - reach);
      hi[a] = std::min(spec_.res[a] - 1, c[a] + reach);
    }
    // Visits the cells of the box [lo, hi] (D-linear index order).
    auto forBox = [&](const IVec<D>& from, const IVec<D>& to, auto&& f) {
      IVec<D> n = from;
      while (true) {
        f(n);
        int a = 0;
        for (; a < D; ++a) {
          if (++n[a] <= to[a]) break;
          n[a] = from[a];
        }
        if (a == D) return;
      }
    };
    // Deep inside: the cell and its face and corner neighbours all hold particles (their kernel
    // sums would only give about -r; the reinitialisation fills in the distance).
    IVec<D> lo1, hi1;
    for (int a = 0; a < D; ++a) {
      lo1[a] = std::max(0, c[a] - 1);
      hi1[a] = std::min(spec_.res[a] - 1, c[a] + 1);
    }
    bool deep = true;
    forBox(lo1, hi1, [&](const IVec<D>& n) { deep = deep && count(phi.index(n)) > 0; });
    if (deep) {
      phi[cell] = -band;
      return;
    }
    Vec<D> weighted = Vec<D>::Zero();
    double weights = 0.0;
    const Vec<D> x = phi.position(c);
    forBox(lo, hi, [&](const IVec<D>& n) {
      const std::size_t nc = phi.index(n);
      for (std::uint32_t k = cellStart_[nc]; k < cellStart_[nc + 1]; ++k) {
        const Vec<D> xp = particles[order_[k]].template cast<double>();
        const double s2 = (xp - x).squaredNorm() / (R * R);
        if (s2 >= 1.0) continue;
        const double w = (1.0 - s2) * (1.0 - s2) * (1.0 - s2);
        weighted += w * xp;
        weights += w;
      }
    });
    phi[cell] = weights > 0.0 ? static_cast<float>(std::clamp((x - weighted / weights).norm() - radius_, -double(band),
                                                              double(band)))
                              : band;
  });
}

template class FlipParticles<2>;
template class FlipParticles<3>;

}  // namespace msim::fluid
