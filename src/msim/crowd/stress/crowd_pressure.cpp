#include "msim/crowd/stress/crowd_pressure.hpp"

#include <cmath>
#include <stdexcept>

namespace msim::crowd::stress {

namespace {

// The agents of each cell: their count, velocity sum and squared-speed sum.
struct CellSums {
  std::vector<double> count, sx, sy, s2;
};

CellSums binAgents(std::span<const Vec2f> positions, std::span<const Vec2f> velocities, const GridSpec<2>& spec) {
  if (positions.size() != velocities.size()) throw std::invalid_argument("crowd pressure: positions and velocities differ in number");
  CellSums s{std::vector<double>(spec.cellCount(), 0.0), std::vector<double>(spec.cellCount(), 0.0),
             std::vector<double>(spec.cellCount(), 0.0), std::vector<double>(spec.cellCount(), 0.0)};
  for (std::size_t k = 0; k < positions.size(); ++k) {
    const std::size_t c = spec.clampedCellIndex(positions[k]);
    s.count[c] += 1.0;
    s.sx[c] += velocities[k].x();
    s.sy[c] += velocities[k].y();
    s.s2[c] += velocities[k].squaredNorm();
  }
  return s;
}

// Sums over the (2w+1)^2 window of cell (i, j): count, velocity, squared speed, and the window's
// cells inside the grid.
struct WindowSums {
  double n = 0.0, vx = 0.0, vy = 0.0, v2 = 0.0;
  int cells = 0;
};

WindowSums windowSums(const CellSums& s, const GridSpec<2>& spec, int i, int j, int window) {
  WindowSums w;
  const int nx = spec.res.x(), ny = spec.res.y();
  for (int dj = -window; dj <= window; ++dj)
    for (int di = -window; di <= window; ++di) {
      const int a = i + di, b = j + dj;
      if (a < 0 || b < 0 || a >= nx || b >= ny) continue;
      const std::size_t c = static_cast<std::size_t>(a + nx * b);
      w.n += s.count[c];
      w.vx += s.sx[c];
      w.vy += s.sy[c];
      w.v2 += s.s2[c];
      ++w.cells;
    }
  return w;
}

void checkWindow(int window) {
  if (window < 0) throw std::invalid_argument("crowd pressure: the window must be >= 0 cells");
}

}  // namespace

void spatialPressure(std::span<const Vec2f> positions, std::span<const Vec2f> velocities, int window,
                     Grid<float, 2>& pressure) {
  checkWindow(window);
  const GridSpec<2>& spec = pressure.spec();
  const CellSums s = binAgents(positions, velocities, spec);
  for (int j = 0; j < spec.res.y(); ++j)
    for (int i = 0; i < spec.res.x(); ++i) {
      const WindowSums w = windowSums(s, spec, i, j, window);
      float p = 0.0f;
      if (w.n >= 2.0) {
        const double variance = std::max(0.0, w.v2 / w.n - (w.vx * w.vx + w.vy * w.vy) / (w.n * w.n));
        p = static_cast<float>(w.n / (w.cells * spec.dx * spec.dx) * variance);
      }
      pressure(IVec<2>(i, j)) = p;
    }
}

StrainRateSummary strainRate(std::span<const Vec2f> positions, std::span<const Vec2f> velocities, int window,
                             Grid<float, 2>& strain) {
  checkWindow(window);
  const GridSpec<2>& spec = strain.spec();
  const int nx = spec.res.x(), ny = spec.res.y();
  const CellSums s = binAgents(positions, velocities, spec);
  // The window-mean velocity of every cell whose window holds someone.
  std::vector<Vec2> mean(spec.cellCount(), Vec2::Zero());
  std::vector<char> has(spec.cellCount(), 0);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const WindowSums w = windowSums(s, spec, i, j, window);
      const std::size_t c = static_cast<std::size_t>(i + nx * j);
      if (w.n > 0.0) {
        mean[c] = Vec2(w.vx, w.vy) / w.n;
        has[c] = 1;
      }
    }
  // d v / d(axis) at cell c: central where both neighbours have a velocity, one-sided where one does.
  const auto derivative = [&](int i, int j, int di, int dj) -> Vec2 {
    const auto at = [&](int a, int b) -> int {
      if (a < 0 || b < 0 || a >= nx || b >= ny) return -1;
      const int c = a + nx * b;
      return has[static_cast<std::size_t>(c)] ? c : -1;
    };
    const int c = at(i, j), lo = at(i - di, j - dj), hi = at(i + di, j + dj);
    const auto v = [&](int k) { return mean[static_cast<std::size_t>(k)]; };
    if (lo >= 0 && hi >= 0) return (v(hi) - v(lo)) / (2.0 * spec.dx);
    if (hi >= 0) return (v(hi) - v(c)) / spec.dx;
    if (lo >= 0) return (v(c) - v(lo)) / spec.dx;
    return Vec2::Zero();
  };
  StrainRateSummary summary;
  double sum = 0.0, sum2 = 0.0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const std::size_t c = static_cast<std::size_t>(i + nx * j);
      if (!has[c]) {
        strain[c] = 0.0f;
        continue;
      }
      const Vec2 dx = derivative(i, j, 1, 0), dy = derivative(i, j, 0, 1);  // dv/dx, dv/dy
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

TemporalPressure::TemporalPressure(const GridSpec<2>& spec, int window, double seconds)
    : spec_(spec), window_(window), rate_(std::log(2.0) / (0.5 * seconds)), cells_(spec.cellCount()) {
  checkWindow(window);
  if (!(seconds > 0.0)) throw std::invalid_argument("crowd pressure: the time window must be > 0 s");
}

double TemporalPressure::decay(double elapsed) const { return std::exp(-rate_ * elapsed); }

void TemporalPressure::add(std::span<const Vec2f> positions, std::span<const Vec2f> velocities, double dt) {
  if (positions.size() != velocities.size()) throw std::invalid_argument("crowd pressure: positions and velocities differ in number");
  const int nx = spec_.res.x(), ny = spec_.res.y();
  const double previous = time_, stepDecay = decay(dt);
  time_ += dt;
  total_ = total_ * stepDecay + dt;
  // Zero outside the cells the last sample touched (they are zeroed again at the end).
  own_.resize(cells_.size(), Sums{});
  windowTotals_.resize(cells_.size(), Sums{});
  occupied_.clear();
  touched_.clear();
  // The agents of each cell, then each occupied cell's sums added to the windows around it: per
  // occupied cell, not per agent, as dense crowds hold several agents a cell.
  for (std::size_t k = 0; k < positions.size(); ++k) {
    const std::size_t c = spec_.clampedCellIndex(positions[k]);
    Sums& own = own_[c];
    if (own.count == 0.0) occupied_.push_back(static_cast<std::uint32_t>(c));
    own.count += 1.0;
    own.vx += velocities[k].x();
    own.vy += velocities[k].y();
  }
  for (const std::uint32_t home : occupied_) {
    const int i = static_cast<int>(home % static_cast<std::uint32_t>(nx)), j = static_cast<int>(home / static_cast<std::uint32_t>(nx));
    const Sums& own = own_[home];
    for (int b = std::max(0, j - window_); b <= std::min(ny - 1, j + window_); ++b)
      for (int a = std::max(0, i - window_); a <= std::min(nx - 1, i + window_); ++a) {
        Sums& w = windowTotals_[static_cast<std::size_t>(a + nx * b)];
        if (w.count == 0.0) touched_.push_back(static_cast<std::uint32_t>(a + nx * b));
        w.count += own.count;
        w.vx += own.vx;
        w.vy += own.vy;
      }
  }
  for (const std::uint32_t c : touched_) {
    const int i = static_cast<int>(c % static_cast<std::uint32_t>(nx)), j = static_cast<int>(c / static_cast<std::uint32_t>(nx));
    const int cells = (std::min(nx - 1, i + window_) - std::max(0, i - window_) + 1) *
                      (std::min(ny - 1, j + window_) - std::max(0, j - window_) + 1);
    Cell& cell = cells_[c];
    // Most cells were updated by the last sample too: their decay is the step's.
    const double f = cell.time == previous ? stepDecay : decay(time_ - cell.time);
    const Sums& w = windowTotals_[c];
    const double density = w.count / (cells * spec_.dx * spec_.dx);
    const Vec2 v(w.vx / w.count, w.vy / w.count);
    cell.occupied = cell.occupied * f + dt;
    cell.density = cell.density * f + dt * density;
    cell.vx = cell.vx * f + dt * v.x();
    cell.vy = cell.vy * f + dt * v.y();
    cell.v2 = cell.v2 * f + dt * v.squaredNorm();
    cell.time = time_;
    ++cell.samples;
  }
  for (const std::uint32_t c : occupied_) own_[c] = Sums{};
  for (const std::uint32_t c : touched_) windowTotals_[c] = Sums{};
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
  if (!(out.spec() == spec_)) throw std::invalid_argument("crowd pressure: the output grid differs from the sampled one");
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
