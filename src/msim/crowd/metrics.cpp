#include "msim/crowd/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "msim/core/parallel.hpp"
#include "msim/crowd/neighbour_grid.hpp"

namespace msim::crowd {
namespace {

void requireFinite(std::span<const Vec2f> v, const char* what) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!v[i].allFinite()) throw std::invalid_argument(std::string(what) + " " + std::to_string(i) + " is not finite");
}

}  // namespace

Grid<double, 2> gridDensity(const GridSpec<2>& spec, std::span<const Vec2f> positions,
                            const Grid<double, 2>* freeFraction) {
  requireFinite(positions, "gridDensity: position");
  if (freeFraction && (freeFraction->spec() != spec || freeFraction->size() != spec.res))
    throw std::invalid_argument("gridDensity: the free-fraction grid must be cell-centred over the same spec");
  Grid<double, 2> density(spec, 0.0);
  // Serial scatter: counting is cheap next to the neighbour search, and it stays deterministic.
  for (const Vec2f& p : positions) {
    const Vec2 rel = (p.cast<double>() - spec.origin) / spec.dx;
    const IVec2 c(static_cast<int>(std::floor(rel.x())), static_cast<int>(std::floor(rel.y())));
    if (density.inside(c)) density(c) += 1.0;
  }
  const double cellArea = spec.dx * spec.dx;
  for (std::size_t k = 0; k < density.count(); ++k) {
    const double f = freeFraction ? (*freeFraction)[k] : 1.0;
    density[k] = f > 0.0 ? density[k] / (cellArea * f) : 0.0;
  }
  return density;
}

double percentile(std::span<const double> sorted, double q) {
  if (sorted.empty()) throw std::invalid_argument("percentile: no values");
  const double h = std::clamp(q, 0.0, 1.0) * static_cast<double>(sorted.size() - 1);
  const std::size_t k = static_cast<std::size_t>(std::floor(h));
  if (k + 1 >= sorted.size()) return sorted.back();
  return sorted[k] + (h - static_cast<double>(k)) * (sorted[k + 1] - sorted[k]);
}

SpeedStats speedStats(std::span<const Vec2f> velocities) {
  requireFinite(velocities, "speedStats: velocity");
  SpeedStats s;
  s.count = velocities.size();
  if (s.count == 0) return s;
  std::vector<double> speed(s.count);
  for (std::size_t i = 0; i < s.count; ++i) speed[i] = velocities[i].cast<double>().norm();
  std::sort(speed.begin(), speed.end());
  double sum = 0.0;
  for (double v : speed) sum += v;
  s.mean = sum / static_cast<double>(s.count);
  double var = 0.0;
  for (double v : speed) var += (v - s.mean) * (v - s.mean);
  s.stddev = std::sqrt(var / static_cast<double>(s.count));
  s.min = speed.front();
  s.max = speed.back();
  s.p05 = percentile(speed, 0.05);
  s.p25 = percentile(speed, 0.25);
  s.median = percentile(speed, 0.5);
  s.p75 = percentile(speed, 0.75);
  s.p95 = percentile(speed, 0.95);
  return s;
}

NearestNeighbours nearestNeighbours(std::span<const Vec2f> positions, std::span<const float> radii,
                                    double searchRadius) {
  if (radii.size() != positions.size()) throw std::invalid_argument("nearestNeighbours: one radius per agent");
  requireFinite(positions, "nearestNeighbours: position");
  for (std::size_t i = 0; i < radii.size(); ++i)
    if (!(radii[i] > 0.0f) || !std::isfinite(radii[i]))
      throw std::invalid_argument("nearestNeighbours: radius " + std::to_string(i) + " must be > 0");
  if (!(searchRadius > 0.0) || !std::isfinite(searchRadius))
    throw std::invalid_argument("nearestNeighbours: searchRadius must be > 0");

  const std::size_t n = positions.size();
  const double inf = std::numeric_limits<double>::infinity();
  NearestNeighbours nn{std::vector<double>(n, inf), std::vector<double>(n, inf)};
  if (n == 0) return nn;
  NeighbourGrid grid;
  grid.build(positions, static_cast<float>(searchRadius));
  parallelFor(0, n, [&](std::size_t i) {
    const Vec2 xi = positions[i].cast<double>();
    grid.forEachNeighbour(i, static_cast<float>(searchRadius), [&](std::size_t j) {
      // Distances in double from the float positions, so a lattice of spacing a gives a exactly
      // up to the rounding of the positions themselves.
      const double d = (positions[j].cast<double>() - xi).norm();
      const double ratio = d / (static_cast<double>(radii[i]) + radii[j]);
      if (ratio < nn.ratio[i]) {
        nn.ratio[i] = ratio;
        nn.distance[i] = d;
      }
    });
  }, 256);
  return nn;
}

double NearestNeighbourFrame::meanDenseRatio() const {
  return dense > 0 ? denseRatioSum / static_cast<double>(dense) : std::numeric_limits<double>::quiet_NaN();
}

double NearestNeighbourFrame::fractionCloser() const {
  return agents > 0 ? static_cast<double>(closer) / static_cast<double>(agents) : 0.0;
}

NearestNeighbourFrame nearestNeighbourFrame(const NearestNeighbours& nn, std::span<const double> localDensity,
                                            const NearestNeighbourOptions& options) {
  if (localDensity.size() != nn.ratio.size())
    throw std::invalid_argument("nearestNeighbourFrame: one local density per agent");
  if (!(options.rhoMax > 0.0) || !std::isfinite(options.rhoMax))
    throw std::invalid_argument("nearestNeighbourFrame: rhoMax must be > 0");
  const double threshold = options.denseFraction * options.rhoMax;
  const double contact = 1.0 - options.contactTolerance;
  NearestNeighbourFrame f;
  f.agents = nn.ratio.size();
  for (std::size_t i = 0; i < f.agents; ++i) {
    const double r = nn.ratio[i];
    const bool closer = r < contact;
    f.closer += closer;
    f.minRatio = std::min(f.minRatio, r);
    if (std::isfinite(r) && localDensity[i] >= threshold) {
      ++f.dense;
      f.denseCloser += closer;
      f.denseRatioSum += r;
    }
  }
  return f;
}

void NearestNeighbourAccumulator::add(const NearestNeighbourFrame& frame) {
  total_.agents += frame.agents;
  total_.closer += frame.closer;
  total_.dense += frame.dense;
  total_.denseCloser += frame.denseCloser;
  total_.denseRatioSum += frame.denseRatioSum;
  total_.minRatio = std::min(total_.minRatio, frame.minRatio);
  ++frames_;
}

}  // namespace msim::crowd
