#include "msim/crowd/walking_density.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "msim/crowd/free_area.hpp"

namespace msim::crowd {
namespace {

// The table's cell: fine enough that a door frame's corner cell misplaces little of a 1.5 m
// square, coarse enough that a 400 m site stays a few million cells.
constexpr double kTableCell = 0.25;

void check(const SpeedDensitySettings& s) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("speed-density settings: " + what); };
  if (!(s.window > 0.0) || !std::isfinite(s.window)) bad(fmt::format("window = {} m must be positive", s.window));
  // The person must stay inside its own square after snapping (measure()).
  if (!(s.lookahead >= 0.0) || !(s.lookahead <= 0.5 * s.window - kTableCell))
    bad(fmt::format("lookahead = {} m must lie in [0, window / 2 - {} = {}]", s.lookahead, kTableCell,
                    0.5 * s.window - kTableCell));
  if (!(s.minFreeArea > 0.0) || !std::isfinite(s.minFreeArea))
    bad(fmt::format("minFreeArea = {} m^2 must be positive", s.minFreeArea));
  if (!(s.weidmann.v0 > 0.0) || !(s.weidmann.gamma > 0.0) || !(s.weidmann.rhoJam > 0.0))
    bad("Weidmann's v0, gamma and rho_jam must be positive");
}

}  // namespace

WalkingDensity::WalkingDensity(const Vec2& lo, const Vec2& hi, std::span<const Polygon> obstacles,
                               const SpeedDensitySettings& settings)
    : settings_(settings), lo_(lo), hi_(hi) {
  check(settings_);
  const Vec2 extent = hi - lo;
  if (!(extent.x() > 0.0) || !(extent.y() > 0.0)) throw std::invalid_argument("speed-density settings: empty walkable box");
  nx_ = std::max(1, static_cast<int>(std::ceil(extent.x() / kTableCell)));
  ny_ = std::max(1, static_cast<int>(std::ceil(extent.y() / kTableCell)));
  cell_ = std::max(extent.x() / nx_, extent.y() / ny_);
  FreeArea free(GridSpec<2>(lo, cell_, IVec2(nx_, ny_)));
  for (const Polygon& p : obstacles) free.addStaticObstacle(p);
  // Summed-area table over corners: table(i, j) = free area of [lo, lo + (i, j) cell].
  const double area = cell_ * cell_;
  const std::size_t stride = static_cast<std::size_t>(nx_) + 1;
  table_.assign(stride * (static_cast<std::size_t>(ny_) + 1), 0.0);
  for (int j = 0; j < ny_; ++j) {
    double row = 0.0;
    for (int i = 0; i < nx_; ++i) {
      row += free.fraction()(IVec2(i, j)) * area;
      table_[(j + 1) * stride + i + 1] = table_[j * stride + i + 1] + row;
    }
  }
  people_.assign(table_.size(), 0);
}

double WalkingDensity::integral(double x, double y) const {
  const double sx = std::clamp((x - lo_.x()) / cell_, 0.0, double(nx_));
  const double sy = std::clamp((y - lo_.y()) / cell_, 0.0, double(ny_));
  const int i = std::min(static_cast<int>(sx), nx_ - 1), j = std::min(static_cast<int>(sy), ny_ - 1);
  const double fx = sx - i, fy = sy - j;
  const std::size_t stride = static_cast<std::size_t>(nx_) + 1;
  const double* row0 = table_.data() + static_cast<std::size_t>(j) * stride + i;
  const double* row1 = row0 + stride;
  return (1.0 - fy) * ((1.0 - fx) * row0[0] + fx * row0[1]) + fy * ((1.0 - fx) * row1[0] + fx * row1[1]);
}

double WalkingDensity::freeArea(const Vec2& c) const {
  const double h = 0.5 * settings_.window;
  const double x0 = std::max(c.x() - h, lo_.x()), x1 = std::min(c.x() + h, hi_.x());
  const double y0 = std::max(c.y() - h, lo_.y()), y1 = std::min(c.y() + h, hi_.y());
  if (!(x1 > x0) || !(y1 > y0)) return 0.0;
  return std::max(0.0, integral(x1, y1) - integral(x0, y1) - integral(x1, y0) + integral(x0, y0));
}

void WalkingDensity::measure(std::span<const Vec2f> people, std::span<const Vec2f> preferred,
                             std::span<const float> maxSpeed, std::span<float> density, std::span<float> speed) {
  const std::size_t n = people.size();
  if (preferred.size() != n || maxSpeed.size() != n || density.size() != n || speed.size() != n)
    throw std::invalid_argument("WalkingDensity::measure: spans of different sizes");
  if (n == 0) return;
  const std::size_t stride = static_cast<std::size_t>(nx_) + 1;
  const float x0 = static_cast<float>(lo_.x()), y0 = static_cast<float>(lo_.y()), inv = static_cast<float>(1.0 / cell_);
  const auto cellOf = [&](const Vec2f& p) {
    const int i = std::clamp(static_cast<int>((p.x() - x0) * inv), 0, nx_ - 1);
    const int j = std::clamp(static_cast<int>((p.y() - y0) * inv), 0, ny_ - 1);
    return std::pair{i, j};
  };
  // People per cell, stored at the cell's upper corner, then summed along rows (rows in parallel)
  // and down columns (blocks of columns in parallel, row by row within a block); all of it only
  // over the corners [iLo, iHi] x [jLo, jHi] of the cells people stand in, to which the queries
  // are clamped (beyond them there is no one to count).
  int iLo = nx_, iHi = 0, jLo = ny_, jHi = 0;
  for (const Vec2f& p : people) {
    const auto [i, j] = cellOf(p);
    iLo = std::min(iLo, i), iHi = std::max(iHi, i + 1), jLo = std::min(jLo, j), jHi = std::max(jHi, j + 1);
  }
  tbb::parallel_for(jLo, jHi + 1, [&](int j) { std::fill_n(people_.data() + j * stride + iLo, iHi - iLo + 1, 0u); });
  for (const Vec2f& p : people) {
    const auto [i, j] = cellOf(p);
    ++people_[(j + 1) * stride + i + 1];
  }
  tbb::parallel_for(jLo + 1, jHi + 1, [&](int j) {
    std::uint32_t* row = people_.data() + j * stride;
    for (int i = iLo + 1; i <= iHi; ++i) row[i] += row[i - 1];
  });
  constexpr int kColumns = 512;
  tbb::parallel_for(0, (iHi - iLo + kColumns - 1) / kColumns, [&](int block) {
    const int first = iLo + 1 + block * kColumns, last = std::min(iHi, first + kColumns - 1);
    for (int j = jLo + 2; j <= jHi; ++j) {
      std::uint32_t* row = people_.data() + j * stride;
      const std::uint32_t* below = row - stride;
      for (int i = first; i <= last; ++i) row[i] += below[i];
    }
  });
  const float half = static_cast<float>(0.5 * settings_.window);
  const float ahead = static_cast<float>(settings_.lookahead);
  const WeidmannParams& w = settings_.weidmann;
  const std::uint32_t* count = people_.data();
  const double* free = table_.data();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k) {
      const float norm = preferred[k].norm();
      const Vec2f c = norm > 0.0f ? Vec2f(people[k] + preferred[k] * (ahead / norm)) : people[k];
      // The square's sides on the nearest cell lines, clamped to the box.
      const auto line = [&](float x, float origin, int cells) {
        return static_cast<std::size_t>(std::clamp(static_cast<int>(std::floor((x - origin) * inv + 0.5f)), 0, cells));
      };
      const std::size_t ia = line(c.x() - half, x0, nx_), ib = line(c.x() + half, x0, nx_);
      const std::size_t ja = line(c.y() - half, y0, ny_), jb = line(c.y() + half, y0, ny_);
      const auto box = [&](const auto* t, std::size_t i0, std::size_t i1, std::size_t j0, std::size_t j1) {
        return t[j1 * stride + i1] - t[j0 * stride + i1] - t[j1 * stride + i0] + t[j0 * stride + i0];
      };
      const auto ci = [&](std::size_t i) { return std::clamp(i, std::size_t(iLo), std::size_t(iHi)); };
      const auto cj = [&](std::size_t j) { return std::clamp(j, std::size_t(jLo), std::size_t(jHi)); };
      // The person is at least window / 2 - lookahead (>= one cell) inside the square, and snapping
      // moves a side by at most half a cell onto a cell line: its cell is counted, and the others
      // are one fewer.
      const std::uint32_t inside = box(count, ci(ia), ci(ib), cj(ja), cj(jb));
      const double others = inside > 0 ? double(inside - 1) : 0.0;
      const double rho = others / std::max(settings_.minFreeArea, box(free, ia, ib, ja, jb));
      density[k] = static_cast<float>(rho);
      speed[k] = static_cast<float>(maxSpeed[k] * weidmannSpeed(rho, w) / w.v0);
    }
  });
}

}  // namespace msim::crowd
