// Procedural turbulence in smoke scenes (Narain ch. 3): the laminar-to-turbulent transition of
// Fig. 3.6 as a jet's speed rises, the fine-grid outputs, and the combinations refused.
#include <gtest/gtest.h>

#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "../sanitizer_build.hpp"
#include "cli_harness.hpp"
#include "msim/io/vdb.hpp"

namespace {

// A 2D jet of smoke from an inflow source, no buoyancy; the turbulence model on, with a
// viscosity of 2e-3 m^2/s so the viscous cutoff (eq. 3.9) matters at these speeds.
std::string jet(double speed, const std::string& extra = "") {
  return R"({"name": "jet", "phenomenon": "smoke",
 "domain": {"min": [0, 0], "max": [1, 2], "resolution": 32,
            "boundaries": {"x_min": "closed", "x_max": "closed", "y_min": "closed", "y_max": "open"}},
 "time": {"duration": 2.0, "fps": 10},
 "smoke": {"buoyancy": {"alpha": 0.0, "beta": 0.0}, "turbulence": {"enabled": true, "viscosity": 2e-3}},
 "sources": [{"shape": {"type": "sphere", "center": [0.5, 0.1], "radius": 0.05}, "mode": "set", "density": 1.0,
              "inflow": true, "velocity": [0, )" +
         std::to_string(speed) + R"(]}],
 "outputs": {"mp4": false, "png": false, "vdb": false})" + extra + "}\n";
}

nlohmann::json runJet(const std::string& name, const std::string& scene) {
  const fs::path dir = scratch(name);
  writeText(dir / "s.json", scene);
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
  EXPECT_EQ(r.exitCode, 0) << r.output;
  std::ifstream in(dir / "out" / "run.json");
  return r.exitCode == 0 ? nlohmann::json::parse(in) : nlohmann::json::object();
}

double largestTurbulentEnergy(const nlohmann::json& run) {
  double e = 0.0;
  for (const auto& f : run.at("frames")) e = std::max(e, f.at("turbulent_kinetic_energy").get<double>());
  return e;
}

}  // namespace

TEST(SmokeTurbulenceCli, TurbulenceSetsInAsTheJetSpeedsUp) {
  // Fig. 3.6: the model reproduces the laminar-to-turbulent transition as the flow speeds up. The
  // sub-grid kinetic energy per unit of the jet's own (speed^2) grows with the speed: the viscous
  // cutoff k_nu = (k_0 E^(3/2) / nu^3)^(1/4) leaves slow, weakly strained flow without eddies.
  double previous = 0.0, slowest = 0.0;
  for (const double speed : {0.05, 0.3, 1.5}) {
    const double e = largestTurbulentEnergy(runJet("jet_" + std::to_string(speed), jet(speed)));
    const double relative = e / (speed * speed);
    std::printf("jet at %.2f m/s: sub-grid kinetic energy %.3e m^4/s^2 (2D), %.3f of speed^2\n", speed, e, relative);
    EXPECT_GT(relative, previous);
    if (speed == 0.05) slowest = relative;
    previous = relative;
  }
  EXPECT_LT(slowest, 0.2 * previous);
  // A viscous fluid stays laminar at the fastest speed: no eddies at all.
  const double viscous = largestTurbulentEnergy(runJet(
      "jet_viscous", jet(1.5, R"(, "smoke": {"buoyancy": {"alpha": 0.0, "beta": 0.0}, "turbulence": {"enabled": true, "viscosity": 1.0}})")));
  EXPECT_EQ(viscous, 0.0);
}

TEST(SmokeTurbulenceCli, SmokeLivesOnTheFineGridAndUnsupportedCombinationsAreRefused) {
  const fs::path dir = scratch("turbulence_outputs");
  writeText(dir / "s.json", jet(0.5, R"(, "time": {"duration": 0.3, "fps": 10})"));
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --set outputs.vdb=true --out " + (dir / "out").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto density = msim::io::readFloatGrid(dir / "out" / "vdb" / "jet_0003.vdb", "density");
  EXPECT_EQ(density.size(), msim::IVec3(64, 128, 1));  // 4 x (16 x 32 cells)
  const auto energy = msim::io::readFloatGrid(dir / "out" / "vdb" / "jet_0003.vdb", "turbulent_energy");
  EXPECT_EQ(energy.size(), msim::IVec3(16, 32, 1));
  // Fire stays on the simulation grid: refused with turbulence, naming the key.
  writeText(dir / "fire.json", jet(0.5, R"(, "fire": {"enabled": true})"));
  const Result fire = runMsim("run " + (dir / "fire.json").string() + " --out " + (dir / "fire_out").string());
  EXPECT_EQ(fire.exitCode, 2) << fire.output;
  EXPECT_NE(fire.output.find("smoke.turbulence.enabled"), std::string::npos) << fire.output;
  EXPECT_FALSE(fs::exists(dir / "fire_out"));
  // So is the conservative scalar transport: the fine smoke moves with the advection scheme.
  const Result conservative = runMsim("run " + (dir / "s.json").string() +
                                      " --set smoke.advection.scalars=conservative --out " + (dir / "cons_out").string());
  EXPECT_EQ(conservative.exitCode, 2) << conservative.output;
  EXPECT_NE(conservative.output.find("smoke.advection.scalars"), std::string::npos) << conservative.output;
  EXPECT_FALSE(fs::exists(dir / "cons_out"));
  // Calibration out of range names its key.
  for (const char* bad : {"eddy_viscosity_constant=0", "intensity=-1"}) {
    const Result r = runMsim("run " + (dir / "s.json").string() + " --set smoke.turbulence." + bad + " --out " +
                             (dir / "bad_out").string());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find(std::string(bad).substr(0, std::string(bad).find('='))), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "bad_out"));
  }
}

TEST(SmokeTurbulenceCli, MovingObstacleKeepsTheFineSmokeOut) {
  // A box sweeps through a region a source keeps full of smoke: the fine grid, the energy model and
  // the noise particles follow it, and no smoke is left inside it (without following it, the
  // source's cells the box moved over would stay full).
  const fs::path dir = scratch("turbulence_moving");
  writeText(dir / "s.json", R"({"name": "sweep", "phenomenon": "smoke",
 "domain": {"min": [0, 0], "max": [1, 1], "resolution": 16},
 "time": {"duration": 0.6, "fps": 10},
 "smoke": {"buoyancy": {"alpha": 0.0, "beta": 0.0}, "turbulence": {"enabled": true}},
 "sources": [{"shape": {"type": "sphere", "center": [0.5, 0.5], "radius": 0.4}, "mode": "set", "density": 1.0}],
 "obstacles": [{"shape": {"type": "box", "min": [0.2, 0.4], "max": [0.45, 0.6]}, "velocity": [0.5, 0.0]}],
 "outputs": {"mp4": false, "png": false}})");
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const fs::path frame = dir / "out" / "vdb" / "sweep_0006.vdb";
  const auto density = msim::io::readFloatGrid(frame, "density");           // 64 x 64 fine cells
  const auto distance = msim::io::readFloatGrid(frame, "obstacle_distance");  // 16 x 16 cells
  int inside = 0;
  double smokeInside = 0.0, smokeOutside = 0.0;
  for (int j = 0; j < 16; ++j)
    for (int i = 0; i < 16; ++i) {
      const bool deep = distance(msim::IVec3(i, j, 0)) < -0.04;  // all its fine cells inside the box
      for (int b = 0; b < 4; ++b)
        for (int a = 0; a < 4; ++a) (deep ? smokeInside : smokeOutside) += density(msim::IVec3(4 * i + a, 4 * j + b, 0));
      inside += deep;
    }
  EXPECT_GT(inside, 0);
  EXPECT_EQ(smokeInside, 0.0);
  EXPECT_GT(smokeOutside, 100.0);
}

TEST(SmokeTurbulenceCli, SpectrumOfSavedVelocities) {
  // A 3D plume with turbulence writing its fine velocity, and `msim spectrum` on the last frame.
  const fs::path dir = scratch("turbulence_spectrum");
  writeText(dir / "s.json", R"({"name": "p", "phenomenon": "smoke",
 "domain": {"min": [0, 0, 0], "max": [1, 1, 1], "resolution": 12},
 "time": {"duration": 0.4, "fps": 5},
 "smoke": {"buoyancy": {"alpha": 0.0, "beta": 0.05}, "turbulence": {"enabled": true, "write_velocity": true}},
 "sources": [{"shape": {"type": "sphere", "center": [0.5, 0.2, 0.5], "radius": 0.15}, "mode": "set", "density": 1.0,
              "temperature": 500.0}],
 "outputs": {"mp4": false, "png": false}})");
  ASSERT_EQ(runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string()).exitCode, 0);
  const fs::path frame = dir / "out" / "vdb" / "p_0002.vdb";
  EXPECT_EQ(msim::io::readVectorGrid(frame, "vel").size(), msim::IVec3(48, 48, 48));  // the fine grid
  const Result r = runMsim("spectrum " + frame.string() + " --out " + (dir / "spec").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("cube of 48 voxels"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(dir / "spec.png"));
  EXPECT_TRUE(fs::exists(dir / "spec_0.csv"));
  // A missing grid names itself.
  const Result bad = runMsim("spectrum " + frame.string() + " --grid nothing");
  EXPECT_EQ(bad.exitCode, 2) << bad.output;
  EXPECT_NE(bad.output.find("nothing"), std::string::npos) << bad.output;
}

namespace {

// Where the smoke of a 2D frame is: its density-weighted mean height and the rms of its horizontal
// spread about its mean, in metres, on a grid of cell size dx.
struct PlumeShape {
  double height = 0.0, width = 0.0;
};

PlumeShape plumeShape(const fs::path& frame, double dx) {
  const auto density = msim::io::readFloatGrid(frame, "density");
  double mass = 0.0, y = 0.0, x = 0.0, xx = 0.0;
  for (int j = 0; j < density.size().y(); ++j)
    for (int i = 0; i < density.size().x(); ++i) {
      const double m = density(msim::IVec3(i, j, 0));
      const double cx = (i + 0.5) * dx, cy = (j + 0.5) * dx;
      mass += m;
      x += m * cx;
      y += m * cy;
      xx += m * cx * cx;
    }
  x /= mass;
  return {y / mass, std::sqrt(std::max(0.0, xx / mass - x * x))};
}

}  // namespace

TEST(SmokeTurbulenceCli, PlumeRisesAndSpreadsLikeTheRefinedSimulation) {
  // Fig. 3.6 in 2D: smoke rising from a small hot source on 32 x 128 cells with the model (smoke on
  // 128 x 512) against the same scene simulated on 128 x 512 cells. The model's eddies add detail
  // and spread the plume, but must not mix it away: its height stays within 25% of the refined
  // simulation's and its width within 40% (measured: 13% and 17% low, 22% and 30% wider). With the
  // seed's eddy viscosity constant (1 instead of 0.09) the plume is 24% low at 2 s, at the edge;
  // with eddies 2.4 times stronger still (about the noise scaling msim used before), 39% low.
  // Two whole runs (one on 128 x 512 cells) and a comparison of chaotic plumes: five minutes
  // instrumented, and the plume's width moves by several per cent with the compiler's rounding.
  if (msim::test::kSanitizerBuild) GTEST_SKIP() << "a Release-build measurement; the sanitizer build runs the smaller smoke tests";
  const fs::path dir = scratch("turbulence_plume");
  writeText(dir / "s.json", R"({"name": "plume", "phenomenon": "smoke",
 "domain": {"min": [0, 0], "max": [0.25, 1.0], "resolution": 128,
            "boundaries": {"x_min": "closed", "x_max": "closed", "y_min": "closed", "y_max": "open"}},
 "time": {"duration": 2.0, "fps": 10},
 "smoke": {"buoyancy": {"alpha": 0.0, "beta": 0.02}, "turbulence": {"enabled": true}},
 "sources": [{"shape": {"type": "sphere", "center": [0.125, 0.06], "radius": 0.025}, "mode": "set", "density": 1.0,
              "temperature": 400.0}],
 "outputs": {"mp4": false, "png": false, "vdb": true}})");
  const std::string scene = (dir / "s.json").string();
  ASSERT_EQ(runMsim("run " + scene + " -q --out " + (dir / "model").string()).exitCode, 0);
  ASSERT_EQ(runMsim("run " + scene + " -q --set domain.resolution=512 --set smoke.turbulence.enabled=false --out " +
                    (dir / "refined").string())
                .exitCode,
            0);
  for (const int frame : {15, 20}) {
    const std::string name = fmt::format("plume_{:04d}.vdb", frame);
    const PlumeShape model = plumeShape(dir / "model" / "vdb" / name, 0.25 / 128);
    const PlumeShape refined = plumeShape(dir / "refined" / "vdb" / name, 0.25 / 128);
    std::printf("t = %.1f s: plume height %.3f m (refined %.3f), width %.4f m (refined %.4f)\n", 0.1 * frame, model.height,
                refined.height, model.width, refined.width);
    EXPECT_NEAR(model.height / refined.height, 1.0, 0.25) << frame;
    EXPECT_NEAR(model.width / refined.width, 1.0, 0.4) << frame;
  }
}
