// The "cloth" phenomenon end to end: a small patch falls onto a ball and the floor; every frame
// writes the mesh (same vertices in the same order), the vertices for --resume and a preview;
// --resume continues; wind pushes it; bad input exits 2 naming the key or file. A crushed solid
// springs back.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_harness.hpp"
#include "msim/io/ply.hpp"
#include "msim/io/png.hpp"
#include "msim/io/vdb.hpp"

namespace {

using nlohmann::json;
using namespace msim;

std::string tinyCloth(const std::string& extra = "") {
  return R"({
  "name": "tiny", "phenomenon": "cloth",
  "domain": {"min": [-0.5, 0, -0.5], "max": [0.5, 1, 0.5], "resolution": 24},
  "time": {"duration": 0.2, "fps": 10},
  "outputs": {"mp4": false},
  "cloth": {"patch": {"origin": [-0.3, 0.6, -0.3], "edge_u": [0.6, 0, 0], "edge_v": [0, 0, 0.6], "quads": [8, 8]})" +
         extra + R"(},
  "bodies": [{"shape": {"type": "sphere", "center": [0, 0.3, 0], "radius": 0.2}, "friction": 0.5},
             {"shape": {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]}}]
})";
}

}  // namespace

TEST(ClothCli, PatchFallsOntoTheBallAndWritesMeshesAndResumes) {
  const fs::path dir = scratch("cloth_tiny");
  writeText(dir / "s.json", replaced(tinyCloth(), R"("duration": 0.2)", R"("duration": 0.4)"));
  const std::string run = "run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string();
  const Result r = runMsim(run + " --frames 2");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const fs::path out = dir / "out";
  const auto first = io::readPlyMesh(out / "mesh" / "tiny_0001.ply").mesh, second = io::readPlyMesh(out / "mesh" / "tiny_0002.ply").mesh;
  ASSERT_EQ(first.vertices.size(), 81u);
  ASSERT_EQ(second.vertices.size(), 81u);
  EXPECT_EQ(first.triangles, second.triangles);
  EXPECT_LT(second.vertices[40].y(), first.vertices[40].y()) << "the middle of the cloth falls";
  const json last = readJson(out / "run.json").at("frames").back();
  for (const char* key : {"kinetic_energy_J", "potential_energy_J", "max_strain", "mean_strain", "contacts",
                          "cg_iterations_per_step", "unconverged_solves", "vertices", "triangles"})
    EXPECT_TRUE(last.contains(key)) << key;
  EXPECT_TRUE(fs::exists(out / "png" / "tiny_0002.png"));
  EXPECT_TRUE(io::VdbFile(out / "vdb" / "tiny_0002.vdb", io::VdbProvenance::MsimRun).points("cloth_vertices").positions.size() == 81u);
  const Result resumed = runMsim(run + " --resume");
  ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
  const json frames = readJson(out / "run.json").at("frames");
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_GT(frames.back().at("contacts").get<int>(), 0) << "by 0.4 s the cloth lies on the ball";
  // msim render draws the frame's surface mesh in mesh_albedo (red here) and the bodies (grey)
  // from the frame's obstacle_distance: both must show.
  const Result rendered = runMsim("render " + out.string() +
                                  " --last --set render.camera.width=160 --set render.camera.height=120 "
                                  "--set render.multiple_scattering=false --set 'render.mesh_albedo=[0.9,0.05,0.05]'");
  ASSERT_EQ(rendered.exitCode, 0) << rendered.output;
  const io::Image image = io::readPng(out / "render" / "tiny_0004.png");
  int red = 0, grey = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.pixel(x, y);
      if (p[0] > 60 && p[0] > 3 * p[1]) ++red;
      if (p[0] > 60 && std::abs(p[0] - p[1]) < 12 && std::abs(p[1] - p[2]) < 12) ++grey;
    }
  EXPECT_GT(red, 100) << "the cloth";
  EXPECT_GT(grey, 100) << "the ball and the floor";
}

TEST(ClothCli, InitialVelocityCarriesAFreeClothAndBothContactMethodsRun) {
  // Without bodies a free cloth thrown at 1 m/s along x falls exactly (the trapezoidal rule is
  // exact for a constant acceleration): from frame 1 (0.1 s) to frame 2 (0.2 s) its centroid moves
  // 0.1 m along x and g (0.2^2 - 0.1^2) / 2 = 0.147 m down. The earlier contact method
  // (projection) runs on the ball too.
  const std::string thrown = replaced(tinyCloth(R"(, "initial_velocity": [1, 0, 0])"),
                                      R"(  "bodies": [{"shape": {"type": "sphere", "center": [0, 0.3, 0], "radius": 0.2}, "friction": 0.5},
             {"shape": {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]}}]
)",
                                      R"(  "bodies": []
)");
  const fs::path dir = scratch("cloth_thrown");
  writeText(dir / "s.json", replaced(thrown, R"("min": [-0.5, 0, -0.5])", R"("min": [-0.5, -0.5, -0.5])"));
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto start = io::readPlyMesh(dir / "out" / "mesh" / "tiny_0001.ply").mesh;
  const auto end = io::readPlyMesh(dir / "out" / "mesh" / "tiny_0002.ply").mesh;
  Vec3 moved = Vec3::Zero();
  for (std::size_t v = 0; v < end.vertices.size(); ++v) moved += (end.vertices[v] - start.vertices[v]) / double(end.vertices.size());
  EXPECT_NEAR(moved.x(), 0.1, 1e-6);
  EXPECT_NEAR(moved.y(), -0.5 * 9.8 * (0.2 * 0.2 - 0.1 * 0.1), 1e-6);
  const fs::path projected = scratch("cloth_projection");
  writeText(projected / "s.json", tinyCloth(R"(, "contact_method": "projection")"));
  const Result p = runMsim("run " + (projected / "s.json").string() + " -q --out " + (projected / "out").string());
  ASSERT_EQ(p.exitCode, 0) << p.output;
  EXPECT_GT(readJson(projected / "out" / "run.json").at("frames").back().at("contacts").get<int>(), 0);
}

TEST(ClothCli, WindPushesTheClothAlongItsNormal) {
  // A vertical patch pinned along its top edge in a 5 m/s wind blowing through it along z: the
  // drag along the normal moves the free cloth downwind; without wind it only hangs.
  const std::string patch = R"("patch": {"origin": [-0.3, 0.55, 0], "edge_u": [0.6, 0, 0], "edge_v": [0, 0.4, 0], "quads": [8, 8]})";
  const std::string scene = replaced(tinyCloth(R"(, "pins": [{"shape": {"type": "box", "min": [-1, 0.94, -1], "max": [1, 0.96, 1]}}])"),
                               R"("patch": {"origin": [-0.3, 0.6, -0.3], "edge_u": [0.6, 0, 0], "edge_v": [0, 0, 0.6], "quads": [8, 8]})", patch);
  auto meanZ = [&](const std::string& name, const std::string& text) {
    const fs::path dir = scratch(name);
    writeText(dir / "s.json", text);
    const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
    EXPECT_EQ(r.exitCode, 0) << r.output;
    const auto mesh = io::readPlyMesh(dir / "out" / "mesh" / "tiny_0002.ply").mesh;
    double z = 0.0;
    for (const Vec3& x : mesh.vertices) z += x.z() / static_cast<double>(mesh.vertices.size());
    return z;
  };
  EXPECT_NEAR(meanZ("cloth_no_wind", scene), 0.0, 1e-9) << "without wind the cloth hangs in its plane";
  const std::string windy = replaced(scene, R"("bodies": [)", R"("winds": [{"speed_rms": 0.1, "mean_velocity": [0, 0, 5]}], "bodies": [)");
  EXPECT_GT(meanZ("cloth_wind", windy), 0.01) << "the wind should blow the cloth along +z";
}

TEST(ClothCli, StrainLimitHoldsASoftClothAtTheLimit) {
  // A soft patch (k = 0.5 N) hanging from one edge stretches far beyond 10% without the limit and
  // not beyond it with cloth.strain_limit = 0.1.
  // The ball is moved out of the way: draped over it from a pinned edge, the cloth would have to
  // stretch to reach around it, and contact (which puts vertices back on the ball's surface after
  // the limit) wins over the limit.
  const std::string soft = replaced(replaced(tinyCloth(R"(, "edge_stiffness": 0.5, "density": 1.0,
      "pins": [{"shape": {"type": "box", "min": [-1, 0.5, -0.31], "max": [1, 0.7, -0.29]}}])"),
                                             R"("duration": 0.2)", R"("duration": 1.0)"),
                                    R"("center": [0, 0.3, 0])", R"("center": [3, 0.3, 0])");
  auto largestStretch = [&](const std::string& name, const std::string& text) {
    const fs::path dir = scratch(name);
    writeText(dir / "s.json", text);
    const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
    EXPECT_EQ(r.exitCode, 0) << r.output;
    const json run = readJson(dir / "out" / "run.json");
    double largest = 0.0;
    for (const json& f : run.at("frames")) largest = std::max(largest, f.at("max_strain").get<double>());
    return largest;
  };
  EXPECT_GT(largestStretch("cloth_unlimited", replaced(soft, R"("edge_stiffness": 0.5)", R"("edge_stiffness": 0.5, "strain_limit": 0)")), 0.2);
  EXPECT_LE(largestStretch("cloth_limited", soft), 0.12);
}

TEST(ClothCli, ScriptedPinsTurnExactlyAndTheClothStaysFreeOfIntersections) {
  // The patch's edge z = -0.3 turns about the vertical through (0, 0.6, 0) at 2 rad/s and rises at
  // 0.1 m/s: after 0.5 s its corner (-0.3, 0.6, -0.3) is at (0, 0.05, 0) + R_y(1 rad) (-0.3, 0, -0.3).
  const fs::path dir = scratch("cloth_scripted_pin");
  writeText(dir / "s.json", replaced(tinyCloth(R"(, "pins": [{"shape": {"type": "box", "min": [-1, 0.5, -0.31], "max": [1, 0.7, -0.29]},
      "angular_velocity": [0, 2, 0], "center": [0, 0.6, 0], "velocity": [0, 0.1, 0]}])"),
                                     R"("duration": 0.2)", R"("duration": 0.5)"));
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto mesh = io::readPlyMesh(dir / "out" / "mesh" / "tiny_0005.ply").mesh;
  const double c = std::cos(1.0), s = std::sin(1.0);
  const Vec3 expected = Vec3(0.0, 0.65, 0.0) + Vec3(c * -0.3 + s * -0.3, 0.0, -s * -0.3 + c * -0.3);
  EXPECT_LT((mesh.vertices[0] - expected).norm(), 1e-5);  // vertex 0: the patch's origin corner (float PLY)
  const json run = readJson(dir / "out" / "run.json");
  for (const json& f : run.at("frames")) {
    EXPECT_EQ(f.at("self_intersections").get<long>(), 0);
    EXPECT_EQ(f.at("vertices_inside_bodies").get<long>(), 0);
    EXPECT_EQ(f.at("intersecting_steps").get<long>(), 0);  // the referee runs after every step
  }
}

TEST(ClothCli, AMovingBallPushesTheClothWithoutEnteringIt) {
  // The patch falls onto the ball, which moves along +x at 0.5 m/s with friction 0.8: the cloth
  // is carried along +x, and no vertex is ever inside the ball or below the floor.
  const fs::path dir = scratch("cloth_moving_ball");
  writeText(dir / "s.json", replaced(replaced(tinyCloth(), R"("friction": 0.5})", R"("friction": 0.8, "velocity": [0.5, 0, 0]})"),
                                     R"("duration": 0.2)", R"("duration": 0.6)"));
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto first = io::readPlyMesh(dir / "out" / "mesh" / "tiny_0001.ply").mesh;
  const auto last = io::readPlyMesh(dir / "out" / "mesh" / "tiny_0006.ply").mesh;
  double shift = 0.0;
  for (std::size_t v = 0; v < first.vertices.size(); ++v) shift += (last.vertices[v][0] - first.vertices[v][0]) / first.vertices.size();
  EXPECT_GT(shift, 0.05) << "carried along by the ball";
  const json run = readJson(dir / "out" / "run.json");
  for (const json& f : run.at("frames")) {
    EXPECT_EQ(f.at("vertices_inside_bodies").get<long>(), 0);
    EXPECT_EQ(f.at("self_intersections").get<long>(), 0);
    EXPECT_EQ(f.at("intersecting_steps").get<long>(), 0);
  }
}

TEST(ClothCli, BadInputNamesTheKeyOrFile) {
  expectInputError("cloth_pin_nothing", tinyCloth(R"(, "pins": [{"shape": {"type": "sphere", "center": [5, 5, 5], "radius": 0.1}}])"),
                   {"cloth.pins[0].shape", "no vertex"});
  expectInputError("cloth_inside_body",
                   replaced(tinyCloth(), R"("center": [0, 0.3, 0], "radius": 0.2)", R"("center": [0, 0.6, 0], "radius": 0.2)"),
                   {"bodies[0].shape"});
  expectInputError("cloth_stiffness", tinyCloth(R"(, "edge_stiffness": 0)"), {"cloth.edge_stiffness"});
  expectInputError("cloth_thickness", tinyCloth(R"(, "thickness": 0.1)"), {"cloth.thickness", "edge length"});
  // A mesh with an edge shared by three triangles.
  const fs::path dir = scratch("cloth_fan_mesh");
  writeText(dir / "fan.obj", "v 0 0.5 0\nv 0.1 0.5 0\nv 0 0.6 0\nv 0 0.5 0.1\nv 0 0.4 0\nf 1 2 3\nf 1 2 4\nf 1 2 5\n");
  expectInputError("cloth_non_manifold", tinyCloth(R"(, "mesh": {"file": ")" + (dir / "fan.obj").string() + R"("})"),
                   {"fan.obj", "not a manifold"});
}

TEST(SolidCli, CrushedBallSpringsBackWithEveryTetrahedronPositive) {
  // The solid phenomenon: BCC tetrahedra of a ball crushed to a tenth of its height recover with
  // altitude springs (no tetrahedron inverted at the end); with edge springs alone some stay
  // inverted; the surface mesh keeps its vertex order. One step per frame at 24 frames per
  // second (implicit springs).
  const std::string scene = R"({
  "name": "ball", "phenomenon": "solid",
  "domain": {"min": [-0.3, 0, -0.3], "max": [0.3, 0.6, 0.3], "resolution": 24},
  "time": {"duration": 0.5, "fps": 24},
  "outputs": {"mp4": false},
  "solid": {"shape": {"type": "sphere", "center": [0, 0.3, 0], "radius": 0.2}, "spacing": 0.06, "density": 200,
            "edge_stiffness": 2, "edge_damping": 0.02, "altitude_stiffness": 2, "altitude_damping": 0.02,
            "initial_scale": [1, 0.1, 1], "gravity": [0, 0, 0]}
})";
  auto inverted = [&](const std::string& name, const std::string& text) {
    const fs::path dir = scratch(name);
    writeText(dir / "s.json", text);
    const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
    EXPECT_EQ(r.exitCode, 0) << r.output;
    const json last = readJson(dir / "out" / "run.json").at("frames").back();
    EXPECT_GT(last.at("tetrahedra").get<int>(), 100);
    EXPECT_EQ(io::readPlyMesh(dir / "out" / "mesh" / "ball_0001.ply").mesh.triangles,
              io::readPlyMesh(dir / "out" / "mesh" / "ball_0005.ply").mesh.triangles);
    return last.at("inverted_tetrahedra").get<int>();
  };
  EXPECT_EQ(inverted("solid_ball", scene), 0);
  EXPECT_GT(inverted("solid_ball_edges", replaced(scene, R"("altitude_stiffness": 2)", R"("altitude_stiffness": 0)")), 0);
}
