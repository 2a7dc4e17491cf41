#include "msim/scene/liquid/liquid_sources.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/core/parallel.hpp"
#include "msim/scene/keys/json_vectors.hpp"
#include "msim/scene/phenomenon_support.hpp"
#include "msim/scene/scene_file.hpp"
#include "msim/scene/schema/shape_schema.hpp"

namespace msim::scene {

void declareLiquidSources(Schema& root) {
  Schema source = Schema::object(
      "an emitter: liquid fills its shape every step and leaves it at its velocity; against a closed side the side "
      "lets it in there (an inflow)");
  source.field("shape", shapeSchema());
  source.vector("velocity", "m/s", {0.0, 0.0, 0.0}, "velocity of the emitted liquid").lengths({2, 3});
  source.vector("motion", "m/s", {0.0, 0.0, 0.0},
                "the emitter itself moves: its shape is translated by motion (t - start)")
      .lengths({2, 3});
  source.number("start", "s", 0.0, "emits from this time").min(0.0);
  source.number("stop", "s", 0.0, "emits until this time; 0 = to the end").min(0.0);
  root.array("sources", source, "emitters of liquid (taps, hoses, inflows)");

  Schema sink = Schema::object("a sink or drain: the liquid inside its shape is removed every step");
  sink.field("shape", shapeSchema());
  sink.number("start", "s", 0.0, "drains from this time").min(0.0);
  sink.number("stop", "s", 0.0, "drains until this time; 0 = to the end").min(0.0);
  root.array("sinks", sink, "sinks and drains");
}

namespace {

// Cross-section [m^(D-1)] of the covered cells (indices into `grid`, cell-centred) normal to the
// unit direction n: their volume over their extent along n (exact for boxes and cylinders aligned
// with n). Split: over every block's own cells.
template <int D>
double crossSection(const std::vector<std::pair<std::size_t, float>>& cells, const Grid<float, D>& grid,
                    const Vec<D>& n, DomainSplit<D>* split) {
  const GridSpec<D>& spec = grid.spec();
  const IndexBox<D> own = split ? split->owned() : IndexBox<D>{IVec<D>::Zero(), spec.res};
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, volume = 0.0;
  for (const auto& [cell, cover] : cells) {
    if (!own.contains(grid.coord(cell))) continue;
    const double s = grid.position(grid.coord(cell)).dot(n);
    lo = std::min(lo, s);
    hi = std::max(hi, s);
    volume += cover * spec.cellVolume();
  }
  if (split) {
    volume = split->sumOverRanks(volume);
    hi = split->maxOverRanks(hi);
    lo = -split->maxOverRanks(-lo);
  }
  return volume / (hi - lo + spec.dx);
}

}  // namespace

template <int D>
LiquidSources<D>::LiquidSources(const Scene& scene, const Grid<float, D>& solid, double initialVolume,
                                DomainSplit<D>* split) {
  const nlohmann::json& r = scene.resolved;
  const GridSpec<D> spec = solid.spec();
  const double duration = r.at("time").at("duration").get<double>();
  double emitted = 0.0;
  for (std::size_t i = 0; i < r.at("sources").size(); ++i) {
    const nlohmann::json& s = r.at("sources")[i];
    Region e;
    const std::string key = fmt::format("sources[{}].shape", i);
    e.shape = sceneShape<D>(scene, s.at("shape"), key);
    const auto cells = coveredOpenCells<D>(scene, *e.shape, solid, key, split);  // InputError inside a solid
    e.velocity = sceneVector<D>(s.at("velocity"));
    e.motion = sceneVector<D>(s.at("motion"));
    e.start = s.at("start").get<double>();
    e.stop = s.at("stop").get<double>();
    const double speed = e.velocity.norm();
    const double on = std::max(0.0, (e.stop > 0.0 ? std::min(e.stop, duration) : duration) - e.start);
    if (speed > 0.0) emitted += crossSection<D>(cells, solid, Vec<D>(e.velocity / speed), split) * speed * on;
    e.field = e.shape->distanceField(spec);
    emitters_.push_back(std::move(e));
  }
  for (std::size_t i = 0; i < r.at("sinks").size(); ++i) {
    const nlohmann::json& s = r.at("sinks")[i];
    Region k;
    const std::string key = fmt::format("sinks[{}].shape", i);
    k.shape = sceneShape<D>(scene, s.at("shape"), key);
    coveredOpenCells<D>(scene, *k.shape, solid, key, split);
    k.start = s.at("start").get<double>();
    k.stop = s.at("stop").get<double>();
    k.field = k.shape->distanceField(spec);
    sinks_.push_back(std::move(k));
  }
  // A closed domain with no sink keeps all it is given.
  bool closed = sinks_.empty();
  for (const auto& axis : openDomainSides<D>(r)) closed = closed && !axis[0] && !axis[1];
  if (closed && !emitters_.empty()) {
    double capacity = 0.0;
    const IndexBox<D> own = split ? split->owned() : IndexBox<D>{IVec<D>::Zero(), spec.res};
    for (std::size_t c = 0; c < solid.count(); ++c)
      capacity += solid[c] < 0.5f && own.contains(solid.coord(c)) ? spec.cellVolume() : 0.0;
    if (split) capacity = split->sumOverRanks(capacity);
    if (initialVolume + emitted > capacity)
      throw InputError(fmt::format(
          "{}: 'sources': the closed domain has {:.4g} m^{} of open space, but the initial liquid ({:.4g}) and what "
          "the sources emit over the run ({:.4g}: velocity times cross-section times the time they are on) come to "
          "{:.4g}: open a side of 'domain.boundaries', add a sink, or stop the sources sooner",
          scene.file.string(), capacity, D, initialVolume, emitted, initialVolume + emitted, D));
  }
}

template <int D>
const Grid<float, D>& LiquidSources<D>::regionAt(Region& r, double t) {
  if (r.motion.squaredNorm() == 0.0) return r.field;
  // The shape moved by `offset` seen from a grid moved the other way, as SceneObstacles places its
  // solids: meshes keep their fast whole-grid distance evaluation.
  GridSpec<D> shifted = r.field.spec();
  shifted.origin -= r.motion * (t - r.start);
  r.field.data() = r.shape->distanceField(shifted).data();
  return r.field;
}

template <int D>
double LiquidSources<D>::apply(fluid::LiquidSolver<D>& solver, double t) {
  double change = 0.0;
  for (Region& e : emitters_)
    if (e.on(t)) change += solver.emit(regionAt(e, t), e.velocity);
  for (Region& k : sinks_)
    if (k.on(t)) change -= solver.drain(k.field);
  return change;
}

template class LiquidSources<2>;
template class LiquidSources<3>;

}  // namespace msim::scene
