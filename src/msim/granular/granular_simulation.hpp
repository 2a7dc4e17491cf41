#pragma once
// A granular material with rigid bodies, one time step as in Narain (2011) Fig. 5.7:
//   1. particles -> grid density and velocity (trilinear, ch. 5.4);
//   2. density correction (eq. 5.14);
//   3. staggered friction / pressure projections (ch. 5.3.5, 5.5.1) with the bodies coupled
//      (ch. 5.3.4);
//   4. the intermediate velocity v~ (eq. 5.27); v* includes gravity and the drag of winds, if any;
//   5. bodies take the impulse dt F of eq. 5.23 and move (rigid/World: gravity, contacts with the
//      domain, each other and static solids);
//   6. particles: FLIP velocities, advection with the correction displacement, shapes (eq. 5.42),
//      split and merge (ch. 5.4.1); render points follow (ch. 5.6).
// Static solids (containers such as the hourglass) close the faces they cover, so the material
// meets them like the domain walls, with wall friction from the edge stresses beside them.
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "msim/core/grid_spec.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/geometry/shape.hpp"
#include "msim/granular/granular_particles.hpp"
#include "msim/granular/particle_grid_transfer.hpp"
#include "msim/granular/particle_advection.hpp"
#include "msim/granular/render_points.hpp"
#include "msim/granular/split_merge.hpp"
#include "msim/granular/stress_solver.hpp"
#include "msim/rigid/world.hpp"
#include "msim/turbulence/turbulent_wind.hpp"

namespace msim::granular {

struct GranularSettings {
  GridSpec<3> grid;
  Vec3 gravity{0.0, -9.81, 0.0};
  double cfl = 0.5;                 // no particle moves more than this many cells per step (ch. 5.5)
  // 0.9 rather than the 0.95 of kDefaultFlipRatio: in a resting layer 0.95 leaves the particles' sub-grid
  // velocity noise (which no grid stress can see or dissipate) at 2x the mean speed of 0.9 after 1 s.
  double flipRatio = 0.9;
  StressSolverSettings stress;      // its upAxis follows gravity
  bool splitMerge = true;
  // Seeding density k (seed(), in [1, kMaxParticlesPerCell]); the particle radius r = dx / (2 cbrt k)
  // of split/merge and the seeded particle mass rho_max dx^3 / k follow from it (ch. 5.4.1).
  double particlesPerCell = kDefaultParticlesPerCell;
  std::size_t renderPointsPerParticle = 0;  // 0: no render points
  bool coupleBodies = true;         // false: bodies move through the material (one-way tests)
  // Response time of a free grain to the air [s] (winds, addWind): the drag (u_air - v) / tau per
  // unit mass, Stokes drag tau = rho_grain d^2 / (18 mu_air) for fine grains (0.1 s: about 0.1 mm).
  double airResponseTime = 0.1;
};

// Stage times of the last step [s] (the split of Table 5.1: pressure, friction, particles).
// Wall time of one step by stage [s]. assembly: the stress solve outside its QP loops (face
// coefficients, the problems' operators and body columns, the force bookkeeping); other: the rest
// of the step (the predicted velocity, the wall release, checks). The stages add up to `step`.
struct GranularStepTimes {
  double transfer = 0, correction = 0, assembly = 0, pressure = 0, friction = 0, bodies = 0, particles = 0, other = 0;
  double step = 0;
};

class GranularSimulation {
 public:
  // std::invalid_argument (clear message) for invalid materials, a non-positive grid, cfl <= 0.
  GranularSimulation(GranularSettings settings, std::vector<GranularMaterial> materials);

  // Solids that never move (their signed distance, negative inside). Closes the faces whose
  // centre lies inside. Call before the first step.
  void addStaticSolid(std::shared_ptr<const geometry::Shape<3>> solid);
  rigid::World& world() { return world_; }
  // A turbulent wind blowing through the material (several add up): grains feel the drag of
  // settings.airResponseTime in proportion to the open volume around them, 1 - phi, so a dispersed
  // cloud is carried along and a packed pile is not (the air cannot flow through it).
  void addWind(turbulence::TurbulentWind<3> wind) { winds_.push_back(std::move(wind)); }
  const std::vector<turbulence::TurbulentWind<3>>& winds() const { return winds_; }
  const rigid::World& world() const { return world_; }

  GranularParticles& particles() { return particles_; }
  const GranularParticles& particles() const { return particles_; }
  const std::vector<GranularMaterial>& materials() const { return materials_; }
  const RenderPoints* renderPoints() const { return renderPoints_ ? &*renderPoints_ : nullptr; }

  // Seeds settings.particlesPerCell particles per cell in [lo, hi] where inside(x) holds and no solid
  // is (seedRegion, with options.particlesPerCell replaced by the settings' value);
  // throws std::invalid_argument if the region lies entirely inside solids or outside the grid.
  std::size_t seed(const Vec3& lo, const Vec3& hi, const std::function<bool(const Vec3&)>& inside,
                   const SeedOptions& options);

  // After the particles were replaced (a resumed run): samples new render points inside them.
  // They are not the points of the interrupted run, which only follow particles' histories.
  void resampleRenderPoints();

  // The largest stable step: cfl dx / (max particle speed + |g| dt), at most maxDt.
  double stableTimestep(double maxDt) const;
  // One step of length dt. Throws std::runtime_error if a velocity becomes non-finite.
  void step(double dt);
  double time() const { return time_; }
  // Continues a saved run at time t (winds are sampled at the simulation time).
  void setTime(double t) { time_ = t; }

  const GranularSettings& settings() const { return settings_; }
  const ParticleGridFields& gridFields() const { return fields_; }
  const GranularGridState& gridState() const { return state_; }
  // v~ of the last step on the faces (eq. 5.27).
  const MacGrid<3>& gridVelocity() const { return velocityNew_; }
  const StressSolver& stress() const { return stress_; }
  const GranularStepTimes& lastStepTimes() const { return times_; }
  const SplitMergeStats& lastSplitMerge() const { return splitMergeStats_; }

  // Total mass and momentum of the particles (double sums), for conservation checks.
  double totalMass() const;
  Vec3 totalMomentum() const;
  // Signed distance to the nearest solid (static or body), negative inside.
  double solidDistance(const Vec3& x) const;

 private:
  // solidDistance(x) where it is below `cap`, and some value >= cap elsewhere: bodies whose bounding sphere
  // (radii from bodyBoundingRadii, in the world's order) lies at least that far away are skipped.
  double solidDistance(const Vec3& x, double cap, std::span<const double> bodyRadii) const;
  std::vector<double> bodyBoundingRadii() const;
  void buildGridState();
  void rasterizeBodies(double dt);
  void pushOutOfSolids();
  void removeVelocityAgainstCorrection();
  void initialiseRenderPoints();
  void applyWinds(double dt, FaceField& velocity);
  void releaseSeparatingWalls(FaceField& velocity) const;

  GranularSettings settings_;
  std::vector<GranularMaterial> materials_;
  std::vector<std::shared_ptr<const geometry::Shape<3>>> staticSolids_;
  rigid::World world_;
  GranularParticles particles_;
  ParticleGridTransfer transfer_;
  ParticleGridFields fields_;
  GranularGridState state_;
  FaceField wallFaces_;  // 1 open, 0 closed by the domain or a static solid
  FaceField predicted_;  // v* of the step, then v~ (solver storage kept between steps)
  StressSolver stress_;
  SplitMerge splitMerge_;
  SplitMergeStats splitMergeStats_;
  std::optional<RenderPoints> renderPoints_;
  std::vector<CoupledBody> bodies_;
  std::vector<int> bodyIndex_;  // world index of each coupled body
  MacGrid<3> velocityNew_, displacement_;
  std::vector<Vec3> correctionAt_;  // the correction displacement at each particle
  std::vector<ParticleMotion> motion_;  // each particle's last step, for its render points
  std::vector<turbulence::TurbulentWind<3>> winds_;
  std::vector<float> windScratch_;  // the summed winds on one face component
  GranularStepTimes times_;
  double time_ = 0.0;
};

}  // namespace msim::granular
