#pragma once
// The liquid's emitters and sinks from scene keys `sources[]` and `sinks[]` (docs/liquid.md).
// An emitter fills its shape with liquid moving at its velocity every step while it is on (a
// hose, a tap, an inflow); its shape may itself move (`motion`, a pouring jug). A sink removes the
// liquid inside its shape (a drain in a tank's floor, an outflow). Checked before the run: a shape
// that covers no open cell, and a closed domain that the initial liquid and the emitters would
// fill beyond its open volume.
#include <memory>
#include <vector>

#include <nlohmann/json.hpp>

#include "msim/core/domain_split.hpp"
#include "msim/core/grid.hpp"
#include "msim/fluid/liquid/liquid_solver.hpp"
#include "msim/geometry/shape.hpp"
#include "msim/scene/schema/schema.hpp"

namespace msim::scene {

struct Scene;

void declareLiquidSources(Schema& root);

template <int D>
class LiquidSources {
 public:
  // InputError naming the key for a shape covering no open cell of `solid`, or for a closed
  // domain (no open side, no sink) that initialVolume [m^3] plus the emitted liquid would overfill.
  // A run split among processes (`split`): `solid` is the block's, the checks are over every
  // block (collective), and apply must run on every process alike.
  LiquidSources(const Scene& scene, const Grid<float, D>& solid, double initialVolume, DomainSplit<D>* split = nullptr);

  // Applies the emitters and sinks that are on at time t [s] (before the solver's step from t).
  // Returns the volume added less the volume removed [m^3].
  double apply(fluid::LiquidSolver<D>& solver, double t);
  bool empty() const { return emitters_.empty() && sinks_.empty(); }

 private:
  struct Region {
    std::unique_ptr<geometry::Shape<D>> shape;
    Vec<D> velocity = Vec<D>::Zero(), motion = Vec<D>::Zero();
    double start = 0.0, stop = 0.0;  // stop 0: to the end
    Grid<float, D> field;            // the shape's distance at the cell centres (where it is now)
    bool on(double t) const { return t >= start && (stop <= 0.0 || t < stop); }
  };
  // The shape's distance, translated by motion (t - start) when it moves.
  static const Grid<float, D>& regionAt(Region& r, double t);

  std::vector<Region> emitters_, sinks_;
};

}  // namespace msim::scene
