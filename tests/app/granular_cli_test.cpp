// The "granular" phenomenon end to end: a tiny scene with a body, an explosion and render points
// writes its per-frame PLY, VDB and PNG files; --resume continues it; bad input exits 2 naming the
// key and writes nothing.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_harness.hpp"
#include "msim/io/ply.hpp"
#include "msim/io/png.hpp"
#include "msim/io/vdb.hpp"

namespace {

using nlohmann::json;

// 12 x 10 x 12 cells of 5 cm: a slab of sand with a ball dropped on it. `extra` adds keys.
std::string tinyGranularScene(const std::string& extra = "") {
  return R"({
  "name": "tiny", "phenomenon": "granular",
  "domain": {"min": [0, 0, 0], "max": [0.6, 0.5, 0.6], "resolution": 12},
  "time": {"duration": 0.1, "fps": 20},
  "outputs": {"mp4": false},
  "materials": [{"name": "sand"}, {"name": "gravel", "density": 2600, "friction": 1.0, "colour": [0.5, 0.5, 0.5]}],
  "regions": [{"shape": {"type": "box", "min": [0, 0, 0], "max": [0.3, 0.15, 0.6]}, "material": "sand"},
              {"shape": {"type": "cylinder", "a": [0.45, 0, 0.3], "b": [0.45, 0.2, 0.3], "radius": 0.1},
               "material": "gravel"}],
  "bodies": [{"shape": {"type": "sphere", "radius": 0.06}, "mass": 0.5, "position": [0.15, 0.35, 0.3],
              "velocity": [0, -1, 0]}],
  "explosions": [{"centre": [0.45, 0.05, 0.3], "radius": 0.15, "speed": 1.0, "time": 0.02}])" +
         extra + "}\n";
}

}  // namespace

TEST(GranularCli, TinySceneWritesParticlesBodiesVdbAndPng) {
  const fs::path dir = scratch("granular_tiny");
  writeText(dir / "s.json", replaced(tinyGranularScene(), R"("outputs": {"mp4": false},)",
                                     R"("outputs": {"mp4": false}, "granular": {"render_points_per_particle": 2},)"));
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const fs::path out = dir / "out";
  const json run = readJson(out / "run.json");
  ASSERT_EQ(run.at("frames").size(), 2u);
  const json& last = run.at("frames").back();
  for (const char* key : {"particles", "total_mass_kg", "max_speed_mps", "max_phi", "active_pressure_cells",
                          "pressure_iterations_per_step", "seconds_per_step", "transfer_s_per_step",
                          "assembly_s_per_step", "pressure_s_per_step", "friction_s_per_step",
                          "particles_s_per_step", "body0_y_m", "render_points"})
    EXPECT_TRUE(last.contains(key)) << key;
  // The stages are parts of the step: together no more than its wall time.
  double stages = 0.0;
  for (const char* key : {"transfer_s_per_step", "assembly_s_per_step", "pressure_s_per_step", "friction_s_per_step",
                          "particles_s_per_step"})
    stages += last.value(key, 0.0);
  EXPECT_GT(stages, 0.0);
  EXPECT_LE(stages, last.value("seconds_per_step", 0.0) * (1.0 + 1e-9));
  EXPECT_GT(last.at("particles").get<double>(), 1000.0);
  // The ball fell (gravity and its initial speed) but stays above the floor.
  EXPECT_LT(last.at("body0_y_m").get<double>(), 0.35);
  EXPECT_GT(last.at("body0_y_m").get<double>(), 0.0);

  const auto particles = msim::io::readPlyPoints(out / "particles" / "tiny_0002.ply");
  EXPECT_EQ(static_cast<double>(particles.positions.size()), last.at("particles").get<double>());
  for (const char* a : {"vx", "vy", "vz", "mass", "material"}) EXPECT_NE(particles.find(a), nullptr) << a;
  const auto* material = particles.find("material");
  ASSERT_NE(material, nullptr);
  EXPECT_NE(std::find(material->values.begin(), material->values.end(), 1.0f), material->values.end());
  const auto points = msim::io::readPlyPoints(out / "render_points" / "tiny_0002.ply");
  EXPECT_EQ(static_cast<double>(points.positions.size()), last.at("render_points").get<double>());
  const auto bodies = msim::io::readPlyMesh(out / "bodies" / "tiny_0002.ply");
  EXPECT_GT(bodies.mesh.triangles.size(), 100u);

  const auto grids = msim::io::listVdbGrids(out / "vdb" / "tiny_0002.vdb");
  for (const char* g : {"phi", "pressure", "velocity", "particles", "bodies"})
    EXPECT_NE(std::find(grids.begin(), grids.end(), g), grids.end()) << g;
  const auto png = msim::io::readPng(out / "png" / "tiny_0002.png");
  EXPECT_GE(png.width, 400);
  EXPECT_TRUE(fs::exists(out / "stats.csv"));
}

TEST(GranularCli, ResumeContinuesFromTheLastFrame) {
  const fs::path dir = scratch("granular_resume");
  writeText(dir / "s.json", replaced(tinyGranularScene(), R"("duration": 0.1)", R"("duration": 0.15)"));
  const std::string run = "run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string();
  ASSERT_EQ(runMsim(run + " --frames 2").exitCode, 0);
  const Result resumed = runMsim(run + " --resume");
  ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
  const json record = readJson(dir / "out" / "run.json");
  ASSERT_EQ(record.at("frames").size(), 3u);
  // Mass is conserved across the resume (particles are split and merged, never lost).
  EXPECT_NEAR(record.at("frames").back().at("total_mass_kg").get<double>(),
              record.at("frames").front().at("total_mass_kg").get<double>(), 1e-3);
}

TEST(GranularCli, ResumeWithRenderPointsSamplesThemAgain) {
  const fs::path dir = scratch("granular_resume_points");
  writeText(dir / "s.json", replaced(tinyGranularScene(), R"("outputs": {"mp4": false},)",
                                     R"("outputs": {"mp4": false}, "granular": {"render_points_per_particle": 2},)"));
  const std::string run = "run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string();
  ASSERT_EQ(runMsim(run + " --frames 1").exitCode, 0);
  const Result resumed = runMsim(run + " --resume");
  ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
  // The resumed frame has render points again (2 per particle when sampled at the restore; split
  // and merge change the particle count afterwards, not the points).
  const json record = readJson(dir / "out" / "run.json");
  ASSERT_GE(record.at("frames").size(), 2u);
  const json& last = record.at("frames").back();
  EXPECT_GT(last.at("render_points").get<double>(), last.at("particles").get<double>());
  EXPECT_TRUE(fs::exists(dir / "out" / "render_points")) << "no render point files";
}

TEST(GranularCli, BadInputNamesTheKey) {
  const std::string scene = tinyGranularScene();
  expectInputError("granular_zero_density", replaced(scene, R"("density": 2600)", R"("density": 0)"),
                   {"materials[1].density"});
  expectInputError("granular_negative_density", replaced(scene, R"("density": 2600)", R"("density": -5)"),
                   {"materials[1].density"});
  expectInputError("granular_friction_above_2", replaced(scene, R"("friction": 1.0)", R"("friction": 2.5)"),
                   {"materials[1].friction"});
  expectInputError("granular_friction_negative", replaced(scene, R"("friction": 1.0)", R"("friction": -0.1)"),
                   {"materials[1].friction"});
  expectInputError("granular_zero_mass", replaced(scene, R"("mass": 0.5)", R"("mass": 0)"), {"bodies[0].mass"});
  expectInputError("granular_region_outside",
                   replaced(scene, R"("min": [0, 0, 0], "max": [0.3, 0.15, 0.6])",
                            R"("min": [1, 1, 1], "max": [1.3, 1.15, 1.6])"),
                   {"regions[0].shape", "outside the domain"});
  // The slab lies inside a solid box: no particle can be seeded.
  expectInputError("granular_region_in_solid",
                   replaced(scene, R"("bodies":)",
                            R"("solids": [{"shape": {"type": "box", "min": [-0.1, -0.1, -0.1], "max": [0.35, 0.2, 0.7]}}],
  "bodies":)"),
                   {"regions[0].shape", "inside solids"});
  expectInputError("granular_unknown_material", replaced(scene, R"("material": "gravel")", R"("material": "clay")"),
                   {"regions[1].material", "clay"});
  expectInputError("granular_hinge_pivot",
                   replaced(scene, R"("velocity": [0, -1, 0]})", R"("velocity": [0, -1, 0], "hinge": {"axis": [0, 0, 1]}})"),
                   {"bodies[0].hinge.pivot"});
  expectInputError("granular_2d", replaced(scene, R"("min": [0, 0, 0], "max": [0.6, 0.5, 0.6])",
                                           R"("min": [0, 0], "max": [0.6, 0.5])"),
                   {"domain.min"});
}
