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
// steady stepping allocates nothing. Semi-Lagrangian feet are cached: advecting several scalars
// by the same velocity and dt traces the characteristics once (see Feet below).
#include <concepts>
#include <cstdint>
#include <optional>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/numerics/advection/advection_settings.hpp"
#include "msim/numerics/advection/field_layout.hpp"
#include "msim/numerics/advection/semi_lagrangian.hpp"

namespace msim::numerics {

template <typename T, int D>
class Advector {
 public:
  // `placement`: where `spec` lies in a domain split among processes (msim/parallel); the
  // fields' ghost layers must then hold the neighbours' samples a step reads. Default: spec is
  // the whole domain.
  Advector(const GridSpec<D>& spec, const AdvectionSettings& settings,
           const AxisBoundaries<D>& boundaries = allClamped<D>(), const BlockPlacement<D>& placement = {});

  const AdvectionSettings& settings() const { return settings_; }
  // Where the grids lie in a split domain (see the constructor).
  void setPlacement(const BlockPlacement<D>& placement) {
    placement_ = placement;
    feet_.valid = false;
  }
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
    std::uint64_t solidVersion = 0;  // the solids `solid` was marked for (0: not marked)
  };
  // Semi-Lagrangian feet of the last field layout traced. They are reused while the layout, the
  // velocity (compared by value against velocity_), dt, the trace and the solids stay the same,
  // so every scalar after the first advected by one velocity skips the tracing.
  struct FeetCache {
    bool valid = false;
    GridSpec<D> spec;
    IVec<D> size;
    Vec<D> offset;
    double dt = 0.0;
    BackTrace trace = BackTrace::RK2;
    std::uint64_t solidVersion = 0;
    Feet<T, D> forward, backward;
    std::vector<std::uint8_t> touched;  // either stencil reads a solid sample (ch. 2.9)
  };
  Scratch& scratchFor(const Grid<T, D>& field, int slot);
  const std::uint8_t* solidSamples(const Grid<T, D>& field, Scratch& s);
  const FeetCache& feetFor(const Grid<T, D>& field, double dt, const std::uint8_t* solid);
  void holdVelocity(const MacGrid<D>& velocity);
  void advectComponent(Grid<T, D>& field, double dt, Scratch& s);

  GridSpec<D> spec_;
  AdvectionSettings settings_;
  AxisBoundaries<D> boundaries_;
  BlockPlacement<D> placement_;
  std::optional<Grid<float, D>> solid_;
  std::uint64_t solidVersion_ = 0;  // bumped by setSolid
  Scratch scratch_[D + 1];  // slot 0: cell-centred / arbitrary grids, slot 1 + a: face component a
  // Copy of the velocity being advected with: the key of feet_, and the velocity of time n when a
  // MAC grid advects itself.
  MacGrid<D> velocity_;
  FeetCache feet_;
};

}  // namespace msim::numerics
