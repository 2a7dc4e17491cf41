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

// out[c] += in[c] for c < count: the sliding sums' one operation, in its own function so that the
// compiler knows the rows apart and vectorises it.
void addRow(std::uint16_t* __restrict out, const std::uint16_t* __restrict in, int count) {
  for (int c = 0; c < count; ++c) out[c] += in[c];
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
  // The counting square: `across` whole cells, its lower-left corner anywhere from `pad` cells
  // before the box to its last cell, so that it can hold any cell.
  across_ = std::max(1, static_cast<int>(std::lround(settings_.window / cell_)));
  pad_ = across_ - 1;
  cornersX_ = nx_ + pad_;
  const int cornersY = ny_ + pad_;
  const double full = across_ * across_ * area;
  freeSquare_.resize(static_cast<std::size_t>(cornersX_) * cornersY);
  for (int ja = -pad_; ja < ny_; ++ja)
    for (int ia = -pad_; ia < nx_; ++ia) {
      const std::size_t i0 = std::max(ia, 0), i1 = std::min(ia + across_, nx_);
      const std::size_t j0 = std::max(ja, 0), j1 = std::min(ja + across_, ny_);
      const double free = table_[j1 * stride + i1] - table_[j0 * stride + i1] - table_[j1 * stride + i0] +
                          table_[j0 * stride + i0];
      freeSquare_[corner(ia, ja)] = static_cast<std::uint16_t>(std::lround(std::clamp(free / full, 0.0, 1.0) * kWhole));
    }
  // A square of open floor holds the full area: its speeds for the first counts, once.
  fullArea_ = full;
  openSpeed_.resize(kOpenCounts);
  for (int k = 0; k < kOpenCounts; ++k)
    openSpeed_[k] = static_cast<float>(weidmannSpeed(k / std::max(settings_.minFreeArea, full), settings_.weidmann) /
                                       settings_.weidmann.v0);
  cellPeople_.assign(static_cast<std::size_t>(nx_) * ny_, 0);
  rowSums_.assign(static_cast<std::size_t>(cornersX_) * ny_, 0);
  squarePeople_.assign(freeSquare_.size(), 0);
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
  const float x0 = static_cast<float>(lo_.x()), y0 = static_cast<float>(lo_.y()), inv = static_cast<float>(1.0 / cell_);
  const auto cellOf = [&](const Vec2f& p) {
    const int i = std::clamp(static_cast<int>((p.x() - x0) * inv), 0, nx_ - 1);
    const int j = std::clamp(static_cast<int>((p.y() - y0) * inv), 0, ny_ - 1);
    return std::pair{i, j};
  };
  // People per cell, over the cells people stand in ([iLo, iHi] x [jLo, jHi]); then the people of
  // every square that can hold one of them (corners [iLo - pad, iHi] x [jLo - pad, jHi]) as two
  // sliding sums of `across` cells, along rows and then along columns. Each pass adds whole rows,
  // which vectorises, and the rows go in parallel.
  int iLo = nx_, iHi = 0, jLo = ny_, jHi = 0;
  for (const Vec2f& p : people) {
    const auto [i, j] = cellOf(p);
    iLo = std::min(iLo, i), iHi = std::max(iHi, i), jLo = std::min(jLo, j), jHi = std::max(jHi, j);
  }
  const std::size_t nxs = static_cast<std::size_t>(nx_);
  tbb::parallel_for(jLo, jHi + 1, [&](int j) { std::fill_n(cellPeople_.data() + j * nxs + iLo, iHi - iLo + 1, std::uint16_t(0)); });
  for (const Vec2f& p : people) {
    const auto [i, j] = cellOf(p);
    ++cellPeople_[j * nxs + i];
  }
  const int width = iHi - iLo + 1 + pad_;  // corners per row that can hold someone
  tbb::parallel_for(jLo, jHi + 1, [&](int j) {
    // rowSums(ia, j) = sum of cellPeople(ia + k, j), k < across, over cells in [iLo, iHi].
    std::uint16_t* out = rowSums_.data() + static_cast<std::size_t>(j) * cornersX_ + pad_;  // corner ia at out[ia]
    const std::uint16_t* in = cellPeople_.data() + j * nxs;
    std::fill_n(out + iLo - pad_, width, std::uint16_t(0));
    for (int k = 0; k < across_; ++k) addRow(out + iLo - k, in + iLo, iHi - iLo + 1);
  });
  tbb::parallel_for(jLo - pad_, jHi + 1, [&](int ja) {
    std::uint16_t* out = squarePeople_.data() + corner(iLo - pad_, ja);
    std::fill_n(out, width, std::uint16_t(0));
    for (int j = std::max(ja, jLo); j <= std::min(ja + pad_, jHi); ++j)
      addRow(out, rowSums_.data() + static_cast<std::size_t>(j) * cornersX_ + iLo, width);
  });
  const float centreShift = 0.5f * static_cast<float>(across_) - 0.5f;  // centre to lower-left corner, less rounding
  const float ahead = static_cast<float>(settings_.lookahead);
  const float openDensity = static_cast<float>(1.0 / std::max(settings_.minFreeArea, fullArea_));
  const double wholeArea = fullArea_ / kWhole;
  const WeidmannParams& w = settings_.weidmann;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k) {
      const float norm = preferred[k].norm();
      const Vec2f c = norm > 0.0f ? Vec2f(people[k] + preferred[k] * (ahead / norm)) : people[k];
      // The square whose centre lies nearest c, moved (by at most a cell where the lookahead is
      // at its limit or the person is outside the box) so that it holds the person's cell: the
      // others are one fewer than it holds.
      const auto [i, j] = cellOf(people[k]);
      const int ia = std::clamp(static_cast<int>(std::floor((c.x() - x0) * inv - centreShift)), i - pad_, i);
      const int ja = std::clamp(static_cast<int>(std::floor((c.y() - y0) * inv - centreShift)), j - pad_, j);
      const std::size_t at = corner(ia, ja);
      const int others = static_cast<int>(squarePeople_[at]) - 1;
      float factor;
      if (freeSquare_[at] == kWhole && others < kOpenCounts) {
        factor = openSpeed_[others];
        density[k] = static_cast<float>(others) * openDensity;
      } else {
        const double rho = double(others) / std::max(settings_.minFreeArea, freeSquare_[at] * wholeArea);
        density[k] = static_cast<float>(rho);
        factor = static_cast<float>(weidmannSpeed(rho, w) / w.v0);
      }
      speed[k] = maxSpeed[k] * factor;
    }
  });
}

}  // namespace msim::crowd
