#include "msim/numerics/level_set/particle_level_set.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "msim/core/interpolation.hpp"
#include "msim/core/parallel.hpp"
#include "msim/core/rng.hpp"

namespace msim::numerics {

namespace {

template <int D>
Vec<D> unitNormal(const Grid<float, D>& phi, const Vec<D>& x) {
  const double h = 0.5 * phi.spec().dx;
  Vec<D> g;
  for (int a = 0; a < D; ++a) {
    Vec<D> lo = x, hi = x;
    lo[a] -= h;
    hi[a] += h;
    g[a] = (sampleLinear<D>(phi, hi) - sampleLinear<D>(phi, lo)) / (2.0 * h);
  }
  const double n = g.norm();
  return n > 0.0 ? Vec<D>(g / n) : Vec<D>::Zero();
}

template <int D>
Vec<D> clampToDomain(const GridSpec<D>& spec, Vec<D> x) {
  for (int a = 0; a < D; ++a) x[a] = std::clamp(x[a], spec.origin[a], spec.origin[a] + spec.res[a] * spec.dx);
  return x;
}

}  // namespace

template <int D>
ParticleLevelSet<D>::ParticleLevelSet(const GridSpec<D>& spec, const ParticleLevelSetSettings& settings)
    : spec_(spec),
      settings_(settings),
      perCell_(settings.particlesPerCell > 0 ? settings.particlesPerCell : (D == 2 ? 16 : 32)),
      owned_{IVec<D>::Zero(), spec.res} {
  const auto& s = settings_;
  if (!(s.bandCells > 0.0) || !(s.minRadiusCells > 0.0) || !(s.maxRadiusCells >= s.minRadiusCells) ||
      !(s.minSeedCells >= 0.0) || !(s.maxSeedCells > s.minSeedCells) || s.attractionIterations < 1)
    throw std::invalid_argument("particle level set: band, radii and seeding range must be positive and ordered");
}

template <int D>
void ParticleLevelSet<D>::setBlock(const BlockPlacement<D>& placement, const IndexBox<D>& owned) {
  placement_ = placement;
  owned_ = owned;
}

template <int D>
void ParticleLevelSet<D>::appendRows(const std::vector<double>& rows) {
  for (std::size_t at = 0; at + kRowWidth <= rows.size(); at += kRowWidth) {
    Vec<D> x;
    for (int a = 0; a < D; ++a) x[a] = rows[at + a];
    positions_.push_back(x);
    radii_.push_back(static_cast<float>(rows[at + D]));
    signs_.push_back(rows[at + D + 1] < 0.0 ? -1 : 1);
  }
}

template <int D>
void ParticleLevelSet<D>::seedCell(const Grid<float, D>& phi, const IVec<D>& c, int count, std::uint64_t stream) {
  Rng rng = Rng(settings_.seed).split(round_).split(stream);
  const double dx = spec_.dx;
  const double lo = settings_.minSeedCells * dx, hi = settings_.maxSeedCells * dx;
  for (int k = 0; k < count; ++k) {
    Vec<D> x;
    for (int a = 0; a < D; ++a) x[a] = spec_.origin[a] + (c[a] + rng.uniform()) * dx;
    const double sign = sampleLinear<D>(phi, x) < 0.0f ? -1.0 : 1.0;
    const double goal = sign * rng.uniform(lo, hi);
    double lambda = 1.0;
    bool placed = false;
    for (int it = 0; it < settings_.attractionIterations; ++it) {
      const double p = sampleLinear<D>(phi, x);
      if (sign * p >= lo && sign * p <= hi) {
        placed = true;
        break;
      }
      const Vec<D> n = unitNormal(phi, x);
      if (n.isZero()) break;
      const Vec<D> next = clampToDomain(spec_, Vec<D>(x + lambda * (goal - p) * n));
      // Halve the step when it lands farther from the goal (Enright's lambda).
      if (std::abs(goal - sampleLinear<D>(phi, next)) > std::abs(goal - p)) lambda *= 0.5;
      x = next;
    }
    if (!placed) continue;
    const double radius = std::clamp(sign * double(sampleLinear<D>(phi, x)), settings_.minRadiusCells * dx,
                                     settings_.maxRadiusCells * dx);
    positions_.push_back(x);
    radii_.push_back(static_cast<float>(radius));
    signs_.push_back(static_cast<std::int8_t>(sign));
  }
}

template <int D>
void ParticleLevelSet<D>::seed(const Grid<float, D>& phi) {
  positions_.clear();
  radii_.clear();
  signs_.clear();
  round_ = 0;
  const float band = static_cast<float>(settings_.bandCells * spec_.dx);
  for (std::size_t i = 0; i < phi.count(); ++i) {
    const IVec<D> c = phi.coord(i);
    if (std::abs(phi[i]) < band && owned_.contains(c)) seedCell(phi, c, perCell_, placement_.globalIndex(c, i));
  }
}

template <int D>
void ParticleLevelSet<D>::assign(std::vector<Vec<D>> positions, std::vector<float> radii,
                                 std::vector<std::int8_t> signs) {
  if (radii.size() != positions.size() || signs.size() != positions.size())
    throw std::invalid_argument("particle level set: positions, radii and signs differ in length");
  positions_ = std::move(positions);
  radii_ = std::move(radii);
  signs_ = std::move(signs);
}

template <int D>
void ParticleLevelSet<D>::advect(const MacGrid<D>& velocity, double dt) {
  parallelFor(0, positions_.size(), [&](std::size_t p) {
    const Vec<D> x = positions_[p];
    const Vec<D> mid = clampToDomain(spec_, Vec<D>(x + 0.5 * dt * sampleLinear<D>(velocity, x)));
    positions_[p] = clampToDomain(spec_, Vec<D>(x + dt * sampleLinear<D>(velocity, mid)));
  });
}

template <int D>
std::size_t ParticleLevelSet<D>::correct(Grid<float, D>& phi) const {
  // The own particles, then the neighbours' copies (rows), as (position, radius, sign).
  const std::size_t own = positions_.size(), count = own + neighbours_.size() / kRowWidth;
  const auto particle = [&](std::size_t p, Vec<D>& x, double& radius, int& sign) {
    if (p < own) {
      x = positions_[p];
      radius = radii_[p];
      sign = signs_[p];
      return;
    }
    const double* row = &neighbours_[(p - own) * kRowWidth];
    for (int a = 0; a < D; ++a) x[a] = row[a];
    radius = static_cast<float>(row[D]);
    sign = row[D + 1] < 0.0 ? -1 : 1;
  };
  std::vector<std::size_t>& escaped = escaped_;
  escaped.clear();
  Vec<D> x;
  double radius = 0.0;
  int sign = 1;
  for (std::size_t p = 0; p < count; ++p) {
    particle(p, x, radius, sign);
    if (sign * sampleLinear<D>(phi, x) < -radius) escaped.push_back(p);
  }
  if (escaped.empty()) return 0;
  // phi+ and phi- start as phi (copied into storage kept across steps).
  Grid<float, D>& plus = plus_;
  Grid<float, D>& minus = minus_;
  plus = phi;
  minus = phi;
  for (const std::size_t p : escaped) {
    particle(p, x, radius, sign);
    // The 2^D cell centres around the particle (those its interpolation reads).
    const Vec<D> s = phi.toSampleSpace(x);
    IVec<D> base;
    for (int a = 0; a < D; ++a) base[a] = std::clamp(static_cast<int>(std::floor(s[a])), 0, phi.size()[a] - 2);
    for (int corner = 0; corner < (1 << D); ++corner) {
      IVec<D> c = base;
      for (int a = 0; a < D; ++a) c[a] += (corner >> a) & 1;
      const std::size_t i = phi.index(c);
      const float sphere = static_cast<float>(sign * (radius - (phi.position(c) - x).norm()));
      if (sign > 0)
        plus[i] = std::max(plus[i], sphere);
      else
        minus[i] = std::min(minus[i], sphere);
    }
  }
  parallelFor(0, phi.count(), [&](std::size_t i) {
    phi[i] = std::abs(plus[i]) <= std::abs(minus[i]) ? plus[i] : minus[i];
  });
  return static_cast<std::size_t>(std::count_if(escaped.begin(), escaped.end(), [&](std::size_t p) { return p < own; }));
}

template <int D>
void ParticleLevelSet<D>::adjustRadii(const Grid<float, D>& phi) {
  const double lo = settings_.minRadiusCells * spec_.dx, hi = settings_.maxRadiusCells * spec_.dx;
  parallelFor(0, positions_.size(), [&](std::size_t p) {
    radii_[p] = static_cast<float>(std::clamp(signs_[p] * double(sampleLinear<D>(phi, positions_[p])), lo, hi));
  });
}

template <int D>
void ParticleLevelSet<D>::reseed(const Grid<float, D>& phi) {
  ++round_;
  const float band = static_cast<float>(settings_.bandCells * spec_.dx);
  keepIf([&](std::size_t p) {
    const float value = sampleLinear<D>(phi, positions_[p]);
    return std::abs(value) <= band && !(settings_.deleteEscapedOnReseed && signs_[p] * value < -radii_[p]);
  });
  std::vector<int>& count = cellCount_;
  count.assign(phi.count(), 0);
  for (const Vec<D>& x : positions_) ++count[spec_.clampedCellIndex(x)];
  for (std::size_t i = 0; i < phi.count(); ++i) {
    const IVec<D> c = phi.coord(i);
    if (std::abs(phi[i]) < band && count[i] < perCell_ && owned_.contains(c)) seedCell(phi, c, perCell_ - count[i], placement_.globalIndex(c, i));
  }
}

template <int D>
std::size_t ParticleLevelSet<D>::removeInside(const Grid<float, D>& region) {
  return keepIf([&](std::size_t p) { return !(sampleLinear<D>(region, positions_[p]) < 0.0f); });
}

template class ParticleLevelSet<2>;
template class ParticleLevelSet<3>;

}  // namespace msim::numerics
