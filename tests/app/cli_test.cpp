// End-to-end checks of the msim program: bad input gives one clear message and exit code 2 with
// no frame written; runs write complete frames; --resume continues bit-exactly.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_harness.hpp"
#include "msim/io/vdb.hpp"

namespace {

// A small, fast 3D gas scene; `extra` is spliced into the top-level object.
std::string tinyScene(const std::string& extra = "", int resolution = 16) {
  return R"({
  "name": "tiny",
  "phenomenon": "gas",
  "domain": {"min": [0, 0, 0], "max": [1, 1, 1], "resolution": )" +
         std::to_string(resolution) + R"(},
  "time": {"duration": 0.5, "fps": 8},
  "gas": {"density": {"diffusion": 0.001}},
  "motion_fields": [{"type": "uniform", "magnitude": 0.5, "axis": [0, 1, 0]},
                    {"type": "line_vortex", "magnitude": 0.2, "position": [0.5, 0.5, 0.5], "core_radius": 0.1}],
  "sources": [{"shape": {"type": "sphere", "center": [0.5, 0.2, 0.5], "radius": 0.12}, "density_rate": 2.0}],
  "outputs": {"mp4": false}
  )" + extra + "}\n";
}


}  // namespace

TEST(Cli, VersionAndHelp) {
  EXPECT_EQ(runMsim("--version").exitCode, 0);
  const Result help = runMsim("--help");
  EXPECT_EQ(help.exitCode, 0);
  EXPECT_NE(help.output.find("run"), std::string::npos);
}

TEST(Cli, MissingSceneFile) {
  const fs::path dir = scratch("missing");
  const Result r = runMsim("run " + (dir / "nope.json").string() + " --out " + (dir / "out").string());
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("not found"), std::string::npos) << r.output;
  EXPECT_TRUE(noFramesIn(dir / "out"));
}

TEST(Cli, MalformedJsonReportsLineAndColumn) {
  const fs::path dir = scratch("malformed");
  writeText(dir / "bad.json", "{\n  \"name\": \"x\",\n  \"phenomenon\": \"gas\"\n  \"domain\": {}\n}\n");
  const Result r = runMsim("run " + (dir / "bad.json").string() + " --out " + (dir / "out").string());
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("bad.json:4:"), std::string::npos) << r.output;  // the error is on line 4
  EXPECT_TRUE(noFramesIn(dir / "out"));
}

TEST(Cli, UnknownKeySuggestsTheClosest) {
  const fs::path dir = scratch("unknown");
  std::string text = tinyScene();
  text.replace(text.find("\"resolution\""), 12, "\"resolutoin\"");
  writeText(dir / "s.json", text);
  const Result r = runMsim("run " + (dir / "s.json").string() + " --out " + (dir / "out").string());
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("domain.resolutoin"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("did you mean 'resolution'"), std::string::npos) << r.output;
  EXPECT_TRUE(noFramesIn(dir / "out"));
}

TEST(Cli, WrongTypeNamesKeyAndExpectation) {
  const fs::path dir = scratch("wrongtype");
  std::string text = tinyScene();
  text.replace(text.find("\"duration\": 0.5"), 15, "\"duration\": \"long\"");
  writeText(dir / "s.json", text);
  const Result r = runMsim("run " + (dir / "s.json").string() + " --out " + (dir / "out").string());
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("time.duration"), std::string::npos) << r.output;
  EXPECT_TRUE(noFramesIn(dir / "out"));
}

TEST(Cli, NonPositiveResolutionIsRejected) {
  const fs::path dir = scratch("resolution");
  for (const char* value : {"0", "-8"}) {
    writeText(dir / "s.json", tinyScene());
    const Result r = runMsim("run " + (dir / "s.json").string() + " --out " + (dir / "out").string() +
                             " --set domain.resolution=" + value);
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("domain.resolution"), std::string::npos) << r.output;
    EXPECT_TRUE(noFramesIn(dir / "out"));
  }
}

TEST(Cli, DomainLargerThanMemoryIsRefusedBeforeAllocating) {
  const fs::path dir = scratch("memory");
  writeText(dir / "s.json", tinyScene("", 200000));
  const Result r = runMsim("run " + (dir / "s.json").string() + " --out " + (dir / "out").string());
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("domain.resolution"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("available"), std::string::npos) << r.output;
  EXPECT_TRUE(noFramesIn(dir / "out"));
}

TEST(Cli, SourceOutsideTheDomainIsAnError) {
  const fs::path dir = scratch("outside");
  std::string text = tinyScene();
  text.replace(text.find("[0.5, 0.2, 0.5]"), 15, "[5.0, 0.2, 0.5]");
  writeText(dir / "s.json", text);
  const Result r = runMsim("validate " + (dir / "s.json").string());
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("sources[0].shape"), std::string::npos) << r.output;
  const Result run = runMsim("run " + (dir / "s.json").string() + " --out " + (dir / "out").string());
  EXPECT_EQ(run.exitCode, 2) << run.output;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(Cli, CflBlowUpStopsWithAMessage) {
  const fs::path dir = scratch("cfl");
  writeText(dir / "s.json", tinyScene());
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string() +
                           " --set time.max_substeps=1 --set motion_fields[0].magnitude=500");
  EXPECT_EQ(r.exitCode, 3) << r.output;
  EXPECT_NE(r.output.find("max_substeps"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("step "), std::string::npos) << r.output;
}

TEST(Cli, InfoListsParametersWithUnits) {
  const fs::path dir = scratch("info");
  writeText(dir / "s.json", tinyScene());
  const Result r = runMsim("info " + (dir / "s.json").string());
  EXPECT_EQ(r.exitCode, 0) << r.output;
  for (const char* needle : {"gas.density.diffusion", "m^2/s", "domain.resolution", "memory", "sources[0].density_rate"})
    EXPECT_NE(r.output.find(needle), std::string::npos) << needle << "\n" << r.output;
}

TEST(Cli, ResumeContinuesBitExactly) {
  const fs::path dir = scratch("resume");
  // Densities kept down to the last nonzero value: the saved frame is the whole state.
  writeText(dir / "s.json", replaced(tinyScene(), "\"mp4\": false", "\"mp4\": false, \"vdb_fog_tolerance\": 0"));
  const std::string scene = (dir / "s.json").string();
  ASSERT_EQ(runMsim("run " + scene + " -q --out " + (dir / "full").string()).exitCode, 0);
  ASSERT_EQ(runMsim("run " + scene + " -q --frames 2 --out " + (dir / "split").string()).exitCode, 0);
  EXPECT_FALSE(fs::exists(dir / "split" / "vdb" / "tiny_0003.vdb"));
  const Result resumed = runMsim("run " + scene + " --resume --out " + (dir / "split").string());
  ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("resuming after frame 2"), std::string::npos) << resumed.output;
  for (const char* frame : {"tiny_0003.vdb", "tiny_0004.vdb"}) {
    const auto a = msim::io::readFloatGrid(dir / "full" / "vdb" / frame, "density");
    const auto b = msim::io::readFloatGrid(dir / "split" / "vdb" / frame, "density");
    ASSERT_EQ(a.count(), b.count());
    EXPECT_EQ(0, std::memcmp(a.data().data(), b.data().data(), a.count() * sizeof(float))) << frame;
  }
  EXPECT_TRUE(fs::exists(dir / "full" / "run.json"));
  EXPECT_TRUE(fs::exists(dir / "full" / "stats.csv"));
  EXPECT_TRUE(fs::exists(dir / "full" / "png" / "tiny_0004.png"));
}

TEST(Cli, InterruptFinishesTheFrameAndStops) {
  // Ctrl-C (SIGINT), and SIGUSR1, which mpirun forwards to its processes where Ctrl-C would end the
  // whole job at once.
  for (const int signal : {SIGINT, SIGUSR1}) {
    const fs::path dir = scratch("interrupt_" + std::to_string(signal));
    writeText(dir / "s.json", tinyScene("", 40));
    const fs::path out = dir / "out";
    const std::string scene = (dir / "s.json").string(), outDir = out.string();
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      const int devnull = open("/dev/null", O_WRONLY);
      dup2(devnull, STDOUT_FILENO);
      dup2(devnull, STDERR_FILENO);
      execl(MSIM_APP_PATH, MSIM_APP_PATH, "run", scene.c_str(), "--out", outDir.c_str(), "--set", "time.duration=30",
            static_cast<char*>(nullptr));
      _exit(127);
    }
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!fs::exists(out / "vdb" / "tiny_0002.vdb") && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    kill(child, signal);
    int status = 0;
    waitpid(child, &status, 0);
    ASSERT_TRUE(WIFEXITED(status)) << signal;
    EXPECT_EQ(WEXITSTATUS(status), 130) << signal;
    // Every frame written is complete (both files), numbered without gaps, and no temporary is left.
    int frames = 0;
    while (fs::exists(out / "vdb" / ("tiny_" + std::string(4 - std::to_string(frames + 1).size(), '0') +
                                     std::to_string(frames + 1) + ".vdb")))
      ++frames;
    EXPECT_GE(frames, 2);
    EXPECT_LT(frames, 240);
    std::size_t files = 0;
    for (const auto& e : fs::recursive_directory_iterator(out)) {
      const std::string name = e.path().filename().string();
      EXPECT_EQ(name.find(".tmp-"), std::string::npos) << name;
      if (e.path().extension() == ".vdb" || e.path().extension() == ".png") ++files;
    }
    EXPECT_EQ(files, 2u * frames);
    std::ifstream run(out / "run.json");
    std::stringstream text;
    text << run.rdbuf();
    EXPECT_NE(text.str().find("\"status\": \"interrupted\""), std::string::npos) << signal;
  }
}

TEST(Cli, TurbulentWindResumesBitExactly) {
  const fs::path dir = scratch("resume_wind");
  writeText(dir / "s.json",
            replaced(tinyScene(R"(, "winds": [{"speed_rms": 0.3, "resolution": 16, "time_samples": 4, "period": 1}])"),
                     "\"mp4\": false", "\"mp4\": false, \"vdb_fog_tolerance\": 0"));
  const std::string scene = (dir / "s.json").string();
  ASSERT_EQ(runMsim("run " + scene + " -q --out " + (dir / "full").string()).exitCode, 0);
  ASSERT_EQ(runMsim("run " + scene + " -q --frames 2 --out " + (dir / "split").string()).exitCode, 0);
  ASSERT_EQ(runMsim("run " + scene + " -q --resume --out " + (dir / "split").string()).exitCode, 0);
  const auto a = msim::io::readFloatGrid(dir / "full" / "vdb" / "tiny_0004.vdb", "density");
  const auto b = msim::io::readFloatGrid(dir / "split" / "vdb" / "tiny_0004.vdb", "density");
  ASSERT_EQ(a.count(), b.count());
  EXPECT_EQ(0, std::memcmp(a.data().data(), b.data().data(), a.count() * sizeof(float)));
  // The run reports the wind's spectrum against the prescribed one.
  EXPECT_TRUE(fs::exists(dir / "full" / "winds" / "wind_0_spectrum.png"));
  EXPECT_TRUE(fs::exists(dir / "full" / "winds" / "wind_0_spectrum.csv"));
  std::ifstream runJson(dir / "full" / "run.json");
  const auto report = nlohmann::json::parse(runJson).at("results").at("winds").at(0);
  EXPECT_LT(report.at("divergence_over_gradient").get<double>(), 1e-5);
  EXPECT_NEAR(report.at("speed_rms_mps").get<double>() / 0.3, 1.0, 0.25);
  // The wind does move the gas: the same run without it differs.
  ASSERT_EQ(runMsim("run " + scene + " -q --set winds=[] --out " + (dir / "calm").string()).exitCode, 0);
  const auto c = msim::io::readFloatGrid(dir / "calm" / "vdb" / "tiny_0004.vdb", "density");
  EXPECT_NE(0, std::memcmp(a.data().data(), c.data().data(), a.count() * sizeof(float)));
}

TEST(Cli, WindTheLatticeCannotHoldNamesTheKey) {
  const fs::path dir = scratch("bad_wind");
  // 8 samples over the 1 m domain resolve waves down to 0.25 m.
  writeText(dir / "s.json", tinyScene(R"(, "winds": [{"resolution": 8, "smallest_eddy": 0.1}])"));
  const Result r = runMsim("run " + (dir / "s.json").string() + " --out " + (dir / "out").string());
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("winds[0]"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("finer than the lattice"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "out"));
  writeText(dir / "s2.json", tinyScene(R"(, "winds": [{"largest_eddy": 0.1, "smallest_eddy": 0.2}])"));
  const Result r2 = runMsim("run " + (dir / "s2.json").string() + " --out " + (dir / "out2").string());
  EXPECT_EQ(r2.exitCode, 2) << r2.output;
  EXPECT_NE(r2.output.find("below the largest scale"), std::string::npos) << r2.output;
}

TEST(Cli, SpatiallySynthesisedWindMovesTheGas) {
  const fs::path dir = scratch("spatial_wind");
  writeText(dir / "s.json",
            tinyScene(R"(, "winds": [{"synthesis": "spatial", "speed_rms": 0.3, "points_per_cell": 2}])"));
  const std::string scene = (dir / "s.json").string();
  ASSERT_EQ(runMsim("run " + scene + " -q --frames 2 --out " + (dir / "windy").string()).exitCode, 0);
  ASSERT_EQ(runMsim("run " + scene + " -q --frames 2 --set winds=[] --out " + (dir / "calm").string()).exitCode, 0);
  const auto a = msim::io::readFloatGrid(dir / "windy" / "vdb" / "tiny_0002.vdb", "density");
  const auto b = msim::io::readFloatGrid(dir / "calm" / "vdb" / "tiny_0002.vdb", "density");
  EXPECT_NE(0, std::memcmp(a.data().data(), b.data().data(), a.count() * sizeof(float)));
  std::ifstream runJson(dir / "windy" / "run.json");
  EXPECT_EQ(nlohmann::json::parse(runJson).at("results").at("winds").at(0).at("synthesis"), "spatial");
  EXPECT_FALSE(fs::exists(dir / "windy" / "winds"));  // no lattice to report on
}
