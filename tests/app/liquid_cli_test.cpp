// The "liquid" phenomenon end to end: a tiny 3D dam break with either tracker writes its VDB
// (liquid_phi as a level set, velocities, particles), surface mesh (PLY) and preview; --resume
// continues it from the saved surface, velocity and particles; a moving obstacle runs; OBJ meshes on
// request; sub-grid turbulence writes, resumes and renders its fine surface; bad input exits 2
// naming the key.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_harness.hpp"
#include "msim/io/obj.hpp"
#include "msim/io/ply.hpp"
#include "msim/io/vdb.hpp"

namespace {

using nlohmann::json;
using namespace msim;

// 16 x 8 x 8 cells of 5 cm in a closed tank, a block of water at one end.
std::string tinyScene(const std::string& tracker, const std::string& extra = "") {
  return R"({
  "name": "tiny", "phenomenon": "liquid",
  "domain": {"min": [0, 0, 0], "max": [0.8, 0.4, 0.4], "resolution": 16,
             "boundaries": {"x_min": "closed", "x_max": "closed", "y_min": "closed", "y_max": "closed",
                            "z_min": "closed", "z_max": "closed"}},
  "time": {"duration": 0.1, "fps": 20},
  "outputs": {"mp4": false},
  "liquid": {"tracker": ")" + tracker + R"("},
  "initial_liquid": [{"shape": {"type": "box", "min": [0, 0, 0], "max": [0.25, 0.3, 0.4]}}])" +
         extra + "}\n";
}

void expectFramesWritten(const std::string& tracker, const std::string& points) {
  const fs::path dir = scratch("liquid_tiny_" + tracker);
  writeText(dir / "s.json", tinyScene(tracker));
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const fs::path out = dir / "out";
  const json run = readJson(out / "run.json");
  ASSERT_EQ(run.at("frames").size(), 2u);
  const json& last = run.at("frames").back();
  for (const char* key : {"volume_m3", "max_speed_m_s", "kinetic_energy_J", "pressure_iterations",
                          "pressure_unconverged_steps", "particles"})
    EXPECT_TRUE(last.contains(key)) << key;
  EXPECT_NEAR(last.at("volume_m3").get<double>() / (0.25 * 0.3 * 0.4), 1.0, 0.05);
  const io::VdbFile vdb(out / "vdb" / "tiny_0002.vdb", io::VdbProvenance::MsimRun);
  const auto names = vdb.gridNames();
  for (const std::string& name : std::vector<std::string>{"liquid_phi", "vel", "vel_face_x", points})
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  EXPECT_FALSE(vdb.points(points).positions.empty());
  const auto mesh = io::readPlyMesh(out / "mesh" / "tiny_0002.ply");
  EXPECT_GT(mesh.mesh.triangles.size(), 50u);
  EXPECT_TRUE(fs::exists(out / "png" / "tiny_0002.png"));
}

}  // namespace

TEST(LiquidCli, ParticleLevelSetSceneWritesSurfaceMeshParticlesAndPreview) {
  expectFramesWritten("particle_level_set", "level_set_particles");
}

TEST(LiquidCli, FlipSceneWritesSurfaceMeshParticlesAndPreview) { expectFramesWritten("flip", "flip_particles"); }

TEST(LiquidCli, MovingObstacleRuns) {
  const fs::path dir = scratch("liquid_moving_obstacle");
  writeText(dir / "s.json", tinyScene("flip", R"(, "obstacles": [{"shape": {"type": "sphere", "center": [0.5, 0.1, 0.2], "radius": 0.06},
                                                     "oscillation": [0.1, 0, 0], "frequency": 2}])"));
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const io::VdbFile vdb(dir / "out" / "vdb" / "tiny_0002.vdb", io::VdbProvenance::MsimRun);
  EXPECT_TRUE(vdb.hasGrid("obstacle_distance"));
}

TEST(LiquidCli, ObjMeshOnRequest) {
  const fs::path dir = scratch("liquid_obj");
  writeText(dir / "s.json", replaced(tinyScene("flip"), R"("tracker": "flip")", R"("tracker": "flip", "mesh_format": "obj")"));
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_FALSE(fs::exists(dir / "out" / "mesh" / "tiny_0002.ply"));
  EXPECT_GT(io::readObj(dir / "out" / "mesh" / "tiny_0002.obj").triangles.size(), 50u);
}

TEST(LiquidCli, ResumeContinuesFromTheSavedSurface) {
  // Three frames at once against two and --resume: the resumed run continues the reseeding from
  // the saved step count and volume control from its saved state (target, integrator). FLIP
  // continues bit for bit; the particle level set's marker particles are saved in single
  // precision, so its first resumed frame agrees to round-off.
  for (const std::string tracker : {"particle_level_set", "flip"}) {
    const fs::path dir = scratch("liquid_resume_" + tracker);
    writeText(dir / "s.json", replaced(tinyScene(tracker), R"("duration": 0.1)", R"("duration": 0.15)"));
    const std::string scene = "run " + (dir / "s.json").string() + " -q --out ";
    ASSERT_EQ(runMsim(scene + (dir / "whole").string()).exitCode, 0);
    ASSERT_EQ(runMsim(scene + (dir / "out").string() + " --frames 2").exitCode, 0);
    const Result resumed = runMsim(scene + (dir / "out").string() + " --resume");
    ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
    const json record = readJson(dir / "out" / "run.json");
    const json whole = readJson(dir / "whole" / "run.json");
    ASSERT_EQ(record.at("frames").size(), 3u);
    const json& a = whole.at("frames").back();
    const json& b = record.at("frames").back();
    const auto relative = [&](const char* key) { return std::abs(b.at(key).get<double>() / a.at(key).get<double>() - 1.0); };
    testing::Test::RecordProperty(tracker + "_volume_difference", std::to_string(relative("volume_m3")));
    EXPECT_EQ(b.at("particles"), a.at("particles")) << tracker;
    EXPECT_EQ(b.at("target_volume_m3"), a.at("target_volume_m3")) << tracker;
    if (tracker == "flip") {
      EXPECT_EQ(b.at("volume_m3"), a.at("volume_m3"));
      EXPECT_EQ(b.at("kinetic_energy_J"), a.at("kinetic_energy_J"));
    } else {
      EXPECT_LT(relative("volume_m3"), 1e-6);
      EXPECT_LT(relative("kinetic_energy_J"), 1e-5);
    }
  }
}

TEST(LiquidCli, SubgridTurbulenceWritesTheFineSurfaceAndResumes) {
  // liquid.turbulence: liquid_phi (meshed, previewed, rendered) is the fine surface, 4 x 4 x 4
  // times the simulation's cells, liquid_sim_phi the simulation's; both hold the liquid's volume;
  // --resume continues from them; the frame renders with the solids' distance resampled.
  const fs::path dir = scratch("liquid_turbulence");
  const std::string scene = replaced(
      tinyScene("particle_level_set", R"(, "obstacles": [{"shape": {"type": "sphere", "center": [0.5, 0.0, 0.2], "radius": 0.08}}])"),
      R"("tracker": "particle_level_set")", R"("tracker": "particle_level_set", "turbulence": {"enabled": true})");
  writeText(dir / "s.json", replaced(scene, R"("duration": 0.1)", R"("duration": 0.15)"));
  const std::string run = "run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string();
  const Result r = runMsim(run + " --frames 2");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const fs::path out = dir / "out";
  const io::VdbFile vdb(out / "vdb" / "tiny_0002.vdb", io::VdbProvenance::MsimRun);
  const Grid<float, 3> fine = vdb.floatGrid("liquid_phi"), coarse = vdb.floatGrid("liquid_sim_phi");
  EXPECT_EQ(fine.size(), IVec3(64, 32, 32));
  EXPECT_EQ(coarse.size(), IVec3(16, 8, 8));
  EXPECT_TRUE(vdb.hasGrid("turbulent_energy"));
  const json last = readJson(out / "run.json").at("frames").back();
  EXPECT_NEAR(last.at("fine_volume_m3").get<double>() / last.at("volume_m3").get<double>(), 1.0, 0.03);
  for (const char* key : {"ripple_height_m", "turbulent_energy_integral", "noise_particles", "turbulence_band_fraction"})
    EXPECT_TRUE(last.contains(key)) << key;
  EXPECT_GT(io::readPlyMesh(out / "mesh" / "tiny_0002.ply").mesh.triangles.size(), 500u);  // the fine surface's
  const Result resumed = runMsim(run + " --resume");
  ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
  EXPECT_EQ(readJson(out / "run.json").at("frames").size(), 3u);
  const Result rendered = runMsim("render " + out.string() + " --last -q --set render.camera.width=64 "
                                  "--set render.camera.height=48 --out " + (dir / "render").string());
  EXPECT_EQ(rendered.exitCode, 0) << rendered.output;
  EXPECT_TRUE(fs::exists(dir / "render" / "tiny_0003.png"));
}

TEST(LiquidCli, BadInputNamesTheKey) {
  expectInputError("liquid_outside",
                   replaced(tinyScene("flip"), R"("min": [0, 0, 0], "max": [0.25, 0.3, 0.4])",
                            R"("min": [2, 2, 2], "max": [3, 3, 3])"),
                   {"initial_liquid[0].shape"});
  expectInputError("liquid_turbulence_without_gravity",
                   replaced(tinyScene("flip"), R"("tracker": "flip")",
                            R"("tracker": "flip", "gravity": [0, 0, 0], "turbulence": {"enabled": true})"),
                   {"liquid.turbulence", "gravity"});
  expectInputError("liquid_flip_ratio", replaced(tinyScene("flip"), R"("tracker": "flip")", R"("tracker": "flip", "flip_ratio": 1.5)"),
                   {"liquid.flip_ratio"});
  expectInputError("liquid_none", replaced(tinyScene("flip"), R"("initial_liquid": [{"shape": {"type": "box", "min": [0, 0, 0], "max": [0.25, 0.3, 0.4]}}])",
                                           R"("initial_liquid": [])"),
                   {"initial_liquid"});
  expectInputError("liquid_emitter_in_solid",
                   tinyScene("flip", R"(, "obstacles": [{"shape": {"type": "box", "min": [0.5, 0, 0], "max": [0.8, 0.2, 0.4]}}],
                                      "sources": [{"shape": {"type": "sphere", "center": [0.65, 0.1, 0.2], "radius": 0.04},
                                                   "velocity": [0, 1, 0]}])"),
                   {"sources[0].shape", "obstacle"});
  // 0.03 m^3 in a 0.128 m^3 tank, and a 10 x 10 cm hose at 2 m/s for 0.1 s adds 0.002: fits; for
  // 10 s it would add 0.2.
  const std::string hose = R"(, "sources": [{"shape": {"type": "box", "min": [0.5, 0.3, 0.15], "max": [0.6, 0.4, 0.25]},
                                              "velocity": [0, -2, 0]}])";
  const fs::path fits = scratch("liquid_hose_fits");
  writeText(fits / "s.json", tinyScene("flip", hose));
  const Result ok = runMsim("run " + (fits / "s.json").string() + " -q --out " + (fits / "out").string());
  EXPECT_EQ(ok.exitCode, 0) << ok.output;
  expectInputError("liquid_overfilled", replaced(tinyScene("flip", hose), R"("duration": 0.1)", R"("duration": 10)"),
                   {"sources", "closed domain"});
}
