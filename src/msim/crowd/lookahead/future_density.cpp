#include "msim/crowd/lookahead/future_density.hpp"

#include <algorithm>
#include <cmath>

#include "msim/core/interpolation.hpp"
#include "msim/core/parallel.hpp"

namespace msim::crowd::lookahead {

namespace {

// Cells of padding around the box: an agent's taps and the central differences around them stay
// on the grid.
constexpr int kPadding = 2;

}  // namespace

void FutureDensity::build(const HorizonSchedule& schedule, double cell, const Vec2& lo, const Vec2& hi,
                          std::span<const Vec2f> positions, std::span<const Vec2f> velocities, DensityLevels which) {
  const int levels = std::max(0, schedule.levels);
  lo_ = lo;
  hi_ = hi;
  horizon_.resize(static_cast<std::size_t>(levels) + 1);
  counts_.resize(horizon_.size());
  levels_.resize(horizon_.size());
  splatters_.resize(horizon_.size());
  predicted_.resize(horizon_.size());
  const std::size_t n = positions.size();
  ones_.assign(n, 1.0f);
  for (int i = 0; i <= levels; ++i) {
    horizon_[static_cast<std::size_t>(i)] = schedule.horizon(i);
    const double h = cell * std::pow(schedule.coarsening, i);
    const Vec2 extent = hi - lo;
    const IVec<2> res(static_cast<int>(std::ceil(extent.x() / h)) + 2 * kPadding,
                      static_cast<int>(std::ceil(extent.y() / h)) + 2 * kPadding);
    const GridSpec<2> spec(lo - Vec2::Constant(kPadding * h), h, res);
    Grid<float, 2>& counts = counts_[static_cast<std::size_t>(i)];
    if (!(counts.spec() == spec)) counts = Grid<float, 2>(spec);
  }
  if (!(velocityX_.spec() == counts_[0].spec())) velocityX_ = velocityY_ = speed2_ = Grid<float, 2>(counts_[0].spec());
  // The levels are independent: one task each (their splats are parallel too).
  parallelFor(which.now ? 0 : 1, which.far ? horizon_.size() : 1, [&](std::size_t i) {
    std::vector<Vec2f>& at = predicted_[i];
    at.resize(n);
    for (std::size_t j = 0; j < n; ++j) at[j] = predicted(static_cast<int>(i), positions[j], velocities[j]).cast<float>();
    counts_[i].fill(0.0f);
    splatters_[i].splat(at, ones_, counts_[i], TransferKernel::Linear);
    differentiate(i);
  }, 1);
  if (!which.now) return;
  vx_.resize(n);
  vy_.resize(n);
  v2_.resize(n);
  for (std::size_t j = 0; j < n; ++j) {
    vx_[j] = velocities[j].x();
    vy_[j] = velocities[j].y();
    v2_[j] = velocities[j].squaredNorm();
  }
  velocityX_.fill(0.0f);
  velocityY_.fill(0.0f);
  speed2_.fill(0.0f);
  splatters_[0].splatSums<3>(predicted_[0], {std::span<const float>(vx_), std::span<const float>(vy_), std::span<const float>(v2_)},
                             {&velocityX_, &velocityY_, &speed2_}, TransferKernel::Linear);
}

Vec2 FutureDensity::predicted(int level, const Vec2f& x, const Vec2f& v) const {
  const Vec2 p = x.cast<double>() + horizon_[static_cast<std::size_t>(level)] * v.cast<double>();
  return p.cwiseMax(lo_).cwiseMin(hi_);
}

void FutureDensity::differentiate(std::size_t i) {
  const Grid<float, 2>& counts = counts_[i];
  Level& level = levels_[i];
  level.spec = counts.spec();
  level.nx = counts.size().x();
  level.ny = counts.size().y();
  const double h = level.spec.dx, area = h * h;
  level.fields.resize(3 * counts.count());
  const auto rho = [&](int x, int y) {
    return counts(IVec<2>(std::clamp(x, 0, level.nx - 1), std::clamp(y, 0, level.ny - 1))) / area;
  };
  for (int y = 0; y < level.ny; ++y)
    for (int x = 0; x < level.nx; ++x) {
      float* f = level.fields.data() + 3 * (static_cast<std::size_t>(y) * level.nx + x);
      f[0] = static_cast<float>(rho(x, y));
      f[1] = static_cast<float>((rho(x + 1, y) - rho(x - 1, y)) / (2.0 * h));
      f[2] = static_cast<float>((rho(x, y + 1) - rho(x, y - 1)) / (2.0 * h));
    }
}

FutureDensity::Taps FutureDensity::taps(const Level& level, const Vec2& at) const {
  // Sample coordinates (samples at cell centres), clamped to the sampled range.
  const double sx = std::clamp((at.x() - level.spec.origin.x()) / level.spec.dx - 0.5, 0.0, level.nx - 1.000001);
  const double sy = std::clamp((at.y() - level.spec.origin.y()) / level.spec.dx - 0.5, 0.0, level.ny - 1.000001);
  const int i = static_cast<int>(sx), j = static_cast<int>(sy);
  return {static_cast<std::size_t>(j) * level.nx + i, sx - i, sy - j};
}

FutureDensity::Density FutureDensity::interpolate(const Level& level, const Taps& t) const {
  const float* f00 = level.fields.data() + 3 * t.corner;
  const float* f10 = f00 + 3;
  const float* f01 = f00 + 3 * static_cast<std::size_t>(level.nx);
  const float* f11 = f01 + 3;
  const double w00 = (1.0 - t.a) * (1.0 - t.b), w10 = t.a * (1.0 - t.b), w01 = (1.0 - t.a) * t.b, w11 = t.a * t.b;
  double v[3];
  for (int k = 0; k < 3; ++k) v[k] = w00 * f00[k] + w10 * f10[k] + w01 * f01[k] + w11 * f11[k];
  return {v[0], Vec2(v[1], v[2])};
}

FutureDensity::Density FutureDensity::density(int level, const Vec2& at) const {
  const Level& l = levels_[static_cast<std::size_t>(level)];
  return interpolate(l, taps(l, at));
}

FutureDensity::Density FutureDensity::othersDensity(int level, const Vec2& at) const {
  const Level& l = levels_[static_cast<std::size_t>(level)];
  const Taps t = taps(l, at);
  Density d = interpolate(l, t);
  // The unit mass at `at` put w_k on the samples around it and reads back sum_k w_k^2 per axis.
  const double own = ((1.0 - t.a) * (1.0 - t.a) + t.a * t.a) * ((1.0 - t.b) * (1.0 - t.b) + t.b * t.b) / (l.spec.dx * l.spec.dx);
  d.value = std::max(0.0, d.value - own);
  return d;
}

FutureDensity::Flow FutureDensity::flow(const Vec2& at) const {
  Flow f;
  const double count = sampleLinear<2>(counts_[0], at);
  if (!(count > 1e-6)) return f;
  const double h = counts_[0].spec().dx;
  f.density = count / (h * h);
  f.meanVelocity = Vec2(sampleLinear<2>(velocityX_, at), sampleLinear<2>(velocityY_, at)) / count;
  f.speedDeviation = std::sqrt(std::max(0.0, sampleLinear<2>(speed2_, at) / count - f.meanVelocity.squaredNorm()));
  return f;
}

}  // namespace msim::crowd::lookahead
