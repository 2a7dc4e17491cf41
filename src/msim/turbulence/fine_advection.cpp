#include "msim/turbulence/fine_advection.hpp"

#include <algorithm>
#include <utility>

#include "msim/core/grid_window.hpp"
#include "msim/core/resample.hpp"

namespace msim::turbulence {

template <int D>
void turbulentAdvectingVelocity(const MacGrid<D>& velocity, const MacGrid<D>* turbulent, const IVec<D>& lo,
                                MacGrid<D>& out) {
  auto addIn = [](const float* big, float* window, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) window[i] += big[i];
  };
  for (int a = 0; a < D; ++a) {
    resampleLinear<D>(velocity.component(a), out.component(a));
    if (turbulent) forEachWindowRow<D>(turbulent->component(a), lo, out.component(a), addIn);
  }
}

template <int D>
FineAdvection<D>::Window::Window(const GridSpec<D>& fine, const IVec<D>& lo, const IVec<D>& size,
                                 const numerics::AdvectionSettings& advection)
    : lo(lo),
      size(size),
      field(GridSpec<D>(fine.origin + lo.template cast<double>() * fine.dx, fine.dx, size)),
      velocity(field.spec()),
      advector(field.spec(), advection) {}

template <int D>
FineAdvection<D>::FineAdvection(const GridSpec<D>& fine, const numerics::AdvectionSettings& advection)
    : fine_(fine), advection_(advection) {}

template <int D>
void FineAdvection<D>::setSolid(const Grid<float, D>& fineSolid) {
  solid_ = &fineSolid;
  solidStale_ = true;
}

template <int D>
void FineAdvection<D>::advect(std::initializer_list<Grid<float, D>*> fields, const IVec<D>& lo, const IVec<D>& size,
                              const MacGrid<D>& velocity, const MacGrid<D>* turbulent, double dt) {
  if (!window_ || window_->lo != lo || window_->size != size) {
    window_.reset();
    window_.emplace(fine_, lo, size, advection_);
    solidStale_ = solid_ != nullptr;
  }
  Window& w = *window_;
  auto copyIn = [](const float* big, float* window, std::size_t n) { std::copy(big, big + n, window); };
  auto copyOut = [](float* big, const float* window, std::size_t n) { std::copy(window, window + n, big); };
  if (solidStale_) {
    Grid<float, D> solid(w.field.spec());
    forEachWindowRow<D>(*solid_, lo, solid, copyIn);
    w.advector.setSolid(solid);
    solidStale_ = false;
  }
  turbulentAdvectingVelocity<D>(velocity, turbulent, lo, w.velocity);
  for (Grid<float, D>* field : fields) {
    forEachWindowRow<D>(std::as_const(*field), lo, w.field, copyIn);
    w.advector.advect(w.field, w.velocity, dt);
    forEachWindowRow<D>(*field, lo, std::as_const(w.field), copyOut);
  }
}

template void turbulentAdvectingVelocity<2>(const MacGrid<2>&, const MacGrid<2>*, const IVec<2>&, MacGrid<2>&);
template void turbulentAdvectingVelocity<3>(const MacGrid<3>&, const MacGrid<3>*, const IVec<3>&, MacGrid<3>&);
template class FineAdvection<2>;
template class FineAdvection<3>;

}  // namespace msim::turbulence
