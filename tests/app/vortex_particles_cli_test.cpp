// Vortex particles in the "smoke" phenomenon end to end (smoke.vortex_particles, Selle ch. 3.3-3.5):
// a 3D run seeds particles at the source's rate, writes them as VDB points and PLY with their
// vorticity, counts them and the enstrophy in stats.csv, deletes those that enter an obstacle,
// resumes from a saved frame with the same particles, and bad keys exit 2 naming the key.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>

#include "cli_harness.hpp"
#include "msim/io/ply.hpp"
#include "msim/io/vdb.hpp"

namespace {

// A small 3D plume with a box obstacle above the vent; particles seeded at 200 per second in the
// vent's box, azimuthal as Fig. 3.4's explosion.
std::string vortexSmoke(const std::string& particles = "") {
  return R"({
  "name": "vortex",
  "phenomenon": "smoke",
  "domain": {"min": [0, 0, 0], "max": [1, 1, 1], "resolution": 20,
             "boundaries": {"y_max": "open"}},
  "time": {"duration": 0.5, "fps": 8},
  "smoke": {"buoyancy": {"alpha": 0.05, "beta": 0.02},
            "vortex_particles": {"enabled": true, "rate": 200, "strength": 0.02, "vorticity": "azimuthal",
                                 "region_min": [0.35, 0.05, 0.35], "region_max": [0.65, 0.25, 0.65])" +
         particles + R"(}},
  "sources": [{"shape": {"type": "sphere", "center": [0.5, 0.15, 0.5], "radius": 0.12}, "mode": "set",
               "density": 1.0, "temperature": 500.0}],
  "obstacles": [{"shape": {"type": "box", "min": [0.3, 0.55, 0.3], "max": [0.7, 0.65, 0.7]}}],
  "outputs": {"mp4": false, "vdb_fog_tolerance": 0}
})";
}

}  // namespace

TEST(VortexParticlesCli, RunWritesParticlesAndCountsThem) {
  const fs::path dir = scratch("vortex_run");
  writeText(dir / "s.json", vortexSmoke());
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto grids = msim::io::listVdbGrids(dir / "out" / "vdb" / "vortex_0004.vdb");
  EXPECT_NE(std::find(grids.begin(), grids.end(), "vortex_particles"), grids.end());
  const msim::io::PointCloud cloud = msim::io::readPlyPoints(dir / "out" / "particles" / "vortex_0004.ply");
  ASSERT_NE(cloud.find("wx"), nullptr);
  // 200 per second for 0.5 s, less those that entered the obstacle or left through the top.
  EXPECT_GT(cloud.positions.size(), 50u);
  EXPECT_LE(cloud.positions.size(), 100u);
  for (const auto& x : cloud.positions)  // none inside the obstacle (deleted, Fig. 3.5)
    EXPECT_FALSE(x.x() > 0.3f && x.x() < 0.7f && x.y() > 0.55f && x.y() < 0.65f && x.z() > 0.3f && x.z() < 0.7f);
  // Azimuthal about the vertical: omega has no vertical part, and |omega| is kept (stretching rescales).
  const auto& wy = cloud.find("wy")->values;
  const auto& wx = cloud.find("wx")->values;
  const auto& wz = cloud.find("wz")->values;
  for (std::size_t p = 0; p < cloud.positions.size(); ++p)
    EXPECT_NEAR(std::sqrt(wx[p] * wx[p] + wy[p] * wy[p] + wz[p] * wz[p]), 1.0, 1e-5);
  const nlohmann::json run = readJson(dir / "out" / "run.json");
  std::ifstream stats(dir / "out" / "stats.csv");
  std::string header;
  std::getline(stats, header);
  for (const char* column : {"vortex_particles", "enstrophy"}) EXPECT_NE(header.find(column), std::string::npos) << column;
}

TEST(VortexParticlesCli, ResumeKeepsTheParticles) {
  const fs::path dir = scratch("vortex_resume");
  writeText(dir / "s.json", vortexSmoke(R"(, "end": 0.25)"));  // no seeding after frame 2
  const std::string scene = (dir / "s.json").string();
  ASSERT_EQ(runMsim("run " + scene + " -q --out " + (dir / "full").string()).exitCode, 0);
  ASSERT_EQ(runMsim("run " + scene + " -q --frames 2 --out " + (dir / "split").string()).exitCode, 0);
  const Result resumed = runMsim("run " + scene + " -q --resume --out " + (dir / "split").string());
  ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
  const auto a = msim::io::readPlyPoints(dir / "full" / "particles" / "vortex_0004.ply");
  const auto b = msim::io::readPlyPoints(dir / "split" / "particles" / "vortex_0004.ply");
  ASSERT_EQ(a.positions.size(), b.positions.size());
  for (std::size_t p = 0; p < a.positions.size(); ++p) EXPECT_LT((a.positions[p] - b.positions[p]).norm(), 1e-4f);
}

TEST(VortexParticlesCli, BadInputNamesTheKey) {
  expectInputError("vortex_region_outside",
                   replaced(vortexSmoke(), "\"region_max\": [0.65, 0.25, 0.65]", "\"region_max\": [1.5, 0.25, 0.65]"),
                   {"smoke.vortex_particles", "region"});
  expectInputError("vortex_negative_radius", vortexSmoke(R"(, "radius": -0.1)"), {"smoke.vortex_particles.radius"});
  expectInputError("vortex_negative_strength", replaced(vortexSmoke(), "\"strength\": 0.02", "\"strength\": -1"),
                   {"smoke.vortex_particles.strength"});
  expectInputError("vortex_empty_window", vortexSmoke(R"(, "start": 0.4, "end": 0.2)"),
                   {"smoke.vortex_particles", "start"});
}
