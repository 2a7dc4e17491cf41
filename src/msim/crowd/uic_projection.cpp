#include "msim/crowd/uic_projection.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "msim/core/error.hpp"
#include "msim/core/parallel.hpp"

namespace msim::crowd {
namespace {

using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

const GridSpec<2>& checkedGrid(const GridSpec<2>& grid, const UicSettings& s) {
  if (!(grid.dx > 0.0) || !std::isfinite(grid.dx) || grid.res.minCoeff() < 1)
    throw std::invalid_argument("UicProjection: the grid needs dx > 0 and at least one cell per axis");
  if (!(s.rhoMax > 0.0) || !std::isfinite(s.rhoMax))
    throw std::invalid_argument(fmt::format("UicProjection: rhoMax must be a positive number, got {}", s.rhoMax));
  if (!(s.tolerance > 0.0) || s.maxIterations < 1 || !(s.regularization >= 0.0) || !(s.renormMinFraction >= 0.0))
    throw std::invalid_argument("UicProjection: need tolerance > 0, maxIterations >= 1, regularization >= 0 "
                                "and renormMinFraction >= 0");
  return grid;
}

// Smallest index i < n with bad(i), or n. Parallel; the minimum makes the answer deterministic.
template <typename Bad>
std::size_t firstBad(std::size_t n, const Bad& bad) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, 4096), n,
      [&](const tbb::blocked_range<std::size_t>& r, std::size_t found) {
        for (std::size_t i = r.begin(); i != r.end() && i < found; ++i)
          if (bad(i)) return i;
        return found;
      },
      [](std::size_t a, std::size_t b) { return std::min(a, b); });
}

}  // namespace

// f(local index in the box, grid index) over the QP box.
template <typename F>
void UicProjection::forBox(const F& f) const {
  const int bx = boxRes_.x();
  const std::size_t nx = static_cast<std::size_t>(grid_.res.x());
  tbb::parallel_for(tbb::blocked_range<int>(0, boxRes_.y(), 16), [&](const tbb::blocked_range<int>& r) {
    for (int j = r.begin(); j != r.end(); ++j) {
      const std::size_t local = static_cast<std::size_t>(j) * bx;
      const std::size_t k = (static_cast<std::size_t>(j) + boxOrigin_.y()) * nx + boxOrigin_.x();
      for (int i = 0; i < bx; ++i) f(local + i, k + i);
    }
  });
}

UicProjection::UicProjection(const GridSpec<2>& grid, const UicSettings& settings)
    : grid_(checkedGrid(grid, settings)),
      settings_(settings),
      density_(grid),
      pressure_(grid),
      predicted_(grid),
      freeArea_(grid, 1.0f),
      ratio_(grid),
      faceDensity_(grid),
      preferred_(grid),
      speed_(grid),
      inner_(grid),
      renormed_(grid),
      velocity_(grid),
      lowerWeight_{std::vector<double>(grid.cellCount(), 0.0), std::vector<double>(grid.cellCount(), 0.0)},
      diagonal_(grid.cellCount(), 1.0),
      excluded_(grid.cellCount(), 1),
      operator_(grid.res, lowerWeight_, diagonal_),
      preconditioner_(grid.res, lowerWeight_, diagonal_),
      rhs_(Eigen::VectorXd::Zero(static_cast<Eigen::Index>(grid.cellCount()))),
      innerPressure_(Eigen::VectorXd::Zero(rhs_.size())),
      outerPressure_(Eigen::VectorXd::Zero(rhs_.size())) {}

UicProjection::SpeedRange UicProjection::validate(std::span<const Vec2f> positions,
                                                  std::span<const Vec2f> preferredVelocities,
                                                  std::span<const float> maxSpeeds, const Grid<float, 2>& freeArea,
                                                  double dt, std::span<Vec2f> velocities) const {
  const std::size_t n = positions.size();
  if (preferredVelocities.size() != n || maxSpeeds.size() != n || velocities.size() != n)
    throw InputError(fmt::format("UIC projection: {} positions but {} preferred velocities, {} speeds and {} outputs",
                                 n, preferredVelocities.size(), maxSpeeds.size(), velocities.size()));
  if (!(dt > 0.0) || !std::isfinite(dt)) throw InputError(fmt::format("UIC projection: dt must be > 0, got {}", dt));
  if (!freeArea.sameLayout(density_))
    throw InputError("UIC projection: the free-area grid does not match the crowd grid's cells");
  const Vec2 lo = grid_.origin, hi = grid_.upper();
  // One pass: the first bad agent (the minimum index, so deterministic) and the speed range. The
  // test is branch-free (comparisons with NaN are false); a block with a bad agent is scanned
  // again for the first one.
  const float loX = static_cast<float>(lo.x()), loY = static_cast<float>(lo.y());
  const float hiX = static_cast<float>(hi.x()), hiY = static_cast<float>(hi.y());
  constexpr float kLargest = std::numeric_limits<float>::max();
  auto good = [&](std::size_t i) {
    const Vec2f& x = positions[i];
    const Vec2f& v = preferredVelocities[i];
    const float speed = maxSpeeds[i];
    return (x.x() >= loX) & (x.x() <= hiX) & (x.y() >= loY) & (x.y() <= hiY) & (std::abs(v.x()) <= kLargest) &
           (std::abs(v.y()) <= kLargest) & (speed >= 0.0f) & (speed <= kLargest);
  };
  struct Scan {
    std::size_t bad;
    SpeedRange speeds;
  };
  const Scan scan = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, 4096),
      Scan{n, SpeedRange{0.0f, std::numeric_limits<float>::infinity()}},
      [&](const tbb::blocked_range<std::size_t>& r, Scan acc) {
        bool all = true;
        float fastest = acc.speeds.fastest, slowest = acc.speeds.slowest;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          all &= good(i);
          fastest = std::max(fastest, maxSpeeds[i]);
          slowest = std::min(slowest, maxSpeeds[i]);
        }
        acc.speeds = SpeedRange{fastest, slowest};
        if (!all)
          for (std::size_t i = r.begin(); i != r.end() && i < acc.bad; ++i)
            if (!good(i)) acc.bad = i;
        return acc;
      },
      [](Scan a, const Scan& b) {
        a.bad = std::min(a.bad, b.bad);
        a.speeds.fastest = std::max(a.speeds.fastest, b.speeds.fastest);
        a.speeds.slowest = std::min(a.speeds.slowest, b.speeds.slowest);
        return a;
      });
  const std::size_t bad = scan.bad;
  if (bad < n)
    throw InputError(fmt::format("UIC projection: agent {} at ({}, {}) with preferred velocity ({}, {}) and speed {} "
                                 "is non-finite, has a negative speed or lies outside the grid [{}, {}] x [{}, {}]",
                                 bad, positions[bad].x(), positions[bad].y(), preferredVelocities[bad].x(),
                                 preferredVelocities[bad].y(), maxSpeeds[bad], lo.x(), hi.x(), lo.y(), hi.y()));
  const std::size_t badCell = firstBad(freeArea.count(), [&](std::size_t i) {
    return !(freeArea[i] >= 0.0f && freeArea[i] <= 1.0f);
  });
  if (badCell < freeArea.count())
    throw InputError(fmt::format("UIC projection: free area {} of cell {} is outside [0, 1]", freeArea[badCell], badCell));
  return scan.speeds;
}

namespace {

// Linear (tent) taps along one axis of a grid with n samples, sample coordinate s: the two folded
// sample indices and their weights (taps outside the grid fold onto the border sample, as in
// core/transfer.hpp). Single precision, as the agents' positions: the weights are good to ~1e-7 of
// the coordinate, and the transfers cost half as much as in double.
struct Taps {
  int at[2];
  float w[2];
  Taps(float s, int n) {
    const float first = std::floor(s);
    const int f = static_cast<int>(first);
    at[0] = std::clamp(f, 0, n - 1);
    at[1] = std::clamp(f + 1, 0, n - 1);
    w[1] = s - first;
    w[0] = 1.0f - w[1];
  }
};

// p[q] += s w[q] for q < 4 (one 128-bit load, multiply-add and store where SSE is there).
inline void addScaled4(float* p, float s, const float* w) {
#if defined(__SSE2__)
  _mm_storeu_ps(p, _mm_add_ps(_mm_loadu_ps(p), _mm_mul_ps(_mm_set1_ps(s), _mm_loadu_ps(w))));
#else
  for (int q = 0; q < 4; ++q) p[q] += s * w[q];
#endif
}

}  // namespace

// Eqs. 4.1-4.2 with the Linear (bilinear) kernel, all fields in one pass over the agents: unit
// masses onto the cells and both face grids (Sum), and v~ (and the speeds, if they differ) onto the
// faces, normalised by the face weight sums, which are the face masses. The agents are split into
// a fixed number of contiguous chunks (it depends on the agent count only), each splatted into
// grids of its own in parallel; the chunks are then summed sample by sample in chunk order, so the
// result does not depend on the thread count. Crowds are stored along a space-filling curve, so a
// chunk's agents lie close together: its grids stay in cache, and only the rows it touched are
// summed and zeroed again (the chunk grids are all zero between calls).
void UicProjection::splatAgents(std::span<const Vec2f> positions, std::span<const Vec2f> preferredVelocities,
                                std::span<const float> maxSpeeds, SpeedRange range) {
  const std::size_t n = positions.size();
  const int nx = grid_.res.x(), ny = grid_.res.y();
  // The Normalized splat of a common speed is that speed wherever agents are, and renorm reads
  // v_max only there: skip the speed sums for uniform speeds (the usual case).
  const bool speeds = n > 0 && range.slowest != range.fastest;
  const std::size_t cells = density_.count(), faces[2] = {faceDensity_.component(0).count(),
                                                          faceDensity_.component(1).count()};
  const std::size_t chunks = std::clamp<std::size_t>((n + kChunkAgents - 1) / kChunkAgents, 1, kMaxChunks);
  if (chunks_.size() < chunks) chunks_.resize(chunks);
  for (std::size_t c = 0; c < chunks; ++c) {
    SplatChunk& k = chunks_[c];
    k.cellMass.resize(cells, 0.0f);
    for (int a = 0; a < 2; ++a) {
      k.faceMassFlow[a].resize(2 * faces[a], 0.0f);
      if (speeds) k.faceSpeed[a].resize(faces[a], 0.0f);
    }
  }

  const float ox = static_cast<float>(grid_.origin.x()), oy = static_cast<float>(grid_.origin.y());
  const float invDx = static_cast<float>(1.0 / grid_.dx);
  const std::size_t stride[2] = {static_cast<std::size_t>(nx) + 1, static_cast<std::size_t>(nx)};  // x, y faces
  const std::size_t cellStride = static_cast<std::size_t>(nx);
  const std::size_t per = (n + chunks - 1) / chunks;
  tbb::parallel_for(std::size_t(0), chunks, [&](std::size_t c) {
    SplatChunk& k = chunks_[c];
    float* const cellMass = k.cellMass.data();
    float* const massFlowX = k.faceMassFlow[0].data();
    float* const massFlowY = k.faceMassFlow[1].data();
    float* const speedX = speeds ? k.faceSpeed[0].data() : nullptr;
    float* const speedY = speeds ? k.faceSpeed[1].data() : nullptr;
    const std::size_t xStride = stride[0], yStride = stride[1];
    const Vec2f* const x = positions.data();
    const Vec2f* const vPreferred = preferredVelocities.data();
    const float* const vMax = maxSpeeds.data();
    int rowLo = ny + 1, rowHi = -1;
    for (std::size_t p = c * per, end = std::min(n, (c + 1) * per); p < end; ++p) {
      const float sx = (x[p].x() - ox) * invDx, sy = (x[p].y() - oy) * invDx;
      const float vx = vPreferred[p].x(), vy = vPreferred[p].y();
      const Taps cx(sx - 0.5f, nx), cy(sy - 0.5f, ny), fx(sx, nx + 1), fy(sy, ny + 1);
      rowLo = std::min({rowLo, cy.at[0], fy.at[0]});
      rowHi = std::max({rowHi, cy.at[1], fy.at[1]});
      for (int b = 0; b < 2; ++b) {
        float* cellRow = cellMass + static_cast<std::size_t>(cy.at[b]) * cellStride;
        cellRow[cx.at[0]] += cy.w[b] * cx.w[0];
        cellRow[cx.at[1]] += cy.w[b] * cx.w[1];
      }
      // (mass, flow) of the two columns of each face grid, interleaved as in faceMassFlow; rows of
      // x faces from cy, of y faces from fy.
      const float xw[4] = {fx.w[0], fx.w[0] * vx, fx.w[1], fx.w[1] * vx};
      const float yw[4] = {cx.w[0], cx.w[0] * vy, cx.w[1], cx.w[1] * vy};
      if (cx.at[1] == cx.at[0] + 1) {
        // Away from the left and right sides (the usual case) both grids' columns are neighbours
        // (sx lies in [cx.at[0] + 0.5, cx.at[0] + 1.5)): one block of four floats per row.
        for (int b = 0; b < 2; ++b) {
          addScaled4(massFlowX + 2 * (static_cast<std::size_t>(cy.at[b]) * xStride + fx.at[0]), cy.w[b], xw);
          addScaled4(massFlowY + 2 * (static_cast<std::size_t>(fy.at[b]) * yStride + cx.at[0]), fy.w[b], yw);
        }
      } else {  // folded at a side
        for (int b = 0; b < 2; ++b)
          for (int a = 0; a < 2; ++a)
            for (int q = 0; q < 2; ++q) {
              massFlowX[2 * (static_cast<std::size_t>(cy.at[b]) * xStride + fx.at[a]) + q] += cy.w[b] * xw[2 * a + q];
              massFlowY[2 * (static_cast<std::size_t>(fy.at[b]) * yStride + cx.at[a]) + q] += fy.w[b] * yw[2 * a + q];
            }
      }
      if (speedX)
        for (int b = 0; b < 2; ++b)
          for (int a = 0; a < 2; ++a) {
            speedX[static_cast<std::size_t>(cy.at[b]) * xStride + fx.at[a]] += cy.w[b] * fx.w[a] * vMax[p];
            speedY[static_cast<std::size_t>(fy.at[b]) * yStride + cx.at[a]] += fy.w[b] * cx.w[a] * vMax[p];
          }
    }
    k.rowLo = rowLo;
    k.rowHi = rowHi;
  }, tbb::simple_partitioner());

  // Sum the chunks row by row in chunk order (only the chunks whose rows include the row hold
  // anything there), zeroing their copies, then normalise.
  const float perArea = static_cast<float>(1.0 / (grid_.dx * grid_.dx));
  const float common = range.fastest;
  tbb::parallel_for(tbb::blocked_range<int>(0, ny + 1, 4), [&](const tbb::blocked_range<int>& rowRange) {
    for (int j = rowRange.begin(); j != rowRange.end(); ++j) {
      if (j < ny) {
        float* rho = density_.data().data() + static_cast<std::size_t>(j) * cellStride;
        std::fill(rho, rho + nx, 0.0f);
        for (std::size_t c = 0; c < chunks; ++c) {
          if (j < chunks_[c].rowLo || j > chunks_[c].rowHi) continue;
          float* part = chunks_[c].cellMass.data() + static_cast<std::size_t>(j) * cellStride;
          for (int i = 0; i < nx; ++i) rho[i] += part[i];
          std::fill(part, part + nx, 0.0f);
        }
        for (int i = 0; i < nx; ++i) rho[i] *= perArea;
      }
      for (int axis = 0; axis < 2; ++axis) {
        if (axis == 0 && j == ny) continue;  // x faces have ny rows, y faces ny + 1
        const std::size_t width = stride[axis], first = static_cast<std::size_t>(j) * width;
        float* rho = faceDensity_.component(axis).data().data() + first;  // the mass sums, then rho
        float* vel = preferred_.component(axis).data().data() + first;   // the flow sums, then v~
        float* vmax = speed_.component(axis).data().data() + first;      // the speed sums, then v_max
        std::fill(rho, rho + width, 0.0f);
        std::fill(vel, vel + width, 0.0f);
        std::fill(vmax, vmax + width, speeds ? 0.0f : common);
        for (std::size_t c = 0; c < chunks; ++c) {
          SplatChunk& k = chunks_[c];
          if (j < k.rowLo || j > k.rowHi) continue;
          float* part = k.faceMassFlow[axis].data() + 2 * first;
          for (std::size_t i = 0; i < width; ++i) {
            rho[i] += part[2 * i];
            vel[i] += part[2 * i + 1];
          }
          std::fill(part, part + 2 * width, 0.0f);
          if (speeds) {
            float* speedPart = k.faceSpeed[axis].data() + first;
            for (std::size_t i = 0; i < width; ++i) vmax[i] += speedPart[i];
            std::fill(speedPart, speedPart + width, 0.0f);
          }
        }
        for (std::size_t i = 0; i < width; ++i) {
          const float m = rho[i];
          vel[i] = m > 0.0f ? vel[i] / m : 0.0f;
          if (speeds) vmax[i] = m > 0.0f ? vmax[i] / m : 0.0f;
          rho[i] = m * perArea;
        }
      }
    }
  });
}

// A of eq. 4.18: face weights rho_face dt / dx^2 on interior faces, walls (0) on the domain boundary.
void UicProjection::buildStencil(double dt) {
  const int nx = grid_.res.x(), ny = grid_.res.y();
  const double c = dt / (grid_.dx * grid_.dx);
  const double shift = settings_.regularization * settings_.rhoMax * c;
  const auto& fx = faceDensity_.component(0);
  const auto& fy = faceDensity_.component(1);
  parallelForCells<2>(grid_.res, [&](const IVec2& cell, std::size_t k) {
    const int i = cell.x(), j = cell.y();
    const std::size_t xf = static_cast<std::size_t>(j) * (nx + 1) + i, yf = k;
    const double wl = i > 0 ? fx[xf] * c : 0.0, wr = i + 1 < nx ? fx[xf + 1] * c : 0.0;
    const double wb = j > 0 ? fy[yf] * c : 0.0, wt = j + 1 < ny ? fy[yf + nx] * c : 0.0;
    lowerWeight_[0][k] = wl;
    lowerWeight_[1][k] = wb;
    const double sum = wl + wr + wb + wt;
    excluded_[k] = sum == 0.0;
    diagonal_[k] = sum + shift;
  });
  // Cells without faces decouple.
  numerics::setDecoupledDiagonals(diagonal_, [&](std::size_t k) { return excluded_[k] != 0; });
  // Bounding box of the cells the QP needs (A_ii > 0); every cell outside it is excluded and, since
  // excluded cells have only zero-weight faces, the box problem is exactly the full one restricted.
  struct Box { int lo[2], hi[2]; };
  const Box none{{nx, ny}, {-1, -1}};
  const Box box = tbb::parallel_reduce(
      tbb::blocked_range<int>(0, ny, 8), none,
      [&](const tbb::blocked_range<int>& r, Box b) {
        for (int j = r.begin(); j != r.end(); ++j) {
          const std::uint8_t* row = &excluded_[static_cast<std::size_t>(j) * nx];
          int first = 0, last = nx - 1;
          while (first < nx && row[first]) ++first;
          if (first == nx) continue;
          while (row[last]) --last;
          b.lo[0] = std::min(b.lo[0], first);
          b.hi[0] = std::max(b.hi[0], last);
          b.lo[1] = std::min(b.lo[1], j);
          b.hi[1] = std::max(b.hi[1], j);
        }
        return b;
      },
      [](Box a, const Box& b) {
        for (int d = 0; d < 2; ++d) {
          a.lo[d] = std::min(a.lo[d], b.lo[d]);
          a.hi[d] = std::max(a.hi[d], b.hi[d]);
        }
        return a;
      });
  boxEmpty_ = box.hi[0] < 0;
  if (boxEmpty_) return;
  boxOrigin_ = IVec2(box.lo[0], box.lo[1]);
  boxRes_ = IVec2(box.hi[0] - box.lo[0] + 1, box.hi[1] - box.lo[1] + 1);
  const std::size_t boxCells = static_cast<std::size_t>(boxRes_.x()) * boxRes_.y();
  for (auto& w : boxLower_) w.resize(boxCells);
  boxDiagonal_.resize(boxCells);
  forBox([&](std::size_t local, std::size_t k) {
    boxLower_[0][local] = lowerWeight_[0][k];
    boxLower_[1][local] = lowerWeight_[1][k];
    boxDiagonal_[local] = diagonal_[k];
  });
  operator_.assign(boxRes_, boxLower_, boxDiagonal_);
  preconditioner_.assign(boxRes_, boxLower_, boxDiagonal_);
}

// dx div(rho u) of cell `cell` (linear index k) by eq. 4.13: the net flux rho_face u_face out
// through its four faces; domain walls carry none.
double UicProjection::massOutflow(const MacGrid<2>& u, const IVec2& cell, std::size_t k) const {
  const int nx = grid_.res.x(), ny = grid_.res.y(), i = cell.x(), j = cell.y();
  const auto& rx = faceDensity_.component(0);
  const auto& ry = faceDensity_.component(1);
  const auto& ux = u.component(0);
  const auto& uy = u.component(1);
  const std::size_t xf = static_cast<std::size_t>(j) * (nx + 1) + i;
  const double left = i > 0 ? double(rx[xf]) * ux[xf] : 0.0;
  const double right = i + 1 < nx ? double(rx[xf + 1]) * ux[xf + 1] : 0.0;
  const double bottom = j > 0 ? double(ry[k]) * uy[k] : 0.0;
  const double top = j + 1 < ny ? double(ry[k + nx]) * uy[k + nx] : 0.0;
  return right - left + top - bottom;
}

// Solver right-hand side: minus b of eq. 4.17 with sigma = f rho_max - rho (ch. 4.4.3); the
// divergence is the flux sum of eq. 4.13 with no flux through the walls.
void UicProjection::assembleRhs(const MacGrid<2>& u, double dt, bool clampSigma, Eigen::VectorXd& rhs) const {
  const double rhoMax = settings_.rhoMax, dtOverDx = dt / grid_.dx;
  parallelForCells<2>(grid_.res, [&](const IVec2& cell, std::size_t k) {
    if (excluded_[k]) {
      rhs[k] = 0.0;
      return;
    }
    double sigma = freeArea_[k] * rhoMax - density_[k];
    if (clampSigma) sigma = std::max(sigma, 0.0);
    rhs[k] = -(sigma + massOutflow(u, cell, k) * dtOverDx);
  });
}

numerics::BoundQpResult UicProjection::solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& p) {
  parallelFor(0, excluded_.size(), [&](std::size_t k) {
    if (excluded_[k]) p[k] = 0.0;
  });
  if (boxEmpty_) {  // no agents: p = 0 solves the (empty) problem
    numerics::BoundQpResult none;
    none.converged = true;
    return none;
  }
  // The QP over the bounding box of the included cells, warm-started from p there.
  const Eigen::Index boxCells = static_cast<Eigen::Index>(boxRes_.x()) * boxRes_.y();
  boxRhs_.resize(boxCells);
  boxPressure_.resize(boxCells);
  forBox([&](std::size_t local, std::size_t k) {
    boxRhs_[static_cast<Eigen::Index>(local)] = rhs[static_cast<Eigen::Index>(k)];
    boxPressure_[static_cast<Eigen::Index>(local)] = p[static_cast<Eigen::Index>(k)];
  });
  // No cell asks for pressure (b <= 0): p = 0 meets the KKT conditions (A 0 - b >= 0), the usual
  // case in a crowd below capacity everywhere, and no solve is needed.
  const double largest = tbb::parallel_reduce(
      tbb::blocked_range<Eigen::Index>(0, boxCells, 4096), -std::numeric_limits<double>::infinity(),
      [&](const tbb::blocked_range<Eigen::Index>& r, double m) {
        for (Eigen::Index i = r.begin(); i != r.end(); ++i) m = std::max(m, boxRhs_[i]);
        return m;
      },
      [](double a, double b) { return std::max(a, b); });
  if (largest <= 0.0) {
    forBox([&](std::size_t, std::size_t k) { p[static_cast<Eigen::Index>(k)] = 0.0; });
    numerics::BoundQpResult none;
    none.activeCount = static_cast<int>(boxCells);
    none.converged = true;
    return none;
  }
  numerics::BoundQpSettings qp;
  const double norm = std::sqrt(parallelSum(static_cast<std::size_t>(boxCells), [&](std::size_t i) {
    return boxRhs_[static_cast<Eigen::Index>(i)] * boxRhs_[static_cast<Eigen::Index>(i)];
  }));
  // Absolute density tolerance (see UicSettings::tolerance) expressed relative to ||b||.
  qp.tolerance = norm > 0.0 ? settings_.tolerance * settings_.rhoMax / norm : 1.0;
  qp.maxIterations = settings_.maxIterations;
  const auto result = solver_.solve(operator_, boxRhs_, boxPressure_, qp, &preconditioner_);
  forBox([&](std::size_t local, std::size_t k) {
    p[static_cast<Eigen::Index>(k)] = boxPressure_[static_cast<Eigen::Index>(local)];
  });
  return result;
}

// psolve (eq. 4.5): u - grad p on the interior faces, zero normal velocity on the walls.
void UicProjection::subtractGradient(const MacGrid<2>& u, const Eigen::VectorXd& p, MacGrid<2>& out) const {
  const int nx = grid_.res.x();
  const double invDx = 1.0 / grid_.dx;
  for (int a = 0; a < 2; ++a) {
    const auto& in = u.component(a);
    auto& o = out.component(a);
    const std::size_t stride = a == 0 ? 1 : static_cast<std::size_t>(nx);
    parallelForCells<2>(o.size(), [&](const IVec2& f, std::size_t idx) {
      if (f[a] == 0 || f[a] == grid_.res[a]) {
        o[idx] = 0.0f;
        return;
      }
      const std::size_t upper = static_cast<std::size_t>(f.y()) * nx + f.x();  // cell above/right of the face
      o[idx] = static_cast<float>(in[idx] - (p[upper] - p[upper - stride]) * invDx);
    });
  }
}

// renorm (eq. 4.11): scale the face velocity vector to v_max on faces that carry agents. The
// tangential component is the density-weighted mean of the four neighbouring faces of the other
// axis, so a uniform field is reproduced exactly and empty faces do not bias it towards zero.
void UicProjection::renorm(const MacGrid<2>& u, MacGrid<2>& out) const {
  const int nx = grid_.res.x(), ny = grid_.res.y();
  const float minFraction = static_cast<float>(settings_.renormMinFraction);
  for (int a = 0; a < 2; ++a) {
    const auto& in = u.component(a);
    const auto& rho = faceDensity_.component(a);
    const auto& vmax = speed_.component(a);
    const auto& other = u.component(1 - a);
    const auto& otherRho = faceDensity_.component(1 - a);
    auto& o = out.component(a);
    const int faceNx = a == 0 ? nx + 1 : nx, faceNy = a == 0 ? ny : ny + 1;
    // The other-axis faces of the two cells sharing face (i, j): for an x face the y faces
    // (c, r) with c = i - 1, i and r = j, j + 1 (index r nx + c); for a y face the x faces (c, r)
    // with c = i, i + 1 and r = j - 1, j (index r (nx + 1) + c).
    const int otherNx = a == 0 ? nx : nx + 1;
    const int dc = a == 0 ? -1 : 0, dr = a == 0 ? 0 : -1;
    tbb::parallel_for(tbb::blocked_range<int>(0, faceNy, 8), [&](const tbb::blocked_range<int>& rows) {
      for (int j = rows.begin(); j != rows.end(); ++j)
        for (int i = 0; i < faceNx; ++i) {
          const std::size_t idx = static_cast<std::size_t>(j) * faceNx + i;
          if ((a == 0 ? i : j) == 0 || (a == 0 ? i == nx : j == ny)) {
            o[idx] = 0.0f;
            continue;
          }
          o[idx] = in[idx];
          if (!(rho[idx] > 0.0f)) continue;
          const std::size_t g = static_cast<std::size_t>(j + dr) * otherNx + (i + dc);
          const std::size_t gs[4] = {g, g + 1, g + otherNx, g + otherNx + 1};
          float wSum = 0.0f, wv = 0.0f;
          for (const std::size_t k : gs) {
            wSum += otherRho[k];
            wv += otherRho[k] * other[k];
          }
          const float tangential = wSum > 0.0f ? wv / wSum : 0.0f;
          const float speed = std::sqrt(in[idx] * in[idx] + tangential * tangential);
          if (vmax[idx] > 0.0f && speed > minFraction * vmax[idx]) o[idx] = in[idx] * (vmax[idx] / speed);
        }
    });
  }
}

// Density after one step with the final v (eq. 4.14) and the before/after ratio statistics.
void UicProjection::predict(double dt) {
  const double dtOverDx = dt / grid_.dx;
  parallelForCells<2>(grid_.res, [&](const IVec2& cell, std::size_t k) {
    predicted_[k] = static_cast<float>(density_[k] - massOutflow(velocity_, cell, k) * dtOverDx);
  });
  const double rhoMax = settings_.rhoMax;
  auto ratio = [&](const Grid<float, 2>& rho) {
    return parallelMax(rho.count(), [&](std::size_t k) {
      return freeArea_[k] > 0.0f ? std::max(0.0, double(rho[k])) / (freeArea_[k] * rhoMax) : 0.0;
    });
  };
  stats_.maxRatioBefore = ratio(density_);
  stats_.maxRatioAfter = ratio(predicted_);
}

// Eq. 4.3 with the ratio rho / (f rho_max) formed per cell, clamped to [0, 1] (a fully covered
// cell holding agents counts as saturated), and interpolated bilinearly to the agents.
void UicProjection::agentVelocities(std::span<const Vec2f> positions, std::span<const Vec2f> preferredVelocities,
                                    std::span<Vec2f> velocities) {
  const float rhoMax = static_cast<float>(settings_.rhoMax);
  parallelFor(0, ratio_.count(), [&](std::size_t k) {
    const float cap = freeArea_[k] * rhoMax;
    ratio_[k] = cap > 0.0f ? std::min(density_[k] / cap, 1.0f) : (density_[k] > 0.0f ? 1.0f : 0.0f);
  });
  // One pass over the agents: r from the cells, v from both face grids (bilinear, folded taps as
  // in core/transfer.hpp's gather).
  const int nx = grid_.res.x(), ny = grid_.res.y();
  const float ox = static_cast<float>(grid_.origin.x()), oy = static_cast<float>(grid_.origin.y());
  const float invDx = static_cast<float>(1.0 / grid_.dx);
  const float* rc = ratio_.data().data();
  const float* ux = velocity_.component(0).data().data();
  const float* uy = velocity_.component(1).data().data();
  const std::size_t xStride = static_cast<std::size_t>(nx) + 1, yStride = static_cast<std::size_t>(nx);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, positions.size(), 2048), [&](const tbb::blocked_range<std::size_t>& range) {
    // Local copies: the velocity stores (floats) could otherwise alias the captured scalars, which
    // would then be loaded again for every agent.
    const float x0 = ox, y0 = oy, scale = invDx;
    const int cellsX = nx, cellsY = ny;
    const std::size_t xs = xStride, ys = yStride;
    const float *ratio = rc, *flowX = ux, *flowY = uy;
    const Vec2f* x = positions.data();
    const Vec2f* preferred = preferredVelocities.data();
    Vec2f* out = velocities.data();
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      const float sx = (x[i].x() - x0) * scale, sy = (x[i].y() - y0) * scale;
      const Taps cx(sx - 0.5f, cellsX), cy(sy - 0.5f, cellsY), fx(sx, cellsX + 1), fy(sy, cellsY + 1);
      float r = 0.0f, vx = 0.0f, vy = 0.0f;
      for (int b = 0; b < 2; ++b) {
        const float* ratioRow = ratio + static_cast<std::size_t>(cy.at[b]) * ys;
        const float* xRow = flowX + static_cast<std::size_t>(cy.at[b]) * xs;
        const float* yRow = flowY + static_cast<std::size_t>(fy.at[b]) * ys;
        r += cy.w[b] * (cx.w[0] * ratioRow[cx.at[0]] + cx.w[1] * ratioRow[cx.at[1]]);
        vx += cy.w[b] * (fx.w[0] * xRow[fx.at[0]] + fx.w[1] * xRow[fx.at[1]]);
        vy += fy.w[b] * (cx.w[0] * yRow[cx.at[0]] + cx.w[1] * yRow[cx.at[1]]);
      }
      const float share = std::clamp(r, 0.0f, 1.0f);
      const Vec2f v = preferred[i];
      out[i] = v + share * (Vec2f(vx, vy) - v);
    }
  });
}

const UicStats& UicProjection::project(std::span<const Vec2f> positions, std::span<const Vec2f> preferredVelocities,
                                       std::span<const float> maxSpeeds, const Grid<float, 2>& freeArea, double dt,
                                       std::span<Vec2f> velocities) {
  const auto start = Clock::now();
  const SpeedRange speeds = validate(positions, preferredVelocities, maxSpeeds, freeArea, dt, velocities);
  stats_ = UicStats{};
  std::copy(freeArea.data().begin(), freeArea.data().end(), freeArea_.data().begin());
  splatAgents(positions, preferredVelocities, maxSpeeds, speeds);
  stats_.splatSeconds = seconds(start);

  const auto solveStart = Clock::now();
  buildStencil(dt);
  // Inner psolve with sigma^n clamped to >= 0 (the remark after eq. 4.20), then renorm.
  assembleRhs(preferred_, dt, true, rhs_);
  const auto inner = solve(rhs_, innerPressure_);
  subtractGradient(preferred_, innerPressure_, inner_);
  renorm(inner_, renormed_);
  // Outer psolve on the renormalised velocities with the full sigma^n.
  assembleRhs(renormed_, dt, false, rhs_);
  const auto outer = solve(rhs_, outerPressure_);
  subtractGradient(renormed_, outerPressure_, velocity_);
  stats_.innerIterations = inner.iterations;
  stats_.outerIterations = outer.iterations;
  stats_.converged = inner.converged && outer.converged;
  parallelFor(0, pressure_.count(), [&](std::size_t k) { pressure_[k] = static_cast<float>(outerPressure_[k]); });
  stats_.activeCells = static_cast<int>(
      parallelSum(pressure_.count(), [&](std::size_t k) { return outerPressure_[k] > 0.0 ? 1.0 : 0.0; }));
  predict(dt);
  stats_.solveSeconds = seconds(solveStart);

  const auto agentStart = Clock::now();
  agentVelocities(positions, preferredVelocities, velocities);
  stats_.agentSeconds = seconds(agentStart);
  stats_.totalSeconds = seconds(start);
  return stats_;
}

}  // namespace msim::crowd
