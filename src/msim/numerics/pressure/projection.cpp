#include "msim/numerics/pressure/projection.hpp"

#include <algorithm>

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
  mic0_.reset();
  multigrid_.reset();
  if (settings_.preconditioner == PressurePreconditioner::Mic0)
    mic0_ = std::make_unique<Mic0Preconditioner<D>>(matrix_, settings_.mic0);
  else
    multigrid_ = std::make_unique<MultigridPreconditioner<D>>(matrix_, weights_, settings_.multigrid);
}

template <int D>
void PressureProjection<D>::setSolidVelocity(const MacGrid<D>& solidVelocity) {
  solidVelocity_ = solidVelocity;
  // Domain walls do not move, whatever the obstacle velocity field says there.
  for (int a = 0; a < D; ++a) {
    auto& us = solidVelocity_.component(a);
    parallelForCells(us, [&](const IVec<D>& f, std::size_t lin) {
      if ((f[a] == 0 && sides_.side[a][0] == DomainSide::Wall) ||
          (f[a] == spec_.res[a] && sides_.side[a][1] == DomainSide::Wall))
        us[lin] = 0.0f;
    });
  }
}

template <int D>
void PressureProjection<D>::netOutflow(const MacGrid<D>& velocity, std::vector<float>& out) const {
  const auto& diag = matrix_.diag();
  parallelForCells<D>(spec_.res, [&](const IVec<D>& c, std::size_t lin) {
    if (diag[lin] <= 0.0f) {
      out[lin] = 0.0f;
      return;
    }
    float sum = 0.0f;
    for (int a = 0; a < D; ++a) {
      const auto& w = weights_.component(a);
      const auto& u = velocity.component(a);
      const auto& us = solidVelocity_.component(a);
      IVec<D> up = c;
      up[a] += 1;
      const float fluxUp = w(up) * u(up) + (1.0f - w(up)) * us(up);
      const float fluxLow = w(c) * u(c) + (1.0f - w(c)) * us(c);
      sum += fluxUp - fluxLow;
    }
    out[lin] = sum;
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
  const float toScaled = static_cast<float>(dt / (density * spec_.dx));
  netOutflow(velocity, rhs_);
  parallelFor(0, rhs_.size(), [&](std::size_t i) {
    rhs_[i] = -rhs_[i];
    scaledPressure_[i] = pressure_[i] * toScaled;
  });
  Preconditioner& M = multigrid_ ? static_cast<Preconditioner&>(*multigrid_) : *mic0_;
  const PcgStats stats = pcg_.solve(matrix_, floating_, M, rhs_, scaledPressure_, settings_.pcg);

  const float toPressure = 1.0f / toScaled;
  parallelFor(0, rhs_.size(), [&](std::size_t i) { pressure_[i] = scaledPressure_[i] * toPressure; });
  const Grid<float, D>& cells = pressure_;
  for (int a = 0; a < D; ++a) {
    auto& u = velocity.component(a);
    const auto& w = weights_.component(a);
    const auto& us = solidVelocity_.component(a);
    parallelForCells(u, [&](const IVec<D>& f, std::size_t lin) {
      if (w[lin] <= 0.0f) {
        u[lin] = us[lin];
        return;
      }
      IVec<D> low = f;
      low[a] -= 1;
      // Ghost cells beyond an open side hold p = 0.
      const float pUp = f[a] < spec_.res[a] ? scaledPressure_[cells.index(f)] : 0.0f;
      const float pLow = f[a] > 0 ? scaledPressure_[cells.index(low)] : 0.0f;
      u[lin] -= pUp - pLow;
    });
  }
  return stats;
}

template class PressureProjection<2>;
template class PressureProjection<3>;

}  // namespace msim::numerics
