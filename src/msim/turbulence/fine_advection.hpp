#pragma once
// Scalars on the fine grid of procedural turbulence carried by the coarse flow plus the eddies,
// U + u' (Narain 2011, ch. 3.5.2): the smoke's density and temperature, a liquid's fine surface
// (ch. 3.5.3). Only a box of the fine grid round the turbulence band is advected: the scalars are
// copied into a window over it, advected with U resampled onto the window's faces plus u', and
// copied back; the window (and its advector's scratch) is kept while the box stays the same.
#include <initializer_list>
#include <optional>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/numerics/advection/advector.hpp"

namespace msim::turbulence {

// U (coarse faces) resampled onto the faces of `out`, a MAC grid over the fine cells from fine
// cell lo, plus u' (turbulent, the whole fine grid's faces; null: U alone) there.
template <int D>
void turbulentAdvectingVelocity(const MacGrid<D>& velocity, const MacGrid<D>* turbulent, const IVec<D>& lo,
                                MacGrid<D>& out);

template <int D>
class FineAdvection {
 public:
  FineAdvection(const GridSpec<D>& fine, const numerics::AdvectionSettings& advection);

  // The fine solid mask (> 0.5 solid); read at the next advect().
  void setSolid(const Grid<float, D>& fineSolid);

  // Advects the fields (grids over the fine spec) inside the fine cells [lo, lo + size) by U + u'
  // (turbulent null: by U alone) over dt; outside the box they stay as they are.
  void advect(std::initializer_list<Grid<float, D>*> fields, const IVec<D>& lo, const IVec<D>& size,
              const MacGrid<D>& velocity, const MacGrid<D>* turbulent, double dt);

 private:
  struct Window {
    Window(const GridSpec<D>& fine, const IVec<D>& lo, const IVec<D>& size, const numerics::AdvectionSettings& advection);
    IVec<D> lo, size;
    Grid<float, D> field;
    MacGrid<D> velocity;
    numerics::Advector<float, D> advector;
  };

  GridSpec<D> fine_;
  numerics::AdvectionSettings advection_;
  const Grid<float, D>* solid_ = nullptr;
  std::optional<Window> window_;
  bool solidStale_ = false;
};

extern template class FineAdvection<2>;
extern template class FineAdvection<3>;

}  // namespace msim::turbulence
