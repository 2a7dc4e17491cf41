#include "msim/scene/keys/scene_obstacles.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/core/log.hpp"
#include "msim/core/parallel.hpp"
#include "msim/numerics/pressure/face_fractions.hpp"
#include "msim/scene/keys/json_vectors.hpp"
#include "msim/scene/phenomenon_support.hpp"
#include "msim/scene/scene_file.hpp"
#include "msim/scene/schema/shape_schema.hpp"

namespace msim::scene {

Schema sceneObstacleSchema(const std::string& description) {
  Schema obstacle = Schema::object(description);
  obstacle.field("shape", shapeSchema());
  obstacle.vector("velocity", "m/s", {0.0, 0.0, 0.0}, "v of the motion x(t) = x0 + v t + A sin(2 pi f t)").lengths({2, 3});
  obstacle.vector("oscillation", "m", {0.0, 0.0, 0.0}, "amplitude A of the motion").lengths({2, 3});
  obstacle.number("frequency", "1/s", 0.0, "f of the motion").min(0.0);
  return obstacle;
}

template <int D>
Vec<D> SceneObstacles<D>::Obstacle::offset(double t) const {
  return velocity * t + amplitude * std::sin(2.0 * std::numbers::pi * frequency * t);
}

template <int D>
Vec<D> SceneObstacles<D>::Obstacle::velocityAt(double t) const {
  const double w = 2.0 * std::numbers::pi * frequency;
  return velocity + amplitude * (w * std::cos(w * t));
}

template <int D>
SceneObstacles<D>::SceneObstacles(const Scene& scene, const GridSpec<D>& spec) : spec_(spec) {
  const nlohmann::json& list = scene.resolved.at("obstacles");
  const double duration = scene.frameCount / scene.fps;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string key = fmt::format("obstacles[{}]", i);
    Obstacle o;
    o.shape = sceneShape<D>(scene, list[i].at("shape"), key + ".shape");
    o.velocity = sceneVector<D>(list[i].at("velocity"));
    o.amplitude = sceneVector<D>(list[i].at("oscillation"));
    o.frequency = list[i].at("frequency").get<double>();
    // An obstacle must cut the domain at some frame of the run, or it is a typo. The domain, not
    // `spec`: a run split among processes samples the obstacles on each rank's block only.
    const auto bounds = o.shape->bounds();
    const GridSpec<D> domain = scene.gridSpec<D>();
    const Vec<D> lo = domain.origin, hi = domain.origin + domain.extent();
    bool seen = false;
    for (int frame = 0; frame <= scene.frameCount && !seen; ++frame) {
      const Vec<D> shift = o.offset(frame / scene.fps);
      bool overlaps = true;
      for (int a = 0; a < D; ++a)
        overlaps = overlaps && bounds.min[a] + shift[a] < hi[a] && bounds.max[a] + shift[a] > lo[a];
      seen = overlaps;
      if (!o.moving()) break;
    }
    if (!seen)
      throw InputError(fmt::format("{}: '{}.shape' lies outside the domain{}", scene.file.string(), key,
                                   o.moving() ? fmt::format(" during the whole run (0 to {:.3g} s)", duration) : ""));
    if (o.moving()) warnOfClosedSides(scene, key, o, bounds);
    obstacles_.push_back(std::move(o));
  }
}

template <int D>
void SceneObstacles<D>::warnOfClosedSides(const Scene& scene, const std::string& key, const Obstacle& o,
                                          const geometry::Bounds<D>& bounds) const {
  // A solid moving into a closed side squeezes the air between them out through a closing gap
  // (and, once it passes the wall, takes volume from a box that cannot give it): the steps shrink
  // tenfold or more. Not an error (the scene may end first), but worth saying before the run.
  const nlohmann::json& sides = scene.resolved.at("domain").at("boundaries");
  const GridSpec<D> domain = scene.gridSpec<D>();
  const Vec<D> lo = domain.origin, hi = domain.origin + domain.extent();
  static const char* axes[] = {"x", "y", "z"};
  for (int frame = 1; frame <= scene.frameCount; ++frame) {
    const double t = frame / scene.fps;
    const Vec<D> shift = o.offset(t);
    for (int a = 0; a < D; ++a) {
      const bool lowClosed = sides.at(std::string(axes[a]) + "_min").get<std::string>() == "closed";
      const bool highClosed = sides.at(std::string(axes[a]) + "_max").get<std::string>() == "closed";
      const char* side = nullptr;
      if (lowClosed && bounds.min[a] >= lo[a] && bounds.min[a] + shift[a] < lo[a]) side = "_min";
      if (highClosed && bounds.max[a] <= hi[a] && bounds.max[a] + shift[a] > hi[a]) side = "_max";
      if (!side) continue;
      logger().warn("{}: {} reaches the closed side {}{} of the domain by t = {:.3g} s; the air pushed against the "
                    "wall escapes through a closing gap and the steps become much smaller (open that side, or end "
                    "the run before)",
                    scene.file.string(), key, axes[a], side, t);
      return;
    }
  }
}

template <int D>
bool SceneObstacles<D>::moving() const {
  for (const auto& o : obstacles_)
    if (o.moving()) return true;
  return false;
}

template <int D>
double SceneObstacles<D>::distance(const Vec<D>& x, double t, std::size_t* nearest) const {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    const double d = obstacles_[i].shape->distance(x - obstacles_[i].offset(t));
    if (d < best) {
      best = d;
      if (nearest) *nearest = i;
    }
  }
  return best;
}

template <int D>
Grid<float, D> SceneObstacles<D>::nodalDistance(double time) const {
  // Far from every solid the exact distance does not matter: cap it so an empty list is finite.
  const double cap = 1e3 * spec_.dx * spec_.res.maxCoeff();
  return numerics::sampleNodes<D>(spec_, [&](const Vec<D>& x) { return std::min(distance(x, time), cap); });
}

template <int D>
Grid<float, D> SceneObstacles<D>::cellDistance(double time) const {
  Grid<float, D> distance(spec_, std::numeric_limits<float>::max());
  for (const auto& o : obstacles_) {
    // The shape moved by `offset` seen from a grid moved the other way: meshes keep their fast
    // whole-grid distance evaluation.
    GridSpec<D> shifted = spec_;
    shifted.origin -= o.offset(time);
    const Grid<float, D> d = o.shape->distanceField(shifted);
    for (std::size_t i = 0; i < distance.count(); ++i) distance[i] = std::min(distance[i], d[i]);
  }
  return distance;
}

template <int D>
MacGrid<D> SceneObstacles<D>::faceVelocity(double time) const {
  MacGrid<D> v(spec_, 0.0f);
  if (!moving()) return v;
  for (int a = 0; a < D; ++a) {
    auto& u = v.component(a);
    parallelForCells(u, [&](const IVec<D>& f, std::size_t lin) {
      std::size_t nearest = 0;
      // Only faces the solid touches use this value; beyond a cell from every solid it is unused.
      if (distance(u.position(f), time, &nearest) < spec_.dx)
        u[lin] = static_cast<float>(obstacles_[nearest].velocityAt(time)[a]);
    });
  }
  return v;
}

template <int D>
double SceneObstacles<D>::maxSpeed(double time) const {
  double speed = 0.0;
  for (const auto& o : obstacles_) speed = std::max(speed, o.velocityAt(time).norm());
  return speed;
}

template class SceneObstacles<2>;
template class SceneObstacles<3>;

}  // namespace msim::scene
