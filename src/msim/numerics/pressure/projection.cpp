#include "msim/numerics/pressure/projection.hpp"

#include <algorithm>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "msim/core/parallel.hpp"

namespace msim::numerics {

template <int D>
PressureProjection<D>::PressureProjection(const GridSpec<D>& spec, const DomainSides<D>& sides,
                                          const ProjectionSettings& settings)
    : spec_(spec),
      sides_(sides),
      settings_(settings),
      solidVelocity_(spec, 0.0f),
      pressure_(spec, 0.0f),
      rhs_(spec.cellCount(), 0.0f),
      scaledPressure_(spec.cellCount(), 0.0f) {
  setSolids(MacGrid<D>(spec, 1.0f));
}

template <int D>
void PressureProjection<D>::setSolids(const MacGrid<D>& openFraction) {
  weights_ = MacGrid<D>(spec_);
  for (int a = 0; a < D; ++a) {
    const auto& in = openFraction.component(a);
    auto& w = weights_.component(a);
    parallelForCells(w, [&](const IVec<D>& f, std::size_t lin) {
      const bool lowerWall = f[a] == 0 && sides_.side[a][0] == DomainSide::Wall;
      const bool upperWall = f[a] == spec_.res[a] && sides_.side[a][1] == DomainSide::Wall;
      const float open = std::min(in[lin], 1.0f);
      w[lin] = (lowerWall || upperWall || !(open >= settings_.minOpenFraction)) ? 0.0f : open;
    });
  }
  matrix_ = PoissonMatrix<D>(weights_);
  floating_ = FloatingRegions<D>(weights_);
  freeSurface_ = false;
  inverseTheta_ = MacGrid<D>();
  invalidatePreconditioner();
}

template <int D>
void PressureProjection<D>::invalidatePreconditioner() {
  mic0_.reset();
  multigrid_.reset();
  preconditionerStale_ = true;
}

template <int D>
void PressureProjection<D>::buildPreconditioner() {
  preconditionerStale_ = false;
  if (settings_.preconditioner == PressurePreconditioner::Mic0)
    mic0_ = std::make_unique<Mic0Preconditioner<D>>(matrix_, settings_.mic0);
  else if (freeSurface_)
    multigrid_ = std::make_unique<MultigridPreconditioner<D>>(matrix_, coupling_, settings_.multigrid, dirichlet_);
  else
    multigrid_ = std::make_unique<MultigridPreconditioner<D>>(matrix_, weights_, settings_.multigrid);
}

template <int D>
void PressureProjection<D>::setFreeSurface(const Grid<float, D>& liquidPhi, float minTheta) {
  if (!liquidPhi.sameLayout(pressure_))
    throw std::invalid_argument("pressure projection: the liquid's phi must be cell-centred on the pressure grid");
  auto liquid = [&](std::size_t cell) { return liquidPhi[cell] < 0.0f; };
  auto theta = [&](std::size_t wet, std::size_t dry) {
    return std::max(minTheta, liquidPhi[wet] / (liquidPhi[wet] - liquidPhi[dry]));
  };
  // Couplings only between liquid cells (a boundary face keeps its weight when its cell is
  // liquid: the open side's ghost pressure is 0 as before); 1 / theta on the liquid-air faces.
  // Storage kept across calls (the liquid sets its surface every step).
  MacGrid<D>& coupling = coupling_;
  if (!freeSurface_) {
    coupling = MacGrid<D>(spec_);
    inverseTheta_ = MacGrid<D>(spec_);
  }
  coupling.fill(0.0f);
  inverseTheta_.fill(1.0f);
  for (int a = 0; a < D; ++a) {
    const auto& w = weights_.component(a);
    auto& c = coupling.component(a);
    auto& it = inverseTheta_.component(a);
    parallelForCells(w, [&](const IVec<D>& f, std::size_t lin) {
      IVec<D> low = f;
      low[a] -= 1;
      const bool hasLow = f[a] > 0, hasUp = f[a] < spec_.res[a];
      const std::size_t up = hasUp ? liquidPhi.index(f) : 0, lo = hasLow ? liquidPhi.index(low) : 0;
      if (!hasLow || !hasUp) {
        c[lin] = liquid(hasUp ? up : lo) ? w[lin] : 0.0f;
      } else if (liquid(lo) && liquid(up)) {
        c[lin] = w[lin];
      } else if (liquid(lo) != liquid(up)) {
        it[lin] = 1.0f / (liquid(lo) ? theta(lo, up) : theta(up, lo));
      }
    });
  }
  // Each liquid cell's Dirichlet terms: w_f / theta over its faces towards air.
  std::vector<float>& dirichlet = dirichlet_;
  dirichlet.assign(spec_.cellCount(), 0.0f);
  parallelForCells(liquidPhi, [&](const IVec<D>& c, std::size_t cell) {
    if (!liquid(cell)) return;
    float sum = 0.0f;
    for (int a = 0; a < D; ++a) {
      for (int side = 0; side < 2; ++side) {
        IVec<D> face = c;
        face[a] += side;
        IVec<D> nb = c;
        nb[a] += side ? 1 : -1;
        if (nb[a] < 0 || nb[a] >= spec_.res[a]) continue;
        const std::size_t n = liquidPhi.index(nb);
        if (!liquid(n)) sum += weights_.component(a)(face) * inverseTheta_.component(a)(face);
      }
    }
    dirichlet[cell] = sum;
  });
  freeSurface_ = true;
  matrix_ = PoissonMatrix<D>(coupling, dirichlet);
  floating_ = FloatingRegions<D>(coupling, dirichlet);
  invalidatePreconditioner();
}

template <int D>
void PressureProjection<D>::setSolidVelocity(const MacGrid<D>& solidVelocity) {
  solidVelocity_ = solidVelocity;
  applyWallVelocities();
}

template <int D>
void PressureProjection<D>::setWallNormalVelocity(int axis, int side, double velocity) {
  wallNormalVelocity_[axis][side] = static_cast<float>(velocity);
  applyWallVelocities();
}

template <int D>
void PressureProjection<D>::setWallFaceVelocity(const MacGrid<D>* velocity) {
  if (velocity)
    wallFaceVelocity_ = *velocity;
  else
    wallFaceVelocity_.reset();
  applyWallVelocities();
}

template <int D>
void PressureProjection<D>::applyWallVelocities() {
  // A domain wall moves with its own normal velocity, whatever the obstacle velocity field says.
  for (int a = 0; a < D; ++a) {
    auto& us = solidVelocity_.component(a);
    parallelForCells(us, [&](const IVec<D>& f, std::size_t lin) {
      for (int s = 0; s < 2; ++s)
        if (f[a] == (s == 0 ? 0 : spec_.res[a]) && sides_.side[a][s] == DomainSide::Wall)
          us[lin] = wallNormalVelocity_[a][s] + (wallFaceVelocity_ ? wallFaceVelocity_->component(a)[lin] : 0.0f);
    });
  }
}

// The per-face loops below run over x-rows (one task per block of rows) with the neighbouring
// rows as pointers: the straightforward per-face coordinate arithmetic cost as much as a V-cycle.
namespace {

// f(row, coord) for every x-row of an index box: coord[b] (b >= 1) are the row's coordinates.
template <int D, typename F>
void forEachRow(const IVec<D>& size, F&& f) {
  std::size_t rows = 1;
  for (int b = 1; b < D; ++b) rows *= static_cast<std::size_t>(size[b]);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows, 16), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t row = r.begin(); row != r.end(); ++row) {
      IVec<D> c = IVec<D>::Zero();
      std::size_t rest = row;
      for (int b = 1; b < D; ++b) {
        c[b] = static_cast<int>(rest % static_cast<std::size_t>(size[b]));
        rest /= static_cast<std::size_t>(size[b]);
      }
      f(row, c);
    }
  });
}

// Linear index of the first sample of the x-row at c (c[0] ignored).
template <typename T, int D>
std::size_t rowStart(const Grid<T, D>& g, const IVec<D>& c) {
  std::ptrdiff_t i = 0;
  for (int b = 1; b < D; ++b) i += c[b] * g.stride(b);
  return static_cast<std::size_t>(i);
}

}  // namespace

template <int D>
void PressureProjection<D>::netOutflow(const MacGrid<D>& velocity, std::vector<float>& out) const {
  const float* diag = matrix_.diag().data();
  const int nx = spec_.res[0];
  forEachRow<D>(spec_.res, [&](std::size_t row, const IVec<D>& c) {
    float* o = out.data() + row * nx;
    std::fill(o, o + nx, 0.0f);
    for (int a = 0; a < D; ++a) {
      const auto& w = weights_.component(a);
      const auto& u = velocity.component(a);
      const auto& us = solidVelocity_.component(a);
      IVec<D> up = c;
      up[a] += a > 0;
      // Faces below and above the cells of the row (on axis 0 the same row, shifted by one).
      const std::size_t lo = rowStart(w, c), hi = a == 0 ? lo + 1 : rowStart(w, up);
      for (int i = 0; i < nx; ++i) {
        const float fluxUp = w[hi + i] * u[hi + i] + (1.0f - w[hi + i]) * us[hi + i];
        const float fluxLow = w[lo + i] * u[lo + i] + (1.0f - w[lo + i]) * us[lo + i];
        o[i] += fluxUp - fluxLow;
      }
    }
    const float* d = diag + row * nx;
    for (int i = 0; i < nx; ++i) o[i] = d[i] > 0.0f ? o[i] : 0.0f;
  });
}

template <int D>
void PressureProjection<D>::divergence(const MacGrid<D>& velocity, Grid<float, D>& out) const {
  if (!out.sameLayout(pressure_)) out = Grid<float, D>(spec_);
  netOutflow(velocity, out.data());
  const float invDx = static_cast<float>(1.0 / spec_.dx);
  for (float& v : out.data()) v *= invDx;
}

template <int D>
PcgStats PressureProjection<D>::project(MacGrid<D>& velocity, double dt, double density) {
  // The pressure is kept as p dt / (rho dx) in the solve: a zero step would make it infinite.
  if (!(dt > 0.0) || !(density > 0.0))
    throw std::invalid_argument("pressure projection: the step and the density must be positive");
  const float toScaled = static_cast<float>(dt / (density * spec_.dx));
  netOutflow(velocity, rhs_);
  // A p^ = -dx (div u* - c): the cells keep the target divergence c (0 unless volume control or
  // an expanding source).
  const float dx = static_cast<float>(spec_.dx), targetOutflow = dx * targetDivergence_;
  const float* cellTarget = cellTargetDivergence_ ? cellTargetDivergence_->data().data() : nullptr;
  const std::vector<float>& diag = matrix_.diag();
  parallelFor(0, rhs_.size(), [&](std::size_t i) {
    const float outflow = cellTarget ? targetOutflow + dx * cellTarget[i] : targetOutflow;
    rhs_[i] = diag[i] > 0.0f ? outflow - rhs_[i] : 0.0f;
    scaledPressure_[i] = pressure_[i] * toScaled;
  });
  if (preconditionerStale_) buildPreconditioner();
  Preconditioner& M = multigrid_ ? static_cast<Preconditioner&>(*multigrid_) : *mic0_;
  const PcgStats stats = pcg_.solve(matrix_, floating_, M, rhs_, scaledPressure_, settings_.pcg);

  const float toPressure = 1.0f / toScaled;
  parallelFor(0, rhs_.size(), [&](std::size_t i) { pressure_[i] = scaledPressure_[i] * toPressure; });
  const Grid<float, D>& cells = pressure_;
  const float* p = scaledPressure_.data();
  for (int a = 0; a < D; ++a) {
    auto& u = velocity.component(a);
    const auto& w = weights_.component(a);
    const auto& us = solidVelocity_.component(a);
    const int nx = u.size()[0];
    forEachRow<D>(u.size(), [&](std::size_t row, const IVec<D>& f) {
      const std::size_t base = row * nx;
      float* ur = u.data().data() + base;
      const float* wr = w.data().data() + base;
      const float* usr = us.data().data() + base;
      const float* itr = freeSurface_ ? inverseTheta_.component(a).data().data() + base : nullptr;
      // Cells above and below each face of the row. A missing one (ghost beyond an open side,
      // p = 0) reads the other row times 0; on walls w = 0 and the face takes the solid velocity.
      IVec<D> low = f;
      low[a] -= a > 0;
      const bool hasUp = a == 0 || f[a] < spec_.res[a], hasLow = a == 0 || f[a] > 0;
      const float* pUp = p + rowStart(cells, hasUp ? f : low);
      const float* pLow = p + rowStart(cells, hasLow ? low : f);
      const float kUp = hasUp ? 1.0f : 0.0f, kLow = hasLow ? 1.0f : 0.0f;
      const int shift = a == 0;  // along x, the cell below face i is cell i - 1 of the same row
      // Across a free surface the air's side reads 0 and the difference is divided by theta.
      auto update = [&](int i, float up, float lo) {
        const float scale = itr ? itr[i] : 1.0f;
        ur[i] = wr[i] > 0.0f ? ur[i] - (up - lo) * scale : usr[i];
      };
      if (a == 0) {  // the row's ends face the ghosts of the x sides
        update(0, pUp[0], 0.0f);
        update(nx - 1, 0.0f, pLow[nx - 2]);
      }
      for (int i = shift; i < nx - shift; ++i) update(i, kUp * pUp[i], kLow * pLow[i - shift]);
    });
  }
  return stats;
}

template class PressureProjection<2>;
template class PressureProjection<3>;

}  // namespace msim::numerics
