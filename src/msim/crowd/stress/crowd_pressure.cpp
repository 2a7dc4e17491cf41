#include "msim/crowd/stress/crowd_pressure.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace msim::crowd::stress {

CrowdWindows::CrowdWindows(const GridSpec<2>& spec, int window)
    : spec_(spec), window_(window), own_(spec.cellCount()), totals_(spec.cellCount()) {
  if (window < 0) throw std::invalid_argument("crowd pressure: the window must be >= 0 cells");
}

void CrowdWindows::gather(std::span<const Vec2f> positions, std::span<const Vec2f> velocities) {
  if (positions.size() != velocities.size()) throw std::invalid_argument("crowd pressure: positions and velocities differ in number");
  for (const std::uint32_t c : touched_) totals_[c] = Sums{};
  occupied_.clear();
  touched_.clear();
  for (std::size_t k = 0; k < positions.size(); ++k) {
    const std::size_t c = spec_.clampedCellIndex(positions[k]);
    Sums& own = own_[c];
    if (own.count == 0.0) occupied_.push_back(static_cast<std::uint32_t>(c));
    own.count += 1.0;
    own.vx += velocities[k].x();
    own.vy += velocities[k].y();
    own.v2 += velocities[k].squaredNorm();
  }
  const int nx = spec_.res.x(), ny = spec_.res.y();
  for (const std::uint32_t home : occupied_) {
    const int i = static_cast<int>(home % static_cast<std::uint32_t>(nx)), j = static_cast<int>(home / static_cast<std::uint32_t>(nx));
    const Sums& own = own_[home];
    for (int b = std::max(0, j - window_); b <= std::min(ny - 1, j + window_); ++b)
      for (int a = std::max(0, i - window_); a <= std::min(nx - 1, i + window_); ++a) {
        const std::uint32_t c = static_cast<std::uint32_t>(a + nx * b);
        Sums& w = totals_[c];
        if (w.count == 0.0) touched_.push_back(c);
        w.count += own.count;
        w.vx += own.vx;
        w.vy += own.vy;
        w.v2 += own.v2;
      }
  }
  for (const std::uint32_t c : occupied_) own_[c] = Sums{};
}

double CrowdWindows::area(std::size_t c) const {
  const int nx = spec_.res.x(), ny = spec_.res.y();
  const int i = static_cast<int>(c % static_cast<std::size_t>(nx)), j = static_cast<int>(c / static_cast<std::size_t>(nx));
  const int cells = (std::min(nx - 1, i + window_) - std::max(0, i - window_) + 1) *
                    (std::min(ny - 1, j + window_) - std::max(0, j - window_) + 1);
  return cells * spec_.dx * spec_.dx;
}

namespace {

void requireSameGrid(const GridSpec<2>& sampled, const Grid<float, 2>& out) {
  if (!(out.spec() == sampled)) throw std::invalid_argument("crowd pressure: the output grid differs from the sampled one");
}

}  // namespace

void spatialPressure(const CrowdWindows& windows, Grid<float, 2>& pressure) {
  requireSameGrid(windows.spec(), pressure);
  pressure.fill(0.0f);
  for (const std::uint32_t c : windows.cells()) {
    const CrowdWindows::Sums& w = windows.sums(c);
    if (w.count < 2.0) continue;
    const double variance = std::max(0.0, w.v2 / w.count - (w.vx * w.vx + w.vy * w.vy) / (w.count * w.count));
    pressure[c] = static_cast<float>(windows.density(c) * variance);
  }
}

double meanLocalSpeed(const CrowdWindows& windows) {
  double weighted = 0.0, weight = 0.0;
  for (const std::uint32_t c : windows.cells()) {
    const CrowdWindows::Sums& w = windows.sums(c);
    weighted += std::hypot(w.vx, w.vy);  // count x |mean velocity|
    weight += w.count;
  }
  return weight > 0.0 ? weighted / weight : 0.0;
}

StrainRateSummary strainRate(const CrowdWindows& windows, Grid<float, 2>& strain) {
  requireSameGrid(windows.spec(), strain);
  const GridSpec<2>& spec = windows.spec();
  const int nx = spec.res.x(), ny = spec.res.y();
  // The window-mean velocity of a cell whose window holds someone, or nothing.
  const auto mean = [&](int a, int b, Vec2& v) {
    if (a < 0 || b < 0 || a >= nx || b >= ny) return false;
    const CrowdWindows::Sums& w = windows.sums(static_cast<std::size_t>(a + nx * b));
    if (w.count == 0.0) return false;
    v = Vec2(w.vx, w.vy) / w.count;
    return true;
  };
  // d v / d(axis) at cell (i, j): central where both neighbours have a velocity, one-sided where one does.
  const auto derivative = [&](int i, int j, int di, int dj, const Vec2& here) -> Vec2 {
    Vec2 lo = Vec2::Zero(), hi = Vec2::Zero();
    const bool hasLo = mean(i - di, j - dj, lo), hasHi = mean(i + di, j + dj, hi);
    if (hasLo && hasHi) return (hi - lo) / (2.0 * spec.dx);
    if (hasHi) return (hi - here) / spec.dx;
    if (hasLo) return (here - lo) / spec.dx;
    return Vec2::Zero();
  };
  strain.fill(0.0f);
  StrainRateSummary summary;
  double sum = 0.0, sum2 = 0.0;
  for (const std::uint32_t c : windows.cells()) {
    const int i = static_cast<int>(c % static_cast<std::uint32_t>(nx)), j = static_cast<int>(c / static_cast<std::uint32_t>(nx));
    Vec2 here = Vec2::Zero();  // every listed cell's window holds someone
    mean(i, j, here);
    const Vec2 dx = derivative(i, j, 1, 0, here), dy = derivative(i, j, 0, 1, here);  // dv/dx, dv/dy
    const double exx = 2.0 * dx.x(), eyy = 2.0 * dy.y(), exy = dy.x() + dx.y();
    const double e = std::sqrt(exx * exx + eyy * eyy + 2.0 * exy * exy);
    strain[c] = static_cast<float>(e);
    sum += e;
    sum2 += e * e;
    summary.max = std::max(summary.max, e);
    ++summary.cells;
  }
  if (summary.cells > 0) {
    summary.mean = sum / double(summary.cells);
    const double spread = std::sqrt(std::max(0.0, sum2 / double(summary.cells) - summary.mean * summary.mean));
    summary.variation = summary.mean > 0.0 ? spread / summary.mean : 0.0;
  }
  return summary;
}

TemporalPressure::TemporalPressure(const GridSpec<2>& spec, double seconds)
    : spec_(spec), rate_(std::log(2.0) / (0.5 * seconds)), cells_(spec.cellCount()) {
  if (!(seconds > 0.0)) throw std::invalid_argument("crowd pressure: the time window must be > 0 s");
}

double TemporalPressure::decay(double elapsed) const { return std::exp(-rate_ * elapsed); }

void TemporalPressure::add(const CrowdWindows& windows, double dt) {
  if (!(windows.spec() == spec_)) throw std::invalid_argument("crowd pressure: the windows lie on another grid");
  const double previous = time_, stepDecay = decay(dt);
  time_ += dt;
  total_ = total_ * stepDecay + dt;
  for (const std::uint32_t c : windows.cells()) {
    Cell& cell = cells_[c];
    // Most cells were updated by the last sample too: their decay is the step's.
    const double f = cell.time == previous ? stepDecay : decay(time_ - cell.time);
    const CrowdWindows::Sums& w = windows.sums(c);
    const double density = windows.density(c);
    const Vec2 v(w.vx / w.count, w.vy / w.count);
    cell.occupied = cell.occupied * f + dt;
    cell.density = cell.density * f + dt * density;
    cell.vx = cell.vx * f + dt * v.x();
    cell.vy = cell.vy * f + dt * v.y();
    cell.v2 = cell.v2 * f + dt * v.squaredNorm();
    cell.time = time_;
    ++cell.samples;
  }
}

double TemporalPressure::meanWhereOccupied(const Grid<float, 2>& p) const {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t c = 0; c < cells_.size(); ++c)
    if (cells_[c].samples > 0 && cells_[c].time == time_) {
      sum += p[c];
      ++n;
    }
  return n > 0 ? sum / double(n) : 0.0;
}

void TemporalPressure::pressure(Grid<float, 2>& out) const {
  requireSameGrid(spec_, out);
  for (std::size_t c = 0; c < cells_.size(); ++c) {
    const Cell& cell = cells_[c];
    if (cell.samples < 2 || !(total_ > 0.0)) {
      out[c] = 0.0f;
      continue;
    }
    // The common decay since the cell's last update cancels in the ratios of its own sums.
    const double mx = cell.vx / cell.occupied, my = cell.vy / cell.occupied;
    const double variance = std::max(0.0, cell.v2 / cell.occupied - mx * mx - my * my);
    const double density = cell.density * decay(time_ - cell.time) / total_;
    out[c] = static_cast<float>(density * variance);
  }
}

}  // namespace msim::crowd::stress
