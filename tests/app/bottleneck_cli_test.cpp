// Door capacities of the default crowd model against pedestrian experiments: the specific flow
// through bottlenecks of 0.8-2.4 m lies at 1.5-2.1 persons/(m s) in the experiments of Seyfried et
// al. 2009, Kretz et al. 2006 and Liddle et al. 2011 (docs/evacuation.md has the sweep and its
// plot). The seed's constant-speed model, still selectable, passes far more.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cli_harness.hpp"
#include "msim/io/csv.hpp"
#include "msim/io/png.hpp"
#include "msim/render/plot.hpp"

namespace {

constexpr int kPeople = 400;

// A 20 x 20 m room with a door of `width` m in its east wall (0.4 m thick); 400 people walk to an
// exit 8 m behind it. The flow is measured from the crossings of a line in the door while 10% to
// 50% of the room passes (the queue formed, the room not yet emptying): persons/(m s).
double specificFlow(double width, const std::string& extra = "") {
  const std::string name = fmt::format("bottleneck_{:.1f}{}", width, extra.empty() ? "" : "_seed");
  const fs::path dir = scratch(name);
  const double lo = 10.0 - 0.5 * width, hi = 10.0 + 0.5 * width;
  writeText(dir / "s.json", fmt::format(R"({{
  "name": "door", "phenomenon": "crowd",
  "domain": {{"min": [0, 0], "max": [30, 20], "resolution": 60}},
  "time": {{"duration": 160, "fps": 5}},
  "crowd": {{"trajectories": false}},
  "goals": [{{"name": "out", "shape": {{"type": "box", "min": [28, 0], "max": [30, 20]}}, "exit": true}}],
  "obstacles": [{{"shape": {{"type": "box", "min": [20, 0], "max": [20.4, {0}]}}}},
                {{"shape": {{"type": "box", "min": [20, {1}], "max": [20.4, 20]}}}}],
  "groups": [{{"count": {2}, "region": {{"type": "box", "min": [4, 3], "max": [19.5, 17]}}, "goal": "out"}}],
  "measurement_lines": [{{"name": "door", "from": [20.2, {0}], "to": [20.2, {1}]}}],
  "outputs": {{"mp4": false, "vdb": false, "png": false}}}})",
                                        lo, hi, kPeople));
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string() + " " + extra);
  EXPECT_EQ(r.exitCode, 0) << r.output;
  if (r.exitCode != 0) return 0.0;
  const auto table = msim::io::readCsv(dir / "out" / "stats.csv");
  const auto column = [&](const std::string& c) {
    return static_cast<std::size_t>(std::find(table.columns.begin(), table.columns.end(), c) - table.columns.begin());
  };
  const std::size_t time = column("time_s"), crossed = column("line_door_crossings");
  double t10 = -1.0, t50 = -1.0;
  for (const auto& row : table.rows) {
    if (t10 < 0.0 && row[crossed] >= 0.1 * kPeople) t10 = row[time];
    if (t50 < 0.0 && row[crossed] >= 0.5 * kPeople) t50 = row[time];
  }
  EXPECT_GT(t10, 0.0) << name;
  EXPECT_GT(t50, t10) << name << ": fewer than half passed in 160 s";
  return t50 > t10 ? 0.4 * kPeople / (t50 - t10) / width : 0.0;
}

}  // namespace

// The sweep over door widths for both models, drawn to bottleneck_capacity.png in the tests'
// scratch folder (docs/images/bottleneck_capacity.png).
TEST(BottleneckCli, DefaultModelPassesTheMeasuredSpecificFlow) {
  const std::vector<double> widths = {0.8, 1.2, 1.6, 2.4};
  msim::render::Plot plot;
  plot.title = "specific flow through a door, 400 people";
  plot.xLabel = "door width (m)";
  plot.yLabel = "persons / (m s)";
  plot.yMin = 0.0;
  plot.yMax = 6.0;  // room above the data for the legend
  plot.xMin = 0.5;
  plot.xMax = 2.5;
  msim::render::PlotSeries model{"default (Weidmann, density ahead)", {}, {}, {}, msim::render::plotColour(0)};
  msim::render::PlotSeries seed{"seed (constant speed)", {}, {}, {}, msim::render::plotColour(1)};
  model.markers = seed.markers = true;
  for (const double width : widths) {
    const double j = specificFlow(width), js = specificFlow(width, "--set crowd.uic.speed_density=constant");
    std::printf("door %.1f m: %.2f persons/(m s), seed model %.2f\n", width, j, js);
    EXPECT_GE(j, 1.5) << width << " m";
    EXPECT_LE(j, 2.1) << width << " m";
    // The seed's model, still selectable, lets far more through.
    EXPECT_GT(js, 1.4 * j) << width << " m";
    model.x.push_back(width);
    model.y.push_back(j);
    seed.x.push_back(width);
    seed.y.push_back(js);
  }
  plot.series = {model, seed};
  for (const double bound : {1.5, 2.1}) {
    msim::render::PlotSeries measured{bound == 1.5 ? "measured range (Seyfried 2009, Kretz 2006, Liddle 2011)" : "",
                                      {0.5, 2.5}, {bound, bound}, {}, msim::Vec3(0.4, 0.4, 0.4)};
    plot.series.push_back(measured);
  }
  msim::io::writePng(scratch("bottleneck_plot") / "bottleneck_capacity.png", msim::render::renderPlot(plot));
}
