#pragma once
// The obstacles[] of a smoke or liquid scene: static solids and rigidly moving ones, with motion
// x(t) = x0 + v t + A sin(2 pi f t). They give the solver, at any time, the nodal signed distance
// of the union of all solids and the velocity of the solid at every face (the moving-obstacle
// boundary condition of the projection).
#include <memory>
#include <string>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/geometry/shape.hpp"
#include "msim/scene/schema/schema.hpp"

namespace msim::scene {

struct Scene;

// The keys of one obstacles[] entry that SceneObstacles reads: shape and rigid motion.
Schema sceneObstacleSchema(const std::string& description);

template <int D>
class SceneObstacles {
 public:
  // Reads obstacles[]; InputError naming the key for an obstacle that never enters the domain
  // during the run.
  SceneObstacles(const Scene& scene, const GridSpec<D>& spec);

  bool empty() const { return obstacles_.empty(); }
  bool moving() const;
  // Signed distance of all solids at the grid nodes (res+1 per axis), negative inside, at time t.
  Grid<float, D> nodalDistance(double time) const;
  // Signed distance of all solids at the cell centres at time t [m] (saved with each frame so
  // renderers can draw the obstacles and refuse a camera inside one).
  Grid<float, D> cellDistance(double time) const;
  // Velocity of the nearest solid on every face at time t (0 for static solids).
  MacGrid<D> faceVelocity(double time) const;
  // Largest speed of any obstacle at time t [m/s].
  double maxSpeed(double time) const;

 private:
  struct Obstacle {
    std::unique_ptr<geometry::Shape<D>> shape;
    Vec<D> velocity, amplitude;
    double frequency = 0.0;
    bool moving() const { return velocity.squaredNorm() > 0.0 || (frequency > 0.0 && amplitude.squaredNorm() > 0.0); }
    Vec<D> offset(double t) const;
    Vec<D> velocityAt(double t) const;
  };
  // Warns (once) if the moving obstacle's box, inside a closed side at t = 0, crosses it at a frame
  // of the run.
  void warnOfClosedSides(const Scene& scene, const std::string& key, const Obstacle& o,
                         const geometry::Bounds<D>& bounds) const;
  // min over obstacles of their distance at x and time t; `nearest` gets the index of the closest.
  double distance(const Vec<D>& x, double t, std::size_t* nearest = nullptr) const;

  GridSpec<D> spec_;
  std::vector<Obstacle> obstacles_;
};

}  // namespace msim::scene
