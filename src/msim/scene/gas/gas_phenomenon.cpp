#include "msim/scene/gas/gas_phenomenon.hpp"

#include <cmath>
#include <limits>
#include <optional>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/scene/keys/json_vectors.hpp"
#include "msim/core/parallel.hpp"
#include "msim/fluid/gas/gas_solver.hpp"
#include "msim/geometry/occupancy.hpp"
#include "msim/io/vdb.hpp"
#include "msim/scene/phenomenon_support.hpp"
#include "msim/scene/scene_file.hpp"
#include "msim/scene/schema/shape_schema.hpp"
#include "msim/scene/keys/turbulent_wind_keys.hpp"
#include "msim/scene/reports/turbulent_wind_report.hpp"

namespace msim::scene {

namespace {

using nlohmann::json;

void declareGas(Schema& root) {
  Schema gas = Schema::object("density and temperature of the gas (Stam ch. 6.4.1)");
  Schema density = Schema::object("d(rho)/dt + u.grad(rho) = kappa lap(rho) - alpha rho + S");
  density.number("diffusion", "m^2/s", 0.0, "kappa_rho: sub-grid turbulent diffusion").min(0.0);
  density.number("dissipation", "1/s", 0.0, "alpha_rho: fraction of the gas lost per second").min(0.0);
  gas.field("density", density);
  Schema temperature = Schema::object("dT/dt + u.grad(T) = kappa_T lap(T) - alpha_T (T - T_ambient) + S_T");
  temperature.number("ambient", "K", 293.15, "temperature of the surrounding air").min(0.0, Bound::Exclusive);
  temperature.number("diffusion", "m^2/s", 0.0, "kappa_T: thermal diffusivity").min(0.0);
  temperature.number("cooling", "1/s", 0.0, "alpha_T: relaxation rate towards ambient").min(0.0);
  gas.field("temperature", temperature);
  root.field("gas", gas);

  Schema field = Schema::object("one instance of a motion-field primitive (Stam ch. 6.3.1)");
  field.string("type", "uniform", "primitive").choices(fluid::motionPrimitiveNames());
  field.number("magnitude", "m/s", 1.0, "speed scale; circulation [m^2/s] for vortices; negative reverses");
  field.vector("position", "m", {0.0, 0.0, 0.0}, "instance origin").lengths({2, 3});
  field.vector("axis", "", {0.0, 0.0, 1.0}, "world direction of the primitive's local +z").lengths({2, 3});
  field.vector("scale", "m", {1.0, 1.0, 1.0}, "size of one local unit along local x, y, z").min(0.0, Bound::Exclusive);
  field.number("half_distance", "", 0.0, "decay W(d) = 2^(-d/half_distance) in local units; 0 = no decay").min(0.0);
  field.number("ring_radius", "", 1.0, "ring vortex radius R, local units").min(0.0, Bound::Exclusive);
  field.number("core_radius", "", 0.05, "vortex core radius, local units (smooths the axis)").min(0.0);
  field.number("edge_softness", "", 0.0, "directional: fraction of the half-width fading to zero; 0 = hard edge")
      .min(0.0)
      .max(1.0);
  root.array("motion_fields", field, "summed to give the velocity u(x) (eq. 6.1)");
  declareTurbulentWinds(root);

  Schema source = Schema::object("a region emitting gas");
  source.field("shape", shapeSchema());
  source.number("density_rate", "kg/(m^3 s)", 1.0, "S_rho in a fully covered cell").min(0.0);
  source.number("temperature", "K", 373.15, "temperature of the emitted gas").min(0.0, Bound::Exclusive);
  root.array("sources", source, "gas emitters");

  Schema obstacle = Schema::object("a solid the gas cannot enter");
  obstacle.field("shape", shapeSchema());
  root.array("obstacles", obstacle, "static solids");
}

double gasBytesPerCell(int dimensions, const json& /*resolved*/) {
  // density, temperature, solid, RK stage, rate, net outflow (6 floats) + velocity, flux and
  // open-face velocity (3 x D floats) + the preview's light buffer and the VDB copies of two
  // fields (~3 floats).
  return 4.0 * (6 + 3 * dimensions + 3);
}

fluid::MotionField motionField(const json& fields) {
  std::vector<fluid::MotionFieldInstance> instances;
  for (const json& f : fields) {
    fluid::MotionFieldInstance m;
    m.type = fluid::parseMotionPrimitive(f.at("type").get<std::string>());
    m.magnitude = f.at("magnitude").get<double>();
    m.position = paddedVec3(f.at("position"));
    m.axis = paddedVec3(f.at("axis"));
    m.scale = paddedVec3(f.at("scale"), 1.0);
    m.halfDistance = f.at("half_distance").get<double>();
    m.ringRadius = f.at("ring_radius").get<double>();
    m.coreRadius = f.at("core_radius").get<double>();
    m.edgeSoftness = f.at("edge_softness").get<double>();
    instances.push_back(m);
  }
  return fluid::MotionField(std::move(instances));
}

template <int D>
numerics::TransportBoundaries<D> boundaries(const json& resolved) {
  numerics::TransportBoundaries<D> b;
  const auto open = openDomainSides<D>(resolved);
  for (int a = 0; a < D; ++a)
    for (int s = 0; s < 2; ++s) b.side[a][s] = open[a][s] ? numerics::BoundaryKind::Open : numerics::BoundaryKind::Closed;
  return b;
}

template <int D>
class GasPhenomenon final : public Phenomenon {
 public:
  GasPhenomenon(const Scene& scene, StageTimers& timers)
      : source_(scene.file.string()),
        timers_(timers),
        solver_(scene.gridSpec<D>(), params(scene.resolved), motionField(scene.resolved.at("motion_fields")),
                boundaries<D>(scene.resolved)) {
    const json& r = scene.resolved;
    const GridSpec<D> spec = scene.gridSpec<D>();
    Grid<float, D> solid(spec, 0.0f);
    const json& obstacles = r.at("obstacles");
    for (std::size_t i = 0; i < obstacles.size(); ++i) {
      const std::string key = fmt::format("obstacles[{}].shape", i);
      const auto shape = sceneShape<D>(scene, obstacles[i].at("shape"), key);
      const Grid<float, D> cover = geometry::occupancy(*shape, spec);
      // The signed distance goes into every frame so renderers can draw the obstacles.
      const Grid<float, D> distance = shape->distanceField(spec);
      if (!obstacleDistance_) obstacleDistance_.emplace(spec, std::numeric_limits<float>::max());
      for (std::size_t c = 0; c < distance.count(); ++c)
        (*obstacleDistance_)[c] = std::min((*obstacleDistance_)[c], distance[c]);
      std::size_t inside = 0;
      for (std::size_t c = 0; c < cover.count(); ++c)
        if (cover[c] > 0.5f) solid[c] = 1.0f, ++inside;
      if (inside == 0) throw InputError(fmt::format("{}: '{}' covers no cell of the domain", source_, key));
    }
    solver_.setSolid(solid);

    const json& sources = r.at("sources");
    for (std::size_t i = 0; i < sources.size(); ++i) {
      const std::string key = fmt::format("sources[{}].shape", i);
      fluid::GasSource s;
      s.densityRate = sources[i].at("density_rate").get<double>();
      s.temperature = sources[i].at("temperature").get<double>();
      s.cells = coveredOpenCells<D>(scene, *sceneShape<D>(scene, sources[i].at("shape"), key), solid, key);
      solver_.addSource(std::move(s));
    }
    // Turbulence on top of the smooth fields (Stam ch. 6.3.2: the plain sum of eq. 6.1).
    for (auto& wind : turbulentWinds<D>(scene)) solver_.addWind(std::move(wind));
    preview_ = previewSettings(scene);
  }

  double stableTimestep() const override { return solver_.stableTimestep(); }

  void step(double dt) override {
    solver_.step(dt);
    // The solver's stages (emit, transport, decay, winds) in the run's table.
    timers_.merge(solver_.timers(), "gas: ");
    solver_.resetTimers();
  }

  void checkFinite(long stepIndex, double time) const override {
    requireFinite(solver_.density(), "density", stepIndex, time);
    requireFinite(solver_.temperature(), "temperature", stepIndex, time);
  }

  void writeVolume(io::VdbWriter& writer) const override {
    writer.addFogVolume("density", solver_.density());
    writer.addFloatGrid("temperature", solver_.temperature());
    if (obstacleDistance_) writer.addLevelSet("obstacle_distance", *obstacleDistance_);
  }

  io::Image preview() const override {
    return render::renderDensityPreview(solver_.density(), preview_, &solver_.solid());
  }

  // The motion fields are steady and the winds a function of time, so the state is the two grids
  // and the clock.
  void restore(const std::filesystem::path& vdbFile, double time, long /*steps*/) override {
    const io::VdbFile saved(vdbFile, io::VdbProvenance::MsimRun);
    solver_.setTime(time);
    restoreGrid(saved, "density", solver_.density(), source_);
    restoreGrid(saved, "temperature", solver_.temperature(), source_);
  }

  // Each wind's spectrum against the prescribed one (winds/), and its measures in run.json.
  json finishRun(const std::filesystem::path& runDir, const json& /*frames*/) override {
    return writeWindReports<D>(solver_.winds(), runDir);
  }

  json statistics() const override {
    const fluid::GasStatistics s = solver_.statistics();
    return {{"mass_kg", s.mass},
            {"max_density", s.maxDensity},
            {"max_temperature_K", s.maxTemperature},
            {"mean_temperature_K", s.meanTemperature},
            {"centroid_x", s.centroid.x()},
            {"centroid_y", s.centroid.y()},
            {"centroid_z", s.centroid.z()}};
  }

 private:
  static fluid::GasParams params(const json& r) {
    fluid::GasParams p;
    const json& g = r.at("gas");
    p.densityDiffusion = g.at("density").at("diffusion").get<double>();
    p.densityDissipation = g.at("density").at("dissipation").get<double>();
    p.ambientTemperature = g.at("temperature").at("ambient").get<double>();
    p.temperatureDiffusion = g.at("temperature").at("diffusion").get<double>();
    p.cooling = g.at("temperature").at("cooling").get<double>();
    p.cfl = r.at("time").at("cfl").get<double>();
    return p;
  }

  std::string source_;
  StageTimers& timers_;
  fluid::GasSolver<D> solver_;
  std::optional<Grid<float, D>> obstacleDistance_;  // signed distance of the obstacles [m], if any
  render::PreviewSettings preview_;
};

template <int D>
std::unique_ptr<Phenomenon> createGas(const Scene& scene, StageTimers& timers) {
  return std::make_unique<GasPhenomenon<D>>(scene, timers);
}

std::unique_ptr<Phenomenon> createGasFor(const Scene& scene, StageTimers& timers) {
  return scene.dimensions == 2 ? createGas<2>(scene, timers) : createGas<3>(scene, timers);
}

}  // namespace

PhenomenonType gasPhenomenonType() {
  return {"gas", "density and temperature carried by analytic motion fields (Stam ch. 6.3-6.4)", &declareGas,
          &gasBytesPerCell, &createGasFor};
}

}  // namespace msim::scene
