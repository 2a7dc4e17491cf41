#include "msim/scene/granular/granular_phenomenon.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/core/parallel.hpp"
#include "msim/scene/granular/granular_outputs.hpp"
#include "msim/scene/granular/granular_preview.hpp"
#include "msim/scene/granular/granular_scene_keys.hpp"
#include "msim/scene/phenomenon_support.hpp"
#include "msim/scene/runner.hpp"
#include "msim/scene/scene_file.hpp"
#include "msim/scene/reports/turbulent_wind_report.hpp"

namespace msim::scene {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class GranularPhenomenon final : public Phenomenon {
 public:
  GranularPhenomenon(const Scene& scene, StageTimers& timers)
      : source_(scene.file.string()),
        name_(scene.name()),
        timers_(timers),
        setup_(buildGranularScene(scene)),
        sim_(*setup_.sim),
        cfl_(scene.resolved.at("time").at("cfl").get<double>()),
        preview_(sim_.settings().grid, previewSettings(scene), setup_.solids) {
    fired_.assign(setup_.explosions.size(), false);
  }

  double stableTimestep() const override { return cfl_ * sim_.stableTimestep(setup_.maxStep); }

  void step(double dt) override {
    explode(time_ + dt);
    try {
      sim_.step(dt);
    } catch (const std::runtime_error& e) {
      throw SimulationError(fmt::format("{}: {}", source_, e.what()));
    }
    time_ += dt;
    const granular::GranularStepTimes& t = sim_.lastStepTimes();
    timers_.add("granular: transfer", t.transfer);
    timers_.add("granular: density correction", t.correction);
    timers_.add("granular: stress assembly", t.assembly);
    timers_.add("granular: pressure", t.pressure);
    timers_.add("granular: friction", t.friction);
    timers_.add("granular: bodies", t.bodies);
    timers_.add("granular: particles", t.particles);
    timers_.add("granular: other", t.other);
    frame_.steps += 1;
    frame_.transfer += t.transfer + t.correction;
    frame_.assembly += t.assembly;
    frame_.pressure += t.pressure;
    frame_.friction += t.friction;
    frame_.particles += t.particles + t.bodies;
    frame_.step += t.step;
    const granular::StressSolverStats& s = sim_.stress().stats();
    frame_.pressureIterations += s.pressureIterations;
    frame_.frictionIterations += s.frictionIterations;
    frame_.correctionIterations += s.correctionIterations;
  }

  void endFrame() override {
    last_ = frame_;
    frame_ = {};
  }

  void checkFinite(long stepIndex, double time) const override {
    const granular::GranularParticles& p = sim_.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (!p.position[i].allFinite() || !p.velocity[i].allFinite())
        throw SimulationError(fmt::format("step {} (t = {:.4g} s): particle {} has a non-finite position or velocity; "
                                          "the run is unstable",
                                          stepIndex, time, i));
  }

  void writeFrameData(const fs::path& runDir, int frame) const override {
    fs::create_directories(runDir / "particles");
    writeParticlePly(frameFile(runDir / "particles", name_, frame, "ply"), sim_.particles());
    if (const granular::RenderPoints* points = sim_.renderPoints()) {
      fs::create_directories(runDir / "render_points");
      writeRenderPointPly(frameFile(runDir / "render_points", name_, frame, "ply"), *points, sim_.particles());
    }
    if (!setup_.bodies.empty()) {
      fs::create_directories(runDir / "bodies");
      writeBodyPly(frameFile(runDir / "bodies", name_, frame, "ply"), sim_.world(), setup_.bodies);
    }
  }

  void writeVolume(io::VdbWriter& writer) const override { addGranularFrame(writer, sim_, setup_.bodies); }

  void restore(const fs::path& vdbFile, double time, long /*steps*/) override {
    restoreGranularVdb(vdbFile, sim_, setup_.bodies, source_);
    // Render points are not saved: new ones are sampled inside the restored particles.
    sim_.resampleRenderPoints();
    time_ = time;
    sim_.setTime(time);
    for (std::size_t k = 0; k < fired_.size(); ++k) fired_[k] = setup_.explosions[k].time < time;
  }

  io::Image preview() const override { return preview_.render(sim_, setup_.colours, setup_.bodies); }

  // Each wind's spectrum against the prescribed one (winds/), and its measures in run.json.
  json finishRun(const fs::path& runDir, const json& /*frames*/) override {
    return writeWindReports<3>(sim_.winds(), runDir);
  }

  json statistics() const override {
    const granular::GranularParticles& p = sim_.particles();
    const double maxSpeed =
        parallelMax(p.size(), [&](std::size_t i) { return static_cast<double>(p.velocity[i].norm()); });
    const std::vector<double>& phi = sim_.gridState().phi;
    const double steps = std::max(1, last_.steps);
    json s = {{"particles", p.size()},
              {"total_mass_kg", sim_.totalMass()},
              {"max_speed_mps", maxSpeed},
              {"max_phi", phi.empty() ? 0.0 : *std::max_element(phi.begin(), phi.end())},
              {"active_pressure_cells", sim_.stress().stats().activePressureCells},
              {"steps", last_.steps},
              {"pressure_iterations_per_step", last_.pressureIterations / steps},
              {"friction_iterations_per_step", last_.frictionIterations / steps},
              {"correction_iterations_per_step", last_.correctionIterations / steps},
              {"seconds_per_step", last_.step / steps},
              {"transfer_s_per_step", last_.transfer / steps},
              {"assembly_s_per_step", last_.assembly / steps},
              {"pressure_s_per_step", last_.pressure / steps},
              {"friction_s_per_step", last_.friction / steps},
              {"particles_s_per_step", last_.particles / steps}};
    if (const granular::RenderPoints* points = sim_.renderPoints()) s["render_points"] = points->size();
    for (std::size_t k = 0; k < setup_.bodies.size(); ++k) {
      const Vec3& x = sim_.world().bodies()[setup_.bodies[k]].position;
      for (int a = 0; a < 3; ++a) s[fmt::format("body{}_{}_m", k, "xyz"[a])] = x[a];
    }
    return s;
  }

 private:
  // Explosions due before `until` push the particles and body centres within their radius outwards.
  void explode(double until) {
    for (std::size_t k = 0; k < fired_.size(); ++k) {
      const GranularExplosion& e = setup_.explosions[k];
      if (fired_[k] || e.time >= until) continue;
      fired_[k] = true;
      granular::GranularParticles& p = sim_.particles();
      parallelFor(0, p.size(), [&](std::size_t i) {
        const Vec3 d = p.position[i].cast<double>() - e.centre;
        const double r = d.norm();
        if (r < e.radius && r > 0.0) p.velocity[i] += (e.speed / r * d).cast<float>();
      });
      for (int index : setup_.bodies) {
        rigid::RigidBody& b = sim_.world().body(index);
        const Vec3 d = b.position - e.centre;
        if (d.norm() < e.radius && d.norm() > 0.0) b.velocity += e.speed * d.normalized();
      }
    }
  }

  struct FrameWork {
    int steps = 0;
    long pressureIterations = 0, frictionIterations = 0, correctionIterations = 0;
    double step = 0, transfer = 0, assembly = 0, pressure = 0, friction = 0, particles = 0;  // [s]
  };

  std::string source_, name_;
  StageTimers& timers_;
  GranularSceneSetup setup_;
  granular::GranularSimulation& sim_;
  double cfl_ = 0.9;
  GranularPreview preview_;
  std::vector<bool> fired_;
  double time_ = 0.0;
  FrameWork frame_, last_;
};

void declare(Schema& root) { declareGranularKeys(root); }

// Grid fields of the transfer and the stress solver (cells, faces, six stress lattices, QP
// scratch), about 1360 bytes, plus granular.particles_per_cell particles per cell at ~80 bytes
// each (their arrays, split/merge and transfer scratch), as if every cell were filled.
double bytesPerCell(int, const json& resolved) {
  return 1360.0 + 80.0 * resolved.at("granular").at("particles_per_cell").get<double>();
}

std::unique_ptr<Phenomenon> create(const Scene& scene, StageTimers& timers) {
  return std::make_unique<GranularPhenomenon>(scene, timers);
}

}  // namespace

PhenomenonType granularPhenomenonType() {
  return {"granular", "granular materials (sand) with rigid bodies: the continuum with particles of Narain 2011, ch. 5",
          declare, bytesPerCell, create};
}

}  // namespace msim::scene
