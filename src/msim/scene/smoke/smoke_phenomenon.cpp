#include "msim/scene/smoke/smoke_phenomenon.hpp"

#include <cmath>
#include <filesystem>
#include <numbers>
#include <optional>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/core/parallel.hpp"
#include "msim/fluid/smoke/combustion.hpp"
#include "msim/fluid/smoke/smoke_solver.hpp"
#include "msim/io/ply.hpp"
#include "msim/io/vdb.hpp"
#include "msim/parallel/ghost_layers.hpp"
#include "msim/parallel/mpi_session.hpp"
#include "msim/render/density_preview.hpp"
#include "msim/scene/keys/json_vectors.hpp"
#include "msim/scene/keys/mpi_split_keys.hpp"
#include "msim/scene/phenomenon_support.hpp"
#include "msim/scene/scene_file.hpp"
#include "msim/scene/keys/scene_obstacles.hpp"
#include "msim/scene/smoke/smoke_scene_keys.hpp"
#include "msim/scene/keys/vortex_particle_keys.hpp"
#include "msim/scene/keys/turbulent_wind_keys.hpp"
#include "msim/scene/reports/turbulent_wind_report.hpp"

namespace msim::scene {

namespace {

using nlohmann::json;

double smokeBytesPerCell(int dimensions, const json& resolved) {
  // Measured growth of the peak RSS with the cell count (docs/PERFORMANCE.md): 346 B/cell in 3D
  // (plume_3d at 118k and 1.83M cells), 353 B/cell in 2D. It covers the solver state and scratch
  // (velocity, scalars, advection stages and traced feet, projection matrix, PCG and multigrid
  // vectors, confinement), the fire fields and the VDB and preview copies at frame time.
  double bytes = 360.0;
  // Sub-grid turbulence keeps the smoke on refinement^D fine cells per cell: their scalars, u' on
  // the faces, the potential and its weights at the nodes, the VDB copies, and in the advection
  // window (at most the whole fine grid) copies of the scalars and U + u' with the advector's
  // stages and feet: 133 bytes per fine cell when the window is the whole grid (smoke_turbulence
  // at 1 s, window about a third: peak RSS 1.12 GB for 16.8M fine cells).
  const json& t = resolved.at("smoke").at("turbulence");
  if (t.at("enabled").get<bool>())
    bytes += std::pow(t.at("refinement").get<double>(), dimensions) * 133.0;
  return bytes;
}

// Under mpirun with several processes the grid is split among them (msim/parallel): each runs
// the solver on its block, and rank 0 gathers the fields at the end of every frame and writes
// them. What is not distributed yet is refused here, naming the key.
template <int D>
std::unique_ptr<DomainSplit<D>> smokeSplit(const Scene& scene) {
  if (parallel::worldSize() == 1) return nullptr;
  const json& smoke = scene.resolved.at("smoke");
  if constexpr (D != 3) {
    refuseSplit(scene, "domain.resolution", "a 2D grid");
  } else {
    if (smoke.at("turbulence").at("enabled").get<bool>()) refuseSplit(scene, "smoke.turbulence.enabled", "sub-grid turbulence");
    const fluid::SmokeParams<3> p = smokeParams<3>(scene);
    // Enough ghost layers for the scheme at the solver's CFL number (and blocks at least that thick).
    const bool conservative = p.scalarTransport == fluid::ScalarTransport::Conservative;
    const int needed = parallel::smokeGhostLayers(p.advection, std::max(1.0, p.cfl), conservative);
    const std::string reads = fmt::format("this smoke (its advection at CFL {:g}, vorticity confinement{})", p.cfl,
                                          conservative ? " and the conservative scalar transport" : "");
    return sceneDomainSplit(scene, needed, reads, p.sides, p.projection.pcg);
  }
}

// The fields of a split run put together on rank 0 for its outputs.
template <int D>
struct GatheredSmoke {
  Grid<float, D> density, temperature, pressure;
  MacGrid<D> velocity;
  std::vector<Grid<float, D>> scalars;
  Grid<float, D> solid;    // with obstacles: gathered once (they do not move)
  MacGrid<D> faceWeights;  // the projection's face weights, likewise
  bool solidsGathered = false;
};

template <int D>
class SmokePhenomenon final : public Phenomenon {
 public:
  SmokePhenomenon(const Scene& scene, StageTimers& timers)
      : source_(scene.file.string()),
        name_(scene.name()),
        timers_(timers),
        split_(smokeSplit<D>(scene)),
        obstacles_(scene, split_ ? split_->localSpec() : scene.gridSpec<D>()),
        solver_(split_ ? split_->localSpec() : scene.gridSpec<D>(), smokeParams<D>(scene)),
        timeCfl_(scene.resolved.at("time").at("cfl").get<double>()) {
    const json& r = scene.resolved;
    for (const auto& axis : solver_.params().wallVelocity)
      for (const auto& wall : axis) boundarySpeed_ = std::max(boundarySpeed_, wall.norm());
    const Vec<D> u0 = sceneVector<D>(r.at("smoke").at("initial_velocity"));
    for (int a = 0; a < D; ++a) solver_.velocity().component(a).fill(static_cast<float>(u0[a]));
    // A split run's solver knows its block before the vortex particles seed (with the local flow's
    // vorticity they read it on the owning ranks) and the obstacles are placed.
    if (split_) solver_.setDomainSplit(split_.get());
    // Vortex particles before the obstacles, which the solver hands them.
    solver_.setVortexLayer(vortexLayer<D>(scene, "smoke"));
    if (!obstacles_.empty()) placeObstacles(0.0);
    // Rank 0 writes the obstacles of the whole grid with each frame of a split run.
    if (split_ && split_->root() && !obstacles_.empty()) wholeObstacles_.emplace(scene, scene.gridSpec<D>());

    if (r.at("fire").at("enabled").get<bool>()) {
      combustion_ = combustionParams(r);
      fuel_ = solver_.addScalar("fuel", r.at("fire").at("fuel_dissipation").get<double>());
      flame_ = solver_.addScalar("flame");
    }
    if (r.at("smoke").at("turbulence").at("enabled").get<bool>()) enableTurbulence(scene);
    addSources(scene);
    for (auto& wind : turbulentWinds<D>(scene)) solver_.addWind(std::move(wind));
    preview_ = previewSettings(scene);
    preview_.emissionScale = r.at("fire").at("emission").get<double>();
  }

  double stableTimestep() const override {
    // Bridson's bound: the fastest face plus the speed forces can add within one step,
    // dt (u_max + sqrt(dx a_max)) <= cfl dx, so a plume starting from rest is not overshot.
    const auto& p = solver_.params();
    const double dx = solver_.spec().dx;
    const double cflDt = solver_.cflTimestep();
    double speed = std::isfinite(cflDt) ? p.cfl * dx / cflDt : 0.0;
    speed = std::max({speed, boundarySpeed_, obstacles_.maxSpeed(time_), solver_.maxWindSpeed()});
    const double hottest = overRanks(maxValue(solver_.temperature())) - p.buoyancy.ambientTemperature;
    const double accel =
        p.buoyancy.beta * std::max(hottest, 0.0) + p.buoyancy.alpha * overRanks(maxValue(solver_.density()));
    speed += std::sqrt(dx * accel);
    return speed > 0.0 ? timeCfl_ * p.cfl * dx / speed : std::numeric_limits<double>::infinity();
  }

  void step(double dt) override {
    for (std::size_t i = 0; i < windows_.size(); ++i) {
      const bool active = time_ >= windows_[i].first && (windows_[i].second <= 0.0 || time_ < windows_[i].second);
      solver_.source(i).active = active;
      if (turbulence_) turbulence_->source(i).active = active;
    }
    if (turbulence_) {
      // The smoke and heat of the sources go into the fine grid; the step's buoyancy sees them.
      ScopedStage stage(timers_, "smoke: turbulence");
      turbulence_->applySources(dt, solver_.density(), solver_.temperature());
    }
    if (obstacles_.moving()) {
      ScopedStage stage(timers_, "smoke: move obstacles");
      placeObstacles(time_ + 0.5 * dt);
    }
    try {
      solver_.step(dt);
    } catch (const SimulationError& e) {
      throw SimulationError(fmt::format("t = {:.4g} s: {}", time_, e.what()));
    }
    // The solver's own stages (advection, forces, projection, ...) in the run's table.
    timers_.merge(solver_.timers(), "smoke: ");
    solver_.resetTimers();
    if (turbulence_) {
      // Sub-grid turbulence, and the fine scalars carried by the new velocity plus the eddies
      // (ch. 3.5.2), as the solver carries its own scalars after its projection.
      ScopedStage stage(timers_, "smoke: turbulence");
      turbulence_->step(solver_.velocity(), dt, solver_.density(), solver_.temperature());
    }
    if (combustion_) {
      ScopedStage stage(timers_, "fire: reactions");
      const Grid<float, D>* solid = obstacles_.empty() ? nullptr : &solver_.solid();
      fluid::react<D>(*combustion_, dt, solver_.scalar(fuel_), solver_.scalar(flame_), solver_.density(),
                      solver_.temperature(), solid);
    }
    time_ += dt;
  }

  void checkFinite(long stepIndex, double time) const override {
    // A split run's solver checks every step on every rank together (one rank throwing alone
    // would leave the others waiting).
    if (split_) return;
    static const char* axes[] = {"velocity x", "velocity y", "velocity z"};
    for (int a = 0; a < D; ++a) requireFinite(solver_.velocity().component(a), axes[a], stepIndex, time);
    requireFinite(solver_.density(), "density", stepIndex, time);
    requireFinite(solver_.temperature(), "temperature", stepIndex, time);
    if (turbulence_) {
      requireFinite(turbulence_->density(), "fine density", stepIndex, time);
      requireFinite(turbulence_->energy().energy(), "turbulent energy", stepIndex, time);
    }
    for (std::size_t i = 0; i < solver_.scalarCount(); ++i)
      requireFinite(solver_.scalar(i), solver_.scalarName(i), stepIndex, time);
  }

  // density, temperature (and fuel, flame) for users; "vel" at cell centres in 3D for tools; the
  // face velocities vel_face_x.. and the pressure (the next solve's warm start) make --resume exact;
  // "obstacle_distance" (signed, at cell centres) lets renderers draw the obstacles.
  // A split run's fields on rank 0 (every rank calls this; only rank 0 writes).
  void endFrame() override {
    if (!split_) return;
    ScopedStage stage(timers_, "smoke: gather frame");
    GatheredSmoke<D>& g = gathered_;
    split_->gather(solver_.density(), g.density);
    split_->gather(solver_.temperature(), g.temperature);
    split_->gather(solver_.pressure(), g.pressure);
    split_->gather(solver_.velocity(), g.velocity);
    g.scalars.resize(solver_.scalarCount());
    for (std::size_t i = 0; i < solver_.scalarCount(); ++i) split_->gather(solver_.scalar(i), g.scalars[i]);
    // Static solids once, moving ones every frame (decided alike on every rank).
    if (!obstacles_.empty() && (!g.solidsGathered || obstacles_.moving())) {
      split_->gather(solver_.solid(), g.solid);
      split_->gather(solver_.projection().faceWeights(), g.faceWeights);
      g.solidsGathered = true;
    }
  }

  void writeVolume(io::VdbWriter& writer) const override {
    // With turbulence the smoke lives on the fine grid; the coarse scalars are its averages.
    writer.addFogVolume("density", turbulence_ ? turbulence_->density() : density());
    writer.addFloatGrid("temperature", turbulence_ ? turbulence_->temperature() : temperature());
    if (turbulence_) writer.addFloatGrid("turbulent_energy", turbulence_->energy().energy());
    for (std::size_t i = 0; i < solver_.scalarCount(); ++i) writer.addFogVolume(solver_.scalarName(i), scalar(i));
    if constexpr (D == 3) {
      if (turbulence_ && turbulence_->params().writeVelocity)
        writer.addVectorGrid("vel", turbulence_->fineVelocity(solver_.velocity()));
      else
        writer.addVectorGrid("vel", velocity());
    }
    writeFaceVelocities(writer, velocity());
    writer.addFloatGrid("pressure", split_ ? gathered_.pressure : solver_.pressure());
    if (!obstacles_.empty())
      writer.addLevelSet("obstacle_distance", (wholeObstacles_ ? *wholeObstacles_ : obstacles_).cellDistance(time_));
    if (solver_.vortexLayer())
      writer.addPoints(kVortexPoints, vortexParticleCloud(solver_.vortexLayer()->particles()), solver_.spec().dx);
  }

  // particles/<name>_NNNN.ply: the vortex particles with their vorticity (wx, wy, wz).
  void writeFrameData(const std::filesystem::path& runDir, int frame) const override {
    if (!solver_.vortexLayer()) return;
    const std::filesystem::path dir = runDir / "particles";
    std::filesystem::create_directories(dir);
    io::writePlyPoints(dir / fmt::format("{}_{:04d}.ply", name_, frame),
                       vortexParticleCloud(solver_.vortexLayer()->particles()));
  }

  io::Image preview() const override {
    if (turbulence_)
      return render::renderDensityPreview(turbulence_->density(), preview_,
                                          obstacles_.empty() ? nullptr : &turbulence_->fineSolid());
    const Grid<float, D>* solid = obstacles_.empty() ? nullptr : (split_ ? &gathered_.solid : &solver_.solid());
    render::PreviewEmission<D> emission;
    if (combustion_) emission = {&scalar(flame_), &temperature()};
    return render::renderDensityPreview(density(), preview_, solid, emission);
  }

  void restore(const std::filesystem::path& vdbFile, double time, long /*steps*/) override {
    const io::VdbFile saved(vdbFile, io::VdbProvenance::MsimRun);
    // A split run's ranks each read the whole frame and keep their block of it.
    const BlockPlacement<D> block = split_ ? split_->placement() : BlockPlacement<D>{};
    time_ = time;
    solver_.setTime(time);
    if (obstacles_.moving()) placeObstacles(time_);
    if (turbulence_) {
      // The noise particles are not saved: they start afresh (the resumed run is not bit-exact).
      restoreGrid(saved, "density", turbulence_->density(), source_);
      restoreGrid(saved, "temperature", turbulence_->temperature(), source_);
      restoreGrid(saved, "turbulent_energy", turbulence_->energy().energy(), source_);
      turbulence_->downsample(solver_.density(), solver_.temperature());
      turbulence_->reseedParticles();
    } else {
      restoreGrid(saved, "density", solver_.density(), source_, block);
      restoreGrid(saved, "temperature", solver_.temperature(), source_, block);
    }
    for (std::size_t i = 0; i < solver_.scalarCount(); ++i)
      restoreGrid(saved, solver_.scalarName(i), solver_.scalar(i), source_, block);
    restoreFaceVelocities(saved, solver_.velocity(), source_, block);
    restoreGrid(saved, "pressure", solver_.pressure(), source_, block);
    if (fluid::VortexLayer<D>* layer = solver_.vortexLayer())
      restoreVortexParticles(saved, kVortexPoints, *layer, source_);
  }

  // Each wind's spectrum against the prescribed one (winds/), and its measures in run.json.
  json finishRun(const std::filesystem::path& runDir, const json& /*frames*/) override {
    return writeWindReports<D>(solver_.winds(), runDir);
  }

  json statistics() const override {
    fluid::SmokeStatistics s = split_ ? solver_.counters() : solver_.statistics();
    if (split_) {  // measured on the gathered fields; the solver's own counts are already reduced
      const bool solids = !obstacles_.empty();
      fluid::measureSmoke<D>(gathered_.velocity, solids ? &gathered_.faceWeights : nullptr, gathered_.density,
                             solids ? &gathered_.solid : nullptr, solver_.params().fluidDensity, s);
    }
    json j = {{"smoke_mass_kg", s.totalDensity},
              {"kinetic_energy_J", s.kineticEnergy},
              {"max_speed_m_s", s.maxSpeed},
              {"max_divergence_1_s", s.maxDivergence},
              {"pressure_iterations", s.pressureIterations},
              {"max_temperature_K", maxValue(temperature())}};
    if (turbulence_) {
      j["turbulent_energy_integral"] = turbulence_->energy().integral();
      j["turbulent_kinetic_energy"] = turbulence_->turbulentKineticEnergy();
      j["noise_particles"] = turbulence_->particles().size();
      j["turbulence_band_fraction"] = turbulence_->bandFraction();
      j["fine_smoke_mass_kg"] = turbulence_->fineSpec().cellVolume() * total(turbulence_->density());
    }
    j["enstrophy"] = s.enstrophy;
    if (solver_.vortexLayer()) j["vortex_particles"] = s.vortexParticles;
    if (combustion_) {
      const double dV = solver_.spec().cellVolume();
      j["fuel_kg"] = dV * total(scalar(fuel_));
      j["flame_kg"] = dV * total(scalar(flame_));
    }
    return j;
  }

 private:
  static double maxValue(const Grid<float, D>& g) {
    return parallelMax(g.count(), [&](std::size_t i) { return double(g[i]); });
  }
  static double total(const Grid<float, D>& g) {
    return parallelSum(g.count(), [&](std::size_t i) { return double(g[i]); });
  }
  double overRanks(double value) const { return split_ ? split_->maxOverRanks(value) : value; }
  // The fields the outputs show: the solver's, or in a split run those gathered on rank 0.
  const Grid<float, D>& density() const { return split_ ? gathered_.density : solver_.density(); }
  const Grid<float, D>& temperature() const { return split_ ? gathered_.temperature : solver_.temperature(); }
  const MacGrid<D>& velocity() const { return split_ ? gathered_.velocity : solver_.velocity(); }
  const Grid<float, D>& scalar(std::size_t i) const { return split_ ? gathered_.scalars[i] : solver_.scalar(i); }

  static constexpr const char* kVortexPoints = "vortex_particles";

  void placeObstacles(double time) {
    solver_.setObstacles(obstacles_.nodalDistance(time));
    if (obstacles_.moving()) solver_.setObstacleVelocity(obstacles_.faceVelocity(time));
    if (turbulence_) turbulence_->setSolid(solver_.solid());
  }

  void enableTurbulence(const Scene& scene) {
    const json& r = scene.resolved;
    if (combustion_)
      throw InputError(fmt::format("{}: 'smoke.turbulence.enabled' with 'fire.enabled' is not supported yet (the fuel "
                                   "and flame stay on the simulation grid)",
                                   source_));
    if (solver_.params().scalarTransport == fluid::ScalarTransport::Conservative)
      throw InputError(fmt::format("{}: 'smoke.advection.scalars' = 'conservative' with 'smoke.turbulence.enabled' is "
                                   "not supported (the smoke lives on the fine grid, moved by the advection scheme)",
                                   source_));
    turbulence_ = std::make_unique<fluid::SmokeTurbulence<D>>(
        solver_.spec(), smokeTurbulenceParams(r), solver_.params().advection,
        obstacles_.empty() ? nullptr : &solver_.solid(), solver_.params().buoyancy.ambientTemperature);
    if (turbulence_->params().coupling) solver_.setAdvectionOffset(&turbulence_->coarseTurbulentVelocity());
    solver_.setScalarsCarriedElsewhere(true);
  }

  void addSources(const Scene& scene) {
    const json& list = scene.resolved.at("sources");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const json& s = list[i];
      const std::string key = fmt::format("sources[{}]", i);
      fluid::SmokeSource<D> src;
      const auto shape = sceneShape<D>(scene, s.at("shape"), key + ".shape");
      // A split run's source may lie in other ranks' blocks: it must cover some cell of one.
      src.cells = coveredOpenCells<D>(scene, *shape, solver_.solid(), key + ".shape", split_.get());
      src.mode = s.at("mode") == "set" ? fluid::SmokeSource<D>::Mode::Set : fluid::SmokeSource<D>::Mode::Add;
      src.density = s.at("density").get<double>();
      src.temperature = s.at("temperature").get<double>();
      src.expansion = s.at("expansion").get<double>();
      if (src.expansion != 0.0) {
        // A ball of volume V expanding at div u = c pushes its surface out at c R / D.
        double volume = 0.0;
        for (const auto& cell : src.cells) volume += cell.second * solver_.spec().cellVolume();
        const double radius = D == 3 ? std::cbrt(3.0 * volume / (4.0 * std::numbers::pi)) : std::sqrt(volume / std::numbers::pi);
        boundarySpeed_ = std::max(boundarySpeed_, std::abs(src.expansion) * radius / D);
      }
      const double fuel = s.at("fuel").get<double>();
      if (fuel > 0.0) {
        if (!combustion_)
          throw InputError(fmt::format("{}: '{}.fuel' is {} but 'fire.enabled' is false; nothing would burn it",
                                       source_, key, fuel));
        src.scalars.emplace_back(fuel_, fuel);
      }
      if (s.at("inflow").get<bool>()) {
        src.velocity = sceneVector<D>(s.at("velocity"));
        boundarySpeed_ = std::max(boundarySpeed_, src.velocity->norm());
      }
      const double start = s.at("start").get<double>(), stop = s.at("stop").get<double>();
      if (stop > 0.0 && stop <= start)
        throw InputError(fmt::format("{}: '{}.stop' ({} s) must come after '{}.start' ({} s), or be 0 for 'to the end'",
                                     source_, key, stop, key, start));
      windows_.emplace_back(start, stop);
      if (turbulence_) {
        // The smoke and heat go into the fine grid; the simulated flow keeps only the inflow.
        fluid::SmokeSource<D> fine = src;
        fine.cells = coveredOpenCells<D>(scene, *shape, turbulence_->fineSolid(), key + ".shape");
        fine.velocity.reset();
        fine.scalars.clear();  // fuel cannot be set here: fire with turbulence is refused
        turbulence_->addSource(std::move(fine));
        src.mode = fluid::SmokeSource<D>::Mode::Add;
        src.density = 0.0;
        src.temperature = 0.0;
      }
      solver_.addSource(std::move(src));
    }
  }

  std::string source_, name_;
  StageTimers& timers_;
  std::unique_ptr<DomainSplit<D>> split_;  // null on one process
  GatheredSmoke<D> gathered_;              // split runs, rank 0: the last frame's fields
  SceneObstacles<D> obstacles_;                        // over the solver's grid (a block when split)
  std::optional<SceneObstacles<D>> wholeObstacles_;     // split runs, rank 0: over the whole grid
  fluid::SmokeSolver<D> solver_;
  double timeCfl_;
  double time_ = 0.0;
  double boundarySpeed_ = 0.0;  // fastest wall, source inflow or expansion: the flow will reach it [m/s]
  std::vector<std::pair<double, double>> windows_;  // (start, stop) of each source [s]
  std::optional<fluid::CombustionParams> combustion_;
  std::size_t fuel_ = 0, flame_ = 0;
  std::unique_ptr<fluid::SmokeTurbulence<D>> turbulence_;
  render::PreviewSettings preview_;
};

std::unique_ptr<Phenomenon> createSmoke(const Scene& scene, StageTimers& timers) {
  if (scene.dimensions == 2) return std::make_unique<SmokePhenomenon<2>>(scene, timers);
  return std::make_unique<SmokePhenomenon<3>>(scene, timers);
}

}  // namespace

PhenomenonType smokePhenomenonType() {
  return {"smoke",
          "incompressible smoke and fire on a MAC grid: high-order advection, pressure projection, buoyancy, "
          "vorticity confinement, combustion (Selle ch. 2-3, Stam ch. 6.4)",
          &declareSmokeKeys, &smokeBytesPerCell, &createSmoke, true};
}

}  // namespace msim::scene
