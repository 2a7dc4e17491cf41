#include "msim/scene/liquid/liquid_phenomenon.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/core/log.hpp"
#include "msim/core/parallel.hpp"
#include "msim/fluid/liquid/liquid_solver.hpp"
#include "msim/fluid/liquid/liquid_turbulence.hpp"
#include "msim/io/level_set_mesh.hpp"
#include "msim/io/obj.hpp"
#include "msim/io/ply.hpp"
#include "msim/io/vdb.hpp"
#include "msim/numerics/level_set/level_set_measures.hpp"
#include "msim/parallel/ghost_layers.hpp"
#include "msim/parallel/mpi_session.hpp"
#include "msim/scene/keys/json_vectors.hpp"
#include "msim/scene/keys/mpi_split_keys.hpp"
#include "msim/scene/liquid/liquid_sources.hpp"
#include "msim/scene/phenomenon_support.hpp"
#include "msim/scene/scene_file.hpp"
#include "msim/scene/keys/scene_obstacles.hpp"
#include "msim/scene/schema/shape_schema.hpp"
#include "msim/scene/keys/subgrid_turbulence_keys.hpp"
#include "msim/scene/keys/vortex_particle_keys.hpp"

namespace msim::scene {

namespace {

using nlohmann::json;

constexpr const char* kPhi = "liquid_phi";  // the surface: the fine one with sub-grid turbulence
constexpr const char* kSimulationPhi = "liquid_sim_phi";  // with turbulence: the simulation grid's
constexpr const char* kLevelSetParticles = "level_set_particles";
constexpr const char* kFlipParticles = "flip_particles";
constexpr const char* kVortexPoints = "vortex_particles";
// Volume control's state among the frame's numbers (--resume continues it): each one's name, and
// "volume_control_started" (1 or 0).
constexpr std::array<std::pair<const char*, double fluid::VolumeControlState::*>, 6> kVolumeControlNumbers = {{
    {"volume_control_target", &fluid::VolumeControlState::target},
    {"volume_control_integral", &fluid::VolumeControlState::errorIntegral},
    {"volume_control_last_error", &fluid::VolumeControlState::lastError},
    {"volume_control_divergence", &fluid::VolumeControlState::divergence},
    {"volume_control_leak_rate", &fluid::VolumeControlState::leakRate},
    {"volume_control_flip_scale", &fluid::VolumeControlState::flipScale},
}};

void declareLiquid(Schema& root) {
  Schema liquid = Schema::object("the liquid and how its surface is tracked (docs/liquid.md)");
  liquid.string("tracker", "particle_level_set",
                "particle_level_set: level set corrected by marker particles (Selle ch. 4.4.3); flip: PIC/FLIP "
                "particles carry the liquid (Golas ch. 2.7)")
      .choices({"particle_level_set", "flip"});
  liquid.number("density", "kg/m^3", 1000.0, "rho of the liquid").min(0.0, Bound::Exclusive);
  liquid.vector("gravity", "m/s^2", {0.0, -9.81, 0.0}, "acceleration of gravity").lengths({2, 3});
  liquid.number("flip_ratio", "", 0.95, "FLIP share of the PIC/FLIP blend: 1 FLIP, 0 PIC").min(0.0).max(1.0);
  liquid.integer("reseed_interval", 5, "steps between reseedings of the particle level set (and deletions of its escaped particles)").min(1);
  liquid.boolean("volume_control", true,
                 "hold the liquid's volume: the pressure solve asks the liquid for the divergence that undoes the "
                 "measured volume error (Kim et al. 2007)");
  liquid.string("mesh_format", "ply", "the surface mesh written per frame in 3D (mesh/<name>_NNNN.*): ply, obj, both or none")
      .choices({"ply", "obj", "both", "none"});
  Schema turbulence = Schema::object(
      "sub-grid turbulence at the free surface (Narain ch. 3.5.3): the energy model and noise particles ripple a "
      "surface on a finer grid, which is written, meshed, previewed and rendered");
  declareSubgridTurbulenceKeys(turbulence, "ripple the surface with sub-grid turbulence", 1.0e-6);
  liquid.field("turbulence", turbulence);
  liquid.field("vortex_particles", vortexParticleKeys());
  root.field("liquid", liquid);

  Schema body = Schema::object("liquid present at the start");
  body.field("shape", shapeSchema());
  body.vector("velocity", "m/s", {0.0, 0.0, 0.0}, "initial velocity of this body").lengths({2, 3});
  root.array("initial_liquid", body, "bodies of liquid at t = 0 (their union)");
  root.array("obstacles", sceneObstacleSchema("a solid the liquid flows around; moving ones push it"),
             "static and moving solids (free-slip walls)");
  declareLiquidSources(root);
}

double liquidBytesPerCell(int dimensions, const json& resolved) {
  // phi, solid, pressure phi, pressure, the matrix (D + 2), MIC(0) (2), PCG (4 + 2), face phi,
  // velocity, its copy, weights, solid velocity, 1/theta and the advector's scratch (about 6
  // face grids), known flags (bytes): ~ 18 + 12 D floats. Particles: the particle level set keeps
  // 16 (2D) or 32 (3D) of 29 bytes in each band cell, about a tenth of the cells; FLIP 2^D of 24
  // bytes in each liquid cell, about half of them. While a frame is written the VDB writer holds
  // copies of phi, the velocities and the particles (about 40 floats a cell more): a 256^3 FLIP
  // dam break with a quarter of the box filled peaked at 480 bytes per cell.
  // Sub-grid turbulence: per fine cell phi, phi~, the fine solid, u' (D floats), the potential's
  // node weight and value (4 floats), the advection window's phi, velocity and scratch (about
  // 6 + 3 D floats where the band's box covers the grid): ~ 13 + 4 D floats.
  const bool flip = resolved.at("liquid").at("tracker").get<std::string>() == "flip";
  const double particles = flip ? 0.5 * (1 << dimensions) * 24.0 : 0.1 * (dimensions == 2 ? 16 : 32) * 29.0;
  const json& t = resolved.at("liquid").at("turbulence");
  const double fine = t.at("enabled").get<bool>() ? std::pow(t.at("refinement").get<int>(), dimensions) * 4.0 * (13 + 4 * dimensions) : 0.0;
  return 4.0 * (58 + 12 * dimensions) + particles + fine;
}

template <int D>
fluid::LiquidParams<D> liquidParams(const Scene& scene) {
  const json& l = scene.resolved.at("liquid");
  fluid::LiquidParams<D> p;
  p.tracker = l.at("tracker").get<std::string>() == "flip" ? fluid::InterfaceTracker::Flip
                                                           : fluid::InterfaceTracker::ParticleLevelSet;
  p.density = l.at("density").get<double>();
  p.gravity = sceneVector<D>(l.at("gravity"));
  p.flipRatio = l.at("flip_ratio").get<double>();
  p.reseedInterval = l.at("reseed_interval").get<int>();
  p.volumeControl = l.at("volume_control").get<bool>();
  p.cfl = scene.resolved.at("time").at("cfl").get<double>();
  const auto open = openDomainSides<D>(scene.resolved);
  for (int a = 0; a < D; ++a)
    for (int s = 0; s < 2; ++s) p.sides.side[a][s] = open[a][s] ? numerics::DomainSide::Open : numerics::DomainSide::Wall;
  return p;
}

template <int D>
fluid::LiquidTurbulenceParams liquidTurbulenceParams(const Scene& scene) {
  const json& l = scene.resolved.at("liquid");
  fluid::LiquidTurbulenceParams p;
  static_cast<turbulence::SubgridTurbulenceParams&>(p) = subgridTurbulenceParams(l.at("turbulence"));
  p.energy.advection = liquidParams<D>(scene).advection;
  p.gravity = sceneVector<D>(l.at("gravity")).norm();
  if (!(p.gravity > 0.0))
    throw InputError(fmt::format("{}: 'liquid.turbulence' needs gravity: 'liquid.gravity' is zero, and the ripples' time "
                                 "scale is that of gravity waves (Narain eq. 3.13)",
                                 scene.file.string()));
  return p;
}

// Under mpirun with several processes the grid is split among them (msim/parallel; docs/parallel.md):
// each runs the solver on its block and rank 0 gathers every frame. What is not distributed yet is
// refused here, naming the key.
template <int D>
std::unique_ptr<DomainSplit<D>> liquidSplit(const Scene& scene) {
  if (parallel::worldSize() == 1) return nullptr;
  const json& r = scene.resolved;
  const json& l = r.at("liquid");
  if constexpr (D != 3) {
    refuseSplit(scene, "domain.resolution", "a 2D grid");
  } else {
    if (l.at("turbulence").at("enabled").get<bool>()) refuseSplit(scene, "liquid.turbulence.enabled", "sub-grid turbulence");
    const fluid::LiquidParams<3> p = liquidParams<3>(scene);
    const int needed = parallel::liquidGhostLayers(p.advection, std::max(1.0, p.cfl), p.bandCells);
    const std::string reads =
        fmt::format("this liquid (its advection at CFL {:g}, the fast marching's band of {:g} cells)", p.cfl, p.bandCells);
    return sceneDomainSplit(scene, needed, reads, p.sides, p.projection.pcg);
  }
}

// A split run's frame on rank 0: the fields, the particles (rows: the marker particles' position,
// radius and sign, or FLIP's position and velocity) and the statistics, reduced over the ranks.
template <int D>
struct GatheredLiquid {
  Grid<float, D> phi, solid;
  MacGrid<D> velocity;
  std::vector<double> particles;
  fluid::LiquidStatistics statistics;
  bool solidGathered = false;
};

template <int D>
class LiquidPhenomenon final : public Phenomenon {
 public:
  LiquidPhenomenon(const Scene& scene, StageTimers& timers)
      : source_(scene.file.string()),
        name_(scene.resolved.at("name").get<std::string>()),
        meshFormat_(scene.resolved.at("liquid").at("mesh_format").get<std::string>()),
        timers_(timers),
        split_(liquidSplit<D>(scene)),
        obstacles_(scene, split_ ? split_->localSpec() : scene.gridSpec<D>()),
        solver_(split_ ? split_->localSpec() : scene.gridSpec<D>(), liquidParams<D>(scene)) {
    const GridSpec<D> spec = solver_.spec();
    solver_.setDomainSplit(split_.get());
    // Rank 0 writes the obstacles of the whole grid with each frame of a split run.
    if (split_ && split_->root() && !obstacles_.empty()) wholeObstacles_.emplace(scene, scene.gridSpec<D>());
    for (int a = 0; a < D; ++a)
      for (int s = 0; s < 2; ++s)
        if (solver_.params().sides.side[a][s] == numerics::DomainSide::Open)
          logger().warn("{}: 'domain.boundaries.{}' is open: the pressure is 0 there and the liquid flows out through "
                        "it (set it to \"closed\" for a tank wall)",
                        source_, kDomainSideKeys[a][s]);
    if (!obstacles_.empty()) placeObstacles(0.0);
    const json& bodies = scene.resolved.at("initial_liquid");
    if (bodies.empty() && scene.resolved.at("sources").empty())
      throw InputError(fmt::format("{}: 'initial_liquid' and 'sources' are empty: a liquid scene needs a body of "
                                   "liquid or an emitter",
                                   source_));
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      const std::string key = fmt::format("initial_liquid[{}].shape", i);
      const auto shape = sceneShape<D>(scene, bodies[i].at("shape"), key);
      coveredOpenCells<D>(scene, *shape, solver_.solid(), key, split_.get());  // InputError when it holds no open cell
      solver_.addLiquid(shape->distanceField(spec), sceneVector<D>(bodies[i].at("velocity")));
    }
    sources_.emplace(scene, solver_.solid(), volume(), split_.get());
    solver_.setVortexLayer(vortexLayer<D>(scene, "liquid"));
    if (scene.resolved.at("liquid").at("turbulence").at("enabled").get<bool>())
      turbulence_.emplace(solver_.spec(), liquidTurbulenceParams<D>(scene), solver_.params().advection, solver_.phi(),
                          obstacles_.empty() ? nullptr : &solver_.solid());
    preview_ = previewSettings(scene);
    preview_.colour = {0.30f, 0.58f, 0.85f};  // water reads as water in the side views
  }

  // The liquid's CFL step, and a moving obstacle crosses at most cfl cells per step.
  double stableTimestep() const override {
    const double obstacleSpeed = obstacles_.moving() ? obstacles_.maxSpeed(time_) : 0.0;
    const double obstacleStep = obstacleSpeed > 0.0 ? solver_.params().cfl * solver_.spec().dx / obstacleSpeed
                                                    : std::numeric_limits<double>::infinity();
    return std::min(solver_.cflTimestep(), obstacleStep);
  }

  void step(double dt) override {
    double exchanged = 0.0;  // by the emitters and sinks
    exchanged = sources_->apply(solver_, time_);  // timed by the solver: "liquid: sources", "sinks"
    if (obstacles_.moving()) {
      ScopedStage stage(timers_, "liquid: move obstacles");
      placeObstacles(time_ + 0.5 * dt);
    }
    solver_.step(dt);
    // The solver's own stages (surface, advection, pressure, ...) in the run's table.
    timers_.merge(solver_.timers());
    solver_.resetTimers();
    if (turbulence_) {
      ScopedStage stage(timers_, "liquid: turbulence");
      if (obstacles_.moving()) turbulence_->setSolid(solver_.solid());
      turbulence_->step(solver_.velocity(), solver_.phi(), dt);
    }
    time_ += dt;
    ScopedStage stage(timers_, "liquid: volume check");
    const long index = solver_.steps();
    if (!solver_.lastPressureSolve().converged) {
      ++unconverged_;
      logger().warn("liquid: the pressure solve of step {} did not converge ({} iterations, relative residual {:.2g})",
                    index, solver_.lastPressureSolve().iterations, solver_.lastPressureSolve().relativeResidual);
    }
    // Steps in which emitters or sinks changed the liquid are not checked: what they add is counted
    // in cells or particles, which the surface measures with a bias of its own (a small blob).
    const double before = volume_, after = solver_.volume();
    if (exchanged == 0.0 && before > 0.0 && after < 0.9 * before)
      throw SimulationError(fmt::format("liquid: step {} lost {:.1f}% of the liquid's volume ({:.4g} -> {:.4g} m^{}): "
                                        "the flow is too violent for the grid",
                                        index, 100.0 * (1.0 - after / before), before, after, D));
    volume_ = after;
  }

  void checkFinite(long stepIndex, double time) const override {
    // A split run's solver checks every step on every rank together (one rank throwing alone
    // would leave the others waiting).
    if (split_) return;
    requireFinite(solver_.phi(), "liquid phi", stepIndex, time);
    static const char* axes[] = {"velocity x", "velocity y", "velocity z"};
    for (int a = 0; a < D; ++a) requireFinite(solver_.velocity().component(a), axes[a], stepIndex, time);
    if (turbulence_) {
      requireFinite(turbulence_->phi(), "fine liquid phi", stepIndex, time);
      requireFinite(turbulence_->energy().energy(), "turbulent energy", stepIndex, time);
    }
  }

  // A split run's frame on rank 0 (every rank calls this; only rank 0 writes).
  void endFrame() override {
    if (!split_) return;
    ScopedStage stage(timers_, "liquid: gather frame");
    GatheredLiquid<D>& g = gathered_;
    split_->gather(solver_.phi(), g.phi);
    split_->gather(solver_.velocity(), g.velocity);
    g.particles = split_->gatherRows(particleRows());
    // Static solids once, moving ones every frame (decided alike on every rank).
    if (!obstacles_.empty() && (!g.solidGathered || obstacles_.moving())) {
      split_->gather(solver_.solid(), g.solid);
      g.solidGathered = true;
    }
    g.statistics = solver_.statistics();
  }

  // liquid_phi (a level set; with sub-grid turbulence the fine surface, and the simulation's as
  // liquid_sim_phi with the turbulent energy), "vel" at the cell centres in 3D for tools, the face
  // velocities for --resume, the particles (their positions and radii or velocities), the
  // obstacles' distance.
  void writeVolume(io::VdbWriter& writer) const override {
    writer.addLevelSet(kPhi, surface(), 3);
    if (turbulence_) {
      writer.addLevelSet(kSimulationPhi, solver_.phi(), 3);
      writer.addFloatGrid("turbulent_energy", turbulence_->energy().energy());
    }
    if constexpr (D == 3) writer.addVectorGrid("vel", velocity());
    writeFaceVelocities(writer, velocity());
    writer.addPoints(solver_.params().tracker == fluid::InterfaceTracker::Flip ? kFlipParticles : kLevelSetParticles,
                     particleCloud(), solver_.spec().dx);
    if (!obstacles_.empty())
      writer.addLevelSet("obstacle_distance", (wholeObstacles_ ? *wholeObstacles_ : obstacles_).cellDistance(time_));
    if (solver_.vortexLayer())
      writer.addPoints(kVortexPoints, vortexParticleCloud(solver_.vortexLayer()->particles()), solver_.spec().dx);
    // Volume control's state, the same on every process (it works on the summed volume).
    const fluid::VolumeControlState& control = solver_.volumeControl();
    for (const auto& [name, member] : kVolumeControlNumbers) writer.addNumber(name, control.*member);
    writer.addNumber("volume_control_started", control.started ? 1.0 : 0.0);
  }

  // The surface as a triangle mesh (3D): mesh/<name>_NNNN.ply and/or .obj (liquid.mesh_format);
  // the vortex particles with their vorticity: particles/<name>_NNNN.ply.
  void writeFrameData(const std::filesystem::path& runDir, int frame) const override {
    if (solver_.vortexLayer()) {
      const std::filesystem::path dir = runDir / "particles";
      std::filesystem::create_directories(dir);
      io::writePlyPoints(dir / fmt::format("{}_{:04d}.ply", name_, frame),
                         vortexParticleCloud(solver_.vortexLayer()->particles()));
    }
    if constexpr (D == 3) {
      if (meshFormat_ == "none") return;
      const std::filesystem::path dir = runDir / "mesh";
      std::filesystem::create_directories(dir);
      const TriangleMesh mesh = io::levelSetMesh(surface());
      const std::string stem = fmt::format("{}_{:04d}", name_, frame);
      if (meshFormat_ != "obj") io::writePlyMesh(dir / (stem + ".ply"), mesh);
      if (meshFormat_ == "obj" || meshFormat_ == "both") io::writeObj(dir / (stem + ".obj"), mesh);
    }
  }

  io::Image preview() const override {
    const Grid<float, D>& phi = surface();
    const double eps = 1.5 * phi.spec().dx;
    if (!fraction_.sameLayout(phi)) fraction_ = Grid<float, D>(phi.spec());
    parallelFor(0, fraction_.count(), [&](std::size_t i) {
      fraction_[i] = static_cast<float>(numerics::smearedInside(phi[i], eps));
    });
    const Grid<float, D>* solid = turbulence_ ? &turbulence_->fineSolid() : split_ ? &gathered_.solid : &solver_.solid();
    return render::renderDensityPreview(fraction_, preview_, obstacles_.empty() ? nullptr : solid);
  }

  // The resumed run continues from the saved surface, velocity and particles, volume control's
  // state, and the step count (the reseeding keeps its phase). FLIP resumes bit for bit; the
  // marker particles' positions and radii are saved in single precision (kept in double), so a
  // particle level set resumes to round-off.
  void restore(const std::filesystem::path& vdbFile, double time, long steps) override {
    time_ = time;
    if (obstacles_.moving()) placeObstacles(time);
    const io::VdbFile saved(vdbFile, io::VdbProvenance::MsimRun);
    // A split run's ranks each read the whole frame and keep their block of it.
    const BlockPlacement<D> block = split_ ? split_->placement() : BlockPlacement<D>{};
    Grid<float, D> phi(solver_.spec());
    restoreGrid(saved, turbulence_ ? kSimulationPhi : kPhi, phi, source_, block);
    MacGrid<D> velocity(solver_.spec());
    restoreFaceVelocities(saved, velocity, source_, block);
    if (solver_.params().tracker == fluid::InterfaceTracker::Flip) {
      const io::PointCloud cloud = saved.points(kFlipParticles);
      std::vector<Vecf<D>> positions(cloud.positions.size()), velocities(cloud.positions.size());
      const char* names[3] = {"vx", "vy", "vz"};
      for (std::size_t p = 0; p < positions.size(); ++p)
        for (int a = 0; a < D; ++a) positions[p][a] = cloud.positions[p][a];
      for (int a = 0; a < D; ++a) {
        const auto& v = savedPointAttribute(cloud, names[a], vdbFile, source_);
        for (std::size_t p = 0; p < positions.size(); ++p) velocities[p][a] = v[p];
      }
      solver_.flipParticles().assign(std::move(positions), std::move(velocities));
    } else {
      const io::PointCloud cloud = saved.points(kLevelSetParticles);
      const auto& radius = savedPointAttribute(cloud, "radius", vdbFile, source_);
      const auto& sign = savedPointAttribute(cloud, "sign", vdbFile, source_);
      std::vector<Vec<D>> positions(cloud.positions.size());
      std::vector<std::int8_t> signs(sign.size());
      for (std::size_t p = 0; p < positions.size(); ++p) {
        for (int a = 0; a < D; ++a) positions[p][a] = cloud.positions[p][a];
        signs[p] = sign[p] < 0.0f ? -1 : 1;
      }
      solver_.levelSetParticles().assign(std::move(positions), radius, std::move(signs));
    }
    solver_.restore(phi, velocity, steps);  // the reseeding keeps its phase
    fluid::VolumeControlState control;
    for (const auto& [name, member] : kVolumeControlNumbers) control.*member = saved.number(name);
    control.started = saved.number("volume_control_started") != 0.0;
    solver_.restoreVolumeControl(control);
    solver_.setTime(time);
    if (fluid::VortexLayer<D>* layer = solver_.vortexLayer())
      restoreVortexParticles(saved, kVortexPoints, *layer, source_);
    volume_ = volume();
    if (turbulence_) {
      // The fine surface continues from the saved one; the noise particles start afresh.
      Grid<float, D> fine(turbulence_->fineSpec());
      restoreGrid(saved, kPhi, fine, source_);
      turbulence_->restoreSurface(fine, phi);
      restoreGrid(saved, "turbulent_energy", turbulence_->energy().energy(), source_);
      if (obstacles_.moving()) turbulence_->setSolid(solver_.solid());
      turbulence_->reseedParticles();
    }
  }

  json statistics() const override {
    const fluid::LiquidStatistics s = split_ ? gathered_.statistics : solver_.statistics();
    json j = {{"volume_m3", s.volume},
            {"target_volume_m3", s.targetVolume},
            {"volume_control_divergence_1_s", s.controlDivergence},
            {"max_speed_m_s", s.maxSpeed},
            {"kinetic_energy_J", s.kineticEnergy},
            {"pressure_iterations", s.pressureIterations},
            {"pressure_unconverged_steps", unconverged_},
            {"particles", s.particles},
            {"escaped_particles", s.escaped},
            {"enstrophy", s.enstrophy}};
    if (solver_.vortexLayer()) j["vortex_particles"] = s.vortexParticles;
    if (turbulence_) {
      j["fine_volume_m3"] = numerics::enclosedVolume(turbulence_->phi(), &turbulence_->fineSolid());
      j["ripple_height_m"] = turbulence_->meanRippleHeight();
      j["turbulent_energy_integral"] = turbulence_->energy().integral();
      j["noise_particles"] = turbulence_->particles().size();
      j["turbulence_band_fraction"] = turbulence_->bandFraction();
    }
    return j;
  }

 private:
  double volume() const { return solver_.liquidVolume(); }
  // The surface users see: the fine one with sub-grid turbulence; a split run's gathered on rank 0.
  const Grid<float, D>& surface() const {
    return turbulence_ ? turbulence_->phi() : split_ ? gathered_.phi : solver_.phi();
  }
  const MacGrid<D>& velocity() const { return split_ ? gathered_.velocity : solver_.velocity(); }

  // The obstacles where they are at time t, with their velocity when they move.
  void placeObstacles(double t) {
    solver_.setObstacles(obstacles_.nodalDistance(t));
    if (obstacles_.moving()) solver_.setObstacleVelocity(obstacles_.faceVelocity(t));
  }

  // This process's particles as rows (FLIP: position and velocity; the particle level set:
  // position, radius and sign).
  std::vector<double> particleRows() const {
    const auto all = [](const auto&) { return true; };
    return solver_.params().tracker == fluid::InterfaceTracker::Flip ? solver_.flipParticles().rowsIf(all)
                                                                     : solver_.levelSetParticles().rowsIf(all);
  }

  // The particles as points (a split run: those gathered on rank 0) with their radius and sign, or
  // (FLIP) their velocity vx, vy, vz.
  io::PointCloud particleCloud() const {
    const bool flip = solver_.params().tracker == fluid::InterfaceTracker::Flip;
    const std::vector<double> rows = split_ ? gathered_.particles : particleRows();
    const int width = flip ? fluid::FlipParticles<D>::kRowWidth : numerics::ParticleLevelSet<D>::kRowWidth;
    io::PointCloud cloud;
    cloud.positions.reserve(rows.size() / width);
    std::vector<io::PointAttribute> attributes =
        flip ? std::vector<io::PointAttribute>{{"vx", {}}, {"vy", {}}, {"vz", {}}}
             : std::vector<io::PointAttribute>{{"radius", {}}, {"sign", {}}};
    for (std::size_t at = 0; at < rows.size(); at += width) {
      Vecf<3> x = Vecf<3>::Zero();
      for (int a = 0; a < D; ++a) x[a] = static_cast<float>(rows[at + a]);
      cloud.positions.push_back(x);
      for (std::size_t k = 0; k < attributes.size(); ++k)
        attributes[k].values.push_back(flip && int(k) >= D ? 0.0f : static_cast<float>(rows[at + D + k]));
    }
    cloud.attributes = std::move(attributes);
    return cloud;
  }

  std::string source_, name_, meshFormat_;
  StageTimers& timers_;
  std::unique_ptr<DomainSplit<D>> split_;           // null on one process
  GatheredLiquid<D> gathered_;                      // split runs, rank 0: the last frame
  SceneObstacles<D> obstacles_;                     // over the solver's grid (a block when split)
  std::optional<SceneObstacles<D>> wholeObstacles_;  // split runs, rank 0: over the whole grid
  fluid::LiquidSolver<D> solver_;
  render::PreviewSettings preview_;
  mutable Grid<float, D> fraction_;  // the preview's liquid fraction (smeared Heaviside of the surface)
  std::optional<LiquidSources<D>> sources_;
  std::optional<fluid::LiquidTurbulence<D>> turbulence_;
  long unconverged_ = 0;
  double volume_ = 0.0;  // after the last step (0 before the first)
  double time_ = 0.0;    // simulated [s]
};

template <int D>
std::unique_ptr<Phenomenon> createLiquid(const Scene& scene, StageTimers& timers) {
  return std::make_unique<LiquidPhenomenon<D>>(scene, timers);
}

std::unique_ptr<Phenomenon> createLiquidFor(const Scene& scene, StageTimers& timers) {
  return scene.dimensions == 2 ? createLiquid<2>(scene, timers) : createLiquid<3>(scene, timers);
}

}  // namespace

PhenomenonType liquidPhenomenonType() {
  return {"liquid", "water with a free surface: particle level set or FLIP (Selle ch. 4.4.3, Golas ch. 2.7)",
          &declareLiquid, &liquidBytesPerCell, &createLiquidFor, true};
}

}  // namespace msim::scene
