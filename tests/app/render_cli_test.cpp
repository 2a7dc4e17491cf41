// `msim render` and render.enabled end to end: saved frames become pictures without simulating
// again; bad input (missing or corrupt VDB, a grid that is not in the file, a bad camera) is one
// clear message with exit code 2.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include "cli_harness.hpp"
#include "msim/io/exr.hpp"
#include "msim/io/png.hpp"

namespace {

// A small 3D smoke scene whose frames the tests render.
std::string tinyRun(const std::string& extra = "") {
  return R"({
  "name": "tiny3d",
  "phenomenon": "smoke",
  "domain": {"min": [0, 0, 0], "max": [1, 1, 1], "resolution": 16,
             "boundaries": {"y_max": "open", "x_min": "closed", "x_max": "closed", "y_min": "closed",
                            "z_min": "closed", "z_max": "closed"}},
  "time": {"duration": 0.25, "fps": 8},
  "smoke": {"buoyancy": {"beta": 0.02}},
  "sources": [{"shape": {"type": "sphere", "center": [0.5, 0.3, 0.5], "radius": 0.2}, "mode": "set",
               "density": 1.0, "temperature": 400.0}],
  "outputs": {"mp4": false}
  )" + extra + "}\n";
}

fs::path simulate(const std::string& name, const std::string& extra = "") {
  const fs::path dir = scratch(name);
  writeText(dir / "s.json", tinyRun(extra));
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
  EXPECT_EQ(r.exitCode, 0) << r.output;
  return dir;
}

}  // namespace

TEST(RenderCli, RendersEveryFrameOfARunAndOneFile) {
  const fs::path dir = simulate("render_run");
  const Result r = runMsim("render " + (dir / "out").string() + " -q --set render.camera.width=64 "
                           "--set render.camera.height=48");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  for (const char* frame : {"tiny3d_0001.png", "tiny3d_0002.png"}) {
    ASSERT_TRUE(fs::exists(dir / "out" / "render" / frame)) << frame;
  }
  const Result one = runMsim("render " + (dir / "out" / "vdb" / "tiny3d_0002.vdb").string() + " -q --out " +
                             (dir / "one.png").string() + " --set render.camera.width=32 --set render.camera.height=32");
  ASSERT_EQ(one.exitCode, 0) << one.output;
  EXPECT_TRUE(fs::exists(dir / "one.png"));
}

TEST(RenderCli, RunWithRenderEnabledWritesPicturesAndExr) {
  const fs::path dir = simulate("render_enabled",
                                R"(, "render": {"enabled": true, "exr": true, "camera": {"width": 48, "height": 48}})");
  EXPECT_TRUE(fs::exists(dir / "out" / "render" / "tiny3d_0002.png"));
  const msim::io::ImageF radiance = msim::io::readExr(dir / "out" / "render" / "tiny3d_0002.exr");
  EXPECT_EQ(radiance.width, 48);
  EXPECT_GT(*std::max_element(radiance.rgb.begin(), radiance.rgb.end()), 0.0f);
}

TEST(RenderCli, LastFrameOnlyAndTheRunListsWhatItWrote) {
  const fs::path dir = scratch("render_last");
  writeText(dir / "s.json", tinyRun(R"(, "render": {"enabled": true, "frames": "last", "camera": {"width": 32, "height": 32}})"));
  const Result r = runMsim("run " + (dir / "s.json").string() + " --out " + (dir / "out").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_FALSE(fs::exists(dir / "out" / "render" / "tiny3d_0001.png"));
  EXPECT_TRUE(fs::exists(dir / "out" / "render" / "tiny3d_0002.png"));
  const std::string listed = (dir / "out" / "render" / "tiny3d_0002.png").string();
  EXPECT_NE(r.output.find(listed + " "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("physically based render of the last frame"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find((dir / "out" / "run.json").string()), std::string::npos) << r.output;
}

TEST(RenderCli, LastRendersOnlyTheRunsLastFrame) {
  const fs::path dir = simulate("render_last_flag", R"(, "render": {"camera": {"width": 32, "height": 32}})");
  const Result r = runMsim("render " + (dir / "out").string() + " --last -q --out " + (dir / "pictures").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_FALSE(fs::exists(dir / "pictures" / "tiny3d_0001.png"));
  EXPECT_TRUE(fs::exists(dir / "pictures" / "tiny3d_0002.png"));
  EXPECT_EQ(msim::io::readPng(dir / "pictures" / "tiny3d_0002.png").width, 32);  // the run's own camera keys
}

TEST(RenderCli, DetailMeasuresAPictureAndNamesABadCrop) {
  const fs::path dir =
      simulate("render_detail", R"(, "render": {"enabled": true, "frames": "last", "camera": {"width": 40, "height": 30}})");
  const std::string picture = (dir / "out" / "render" / "tiny3d_0002.png").string();
  const Result r = runMsim("detail --crop 0 0 40 20 " + picture + " " + picture);  // two pictures after the crop
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 2) << r.output;
  const double share = std::stod(r.output);
  EXPECT_GE(share, 0.0);
  EXPECT_LE(share, 1.0);
  EXPECT_NE(r.output.find(picture), std::string::npos) << r.output;
  const Result badCrop = runMsim("detail " + picture + " --crop 0 0 41 20");
  EXPECT_EQ(badCrop.exitCode, 2) << badCrop.output;
  EXPECT_NE(badCrop.output.find("--crop"), std::string::npos) << badCrop.output;
  const Result missing = runMsim("detail " + (dir / "nothing.png").string());
  EXPECT_EQ(missing.exitCode, 2) << missing.output;
  EXPECT_NE(missing.output.find("nothing.png"), std::string::npos) << missing.output;
}

TEST(RenderCli, CameraInsideAnObstacleIsRefused) {
  const fs::path dir = simulate("render_inside", R"(, "obstacles": [{"shape": {"type": "sphere", "center": [0.5, 0.75, 0.5],
      "radius": 0.15}}])");
  const Result r = runMsim("render " + (dir / "out").string() + " -q --out " + (dir / "pictures").string() +
                           " --set render.camera.auto=false --set render.camera.position=[0.5,0.75,0.5]"
                           " --set render.camera.target=[0.5,0.5,0.0]");
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("camera is inside an obstacle"), std::string::npos) << r.output;
  EXPECT_TRUE(noFramesIn(dir / "pictures"));
}

TEST(RenderCli, BadInputIsOneClearMessage) {
  const fs::path dir = simulate("render_bad");
  const std::string vdb = (dir / "out" / "vdb" / "tiny3d_0001.vdb").string();
  struct Case {
    std::string args, needle;
  };
  writeText(dir / "corrupt.vdb", "this is not a VDB file");
  for (const Case& c : {Case{(dir / "missing.vdb").string(), "no such file"},
                        Case{(dir / "corrupt.vdb").string(), "corrupt.vdb"},
                        Case{vdb + " --set render.grids.density=smoke", "no grid 'smoke'"},
                        Case{vdb + " --set render.camera.fov=0", "render.camera.fov"},
                        Case{vdb + " --set render.camera.auto=false --set render.camera.position=[0,0,0]",
                             "render.camera"},
                        Case{(dir / "s.json").string(), "run folder"}}) {
    const Result r = runMsim("render " + c.args + " -q --out " + (dir / "bad.png").string());
    EXPECT_EQ(r.exitCode, 2) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find(c.needle), std::string::npos) << c.args << "\n" << r.output;
    EXPECT_FALSE(fs::exists(dir / "bad.png")) << c.args;
  }
}

TEST(RenderCli, TwoDimensionalFramesRenderAsSlabs) {
  const fs::path dir = scratch("render_2d");
  writeText(dir / "s.json", R"({"name": "flat", "phenomenon": "smoke",
    "domain": {"min": [0, 0], "max": [1, 1], "resolution": 24},
    "time": {"duration": 0.125, "fps": 8},
    "sources": [{"shape": {"type": "sphere", "center": [0.5, 0.3], "radius": 0.2}, "mode": "set", "density": 1.0}],
    "obstacles": [{"shape": {"type": "sphere", "center": [0.5, 0.7], "radius": 0.1}}],
    "outputs": {"mp4": false}})");
  ASSERT_EQ(runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string()).exitCode, 0);
  const Result r = runMsim("render " + (dir / "out" / "vdb" / "flat_0001.vdb").string() + " -q --out " +
                           (dir / "flat.png").string() + " --set render.camera.width=40 --set render.camera.height=40");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  // The smoke (lower half) and the obstacle (upper half) are both visible against the background.
  const msim::io::Image image = msim::io::readPng(dir / "flat.png");
  const auto* background = image.pixel(1, 1);
  EXPECT_NE(image.pixel(20, 26)[0], background[0]);  // smoke at (0.5, 0.3)
  EXPECT_NE(image.pixel(20, 13)[0], background[0]);  // obstacle at (0.5, 0.7)
}

TEST(RenderCli, MeshesAndPointsFromFilesAreDrawnAndBadFilesNamed) {
  const fs::path dir = simulate("render_geometry");
  writeText(dir / "tetra.obj", "v 0.3 0.3 0.3\nv 0.7 0.3 0.3\nv 0.5 0.7 0.3\nv 0.5 0.5 0.7\n"
                               "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n");
  writeText(dir / "grains.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                                "property float z\nend_header\n0.2 0.8 0.5\n0.8 0.8 0.5\n");
  const std::string vdb = (dir / "out" / "vdb" / "tiny3d_0001.vdb").string();
  const std::string size = " --set render.camera.width=32 --set render.camera.height=32";
  const Result ok = runMsim("render " + vdb + " -q --out " + (dir / "with.png").string() + size +
                            " --set 'render.meshes=[{\"file\":\"" + (dir / "tetra.obj").string() + "\"}]'" +
                            " --set render.points.file=" + (dir / "grains.ply").string() + " --set render.points.radius=0.05");
  ASSERT_EQ(ok.exitCode, 0) << ok.output;
  ASSERT_EQ(runMsim("render " + vdb + " -q --out " + (dir / "without.png").string() + size).exitCode, 0);
  EXPECT_NE(msim::io::readPng(dir / "with.png").rgb, msim::io::readPng(dir / "without.png").rgb);
  const Result bad = runMsim("render " + vdb + " -q --out " + (dir / "bad.png").string() +
                             " --set 'render.meshes=[{\"file\":\"" + (dir / "missing.obj").string() + "\"}]'");
  EXPECT_EQ(bad.exitCode, 2) << bad.output;
  EXPECT_NE(bad.output.find("render.meshes[0].file"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(dir / "bad.png"));
}
