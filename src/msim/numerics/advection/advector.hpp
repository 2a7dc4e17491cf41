#pragma once
// Advector<T,D>: advection of gridded fields by a MAC velocity with the schemes of Selle ch. 2:
// a first-order building block (upwind or semi-Lagrangian), and BFECC or MacCormack built from it
// (ch. 2.4), with the new-extrema limiter of ch. 2.7 and first-order reversion next to solids
// (ch. 2.9).
//
// Works on cell-centred scalars (Grid<T,D>) and on MAC grids (each face component advected by the
// velocity interpolated to its own face positions, then limited on its own, as ch. 2.9 does).
// T is the storage type of the advected field: float for simulation, double where accuracy
// studies need it; both run the same code. The velocity is always a float MacGrid over `spec`.
//
// Scratch grids live in the object and are reused while the field layout stays the same, so
// steady stepping allocates nothing.
#include <concepts>
#include <cstdint>
#include <optional>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/numerics/advection/advection_settings.hpp"
#include "msim/numerics/advection/field_layout.hpp"
#include "msim/numerics/advection/velocity_sampler.hpp"

namespace msim::numerics {

template <typename T, int D>
class Advector {
 public:
  Advector(const GridSpec<D>& spec, const AdvectionSettings& settings,
           const AxisBoundaries<D>& boundaries = allClamped<D>());

  const AdvectionSettings& settings() const { return settings_; }
  void setSettings(const AdvectionSettings& settings) { settings_ = settings; }

  // Cells with mask > 0.5 are solid: their samples (and, on MAC grids, every face of a solid cell)
  // keep their values, and samples whose stencils read them fall back to first order.
  void setSolid(const Grid<float, D>& mask);
  void clearSolid() { solid_.reset(); }

  // Advance `field` (cell-centred, or any sample layout over `spec`) by dt in `velocity`.
  void advect(Grid<T, D>& field, const MacGrid<D>& velocity, double dt);
  // Advance every component of a MAC grid by dt in `velocity` (which may be the field itself; it
  // is then copied first so all components move with the velocity of time n).
  void advect(MacGrid<D>& field, const MacGrid<D>& velocity, double dt)
    requires std::same_as<T, float>;

 private:
  struct Scratch {
    Grid<T, D> forward, backward, corrected, lo, hi;
    std::vector<std::uint8_t> solid, touched;
  };
  Scratch& scratchFor(const Grid<T, D>& field, int slot);
  void markSolidSamples(const Grid<T, D>& field, std::vector<std::uint8_t>& flags) const;
  void advectComponent(Grid<T, D>& field, const VelocitySampler<D>& forward, const VelocitySampler<D>& backward,
                       double dt, Scratch& s);

  GridSpec<D> spec_;
  AdvectionSettings settings_;
  AxisBoundaries<D> boundaries_;
  std::optional<Grid<float, D>> solid_;
  Scratch scratch_[D + 1];   // slot 0: cell-centred / arbitrary grids, slot 1 + a: face component a
  MacGrid<D> velocityCopy_;  // for self-advection of a MAC grid
};

}  // namespace msim::numerics
