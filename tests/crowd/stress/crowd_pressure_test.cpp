// Helbing's crowd pressure over time and the strain-rate magnitude (Golas eq. 4.13, Figs. 4.6,
// 4.10, 4.11): the strain rate of linear flows against its closed form (simple shear sqrt(2)
// gamma, rigid rotation and uniform flow 0), and the temporal pressure's lazily decayed sums
// against a brute-force weighted variance over every stored sample, and Helbing's local speed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "msim/crowd/stress/crowd_pressure.hpp"
#include "msim/crowd/stress/turbulence_metrics.hpp"

using namespace msim;
using namespace msim::crowd;
using namespace msim::crowd::stress;

namespace {

// Four agents per cell at its quarter points (the window means are then the flow at the cell
// centres for a linear flow), velocities from `flow`.
template <typename Flow>
void quarterPoints(const GridSpec<2>& spec, Flow&& flow, std::vector<Vec2f>& x, std::vector<Vec2f>& v) {
  for (int j = 0; j < spec.res.y(); ++j)
    for (int i = 0; i < spec.res.x(); ++i)
      for (const Vec2& q : {Vec2(0.25, 0.25), Vec2(0.75, 0.25), Vec2(0.25, 0.75), Vec2(0.75, 0.75)}) {
        const Vec2 p = spec.origin + (Vec2(i, j) + q) * spec.dx;
        x.push_back(p.cast<float>());
        v.push_back(flow(p).template cast<float>());
      }
}

}  // namespace

TEST(CrowdPressure, StrainRateOfLinearFlowsMatchesTheirClosedForm) {
  const GridSpec<2> spec(Vec2(0.0, 0.0), 0.5, IVec<2>(12, 10));
  Grid<float, 2> strain(spec);
  const double gamma = 0.4, omega = 0.3;
  struct Case {
    const char* name;
    double expected;
    Vec2 (*flow)(const Vec2&, double);
    double parameter;
  };
  const Case cases[] = {
      {"simple shear v = (gamma y, 0)", std::sqrt(2.0) * gamma, [](const Vec2& p, double g) { return Vec2(g * p.y(), 0.0); }, gamma},
      {"rigid rotation", 0.0, [](const Vec2& p, double w) { return Vec2(-w * p.y(), w * p.x()); }, omega},
      {"uniform flow", 0.0, [](const Vec2&, double) { return Vec2(1.2, -0.3); }, 0.0},
      {"stretching v = (g x, -g y)", 2.0 * std::sqrt(2.0) * gamma, [](const Vec2& p, double g) { return Vec2(g * p.x(), -g * p.y()); }, gamma},
  };
  for (const Case& k : cases) {
    std::vector<Vec2f> x, v;
    quarterPoints(spec, [&](const Vec2& p) { return k.flow(p, k.parameter); }, x, v);
    CrowdWindows windows(spec, 1);
    windows.gather(x, v);
    const StrainRateSummary summary = strainRate(windows, strain);
    EXPECT_EQ(summary.cells, spec.cellCount()) << k.name;
    EXPECT_GE(summary.max, k.expected - 1e-5) << k.name;
    if (k.parameter == 0.0) {
      EXPECT_NEAR(summary.mean + summary.max + summary.variation, 0.0, 1e-6) << k.name;
    }
    // Where the 3 x 3 windows and their neighbours' are whole (clipped windows at the boundary are
    // not centred on their cell).
    for (int j = 2; j < spec.res.y() - 2; ++j)
      for (int i = 2; i < spec.res.x() - 2; ++i) EXPECT_NEAR(strain(IVec<2>(i, j)), k.expected, 1e-5) << k.name << " at " << i << "," << j;
  }
}

TEST(CrowdPressure, LocalSpeedIsTheMeanFlowNotTheAgentsSpeed) {
  // Helbing's local speed: a uniform flow's is its speed; agents of every cell pushed to and fro
  // (pairs walking opposite ways at 1 m/s) have a local speed of 0 whatever their own speeds; a
  // uniform flow in one half of the grid and a jostling crowd in the other average to half, weighted
  // by the agents (the windows straddling the two halves see part of the flow: between).
  const GridSpec<2> spec(Vec2(0.0, 0.0), 1.0, IVec<2>(10, 6));
  std::vector<Vec2f> x, v;
  quarterPoints(spec, [](const Vec2&) { return Vec2(0.9, -1.2); }, x, v);
  CrowdWindows windows(spec, 1);
  windows.gather(x, v);
  EXPECT_NEAR(meanLocalSpeed(windows), 1.5, 1e-6);
  for (std::size_t k = 0; k < v.size(); ++k) v[k] = (k % 2 == 0 ? 1.0f : -1.0f) * Vec2f(0.6f, 0.8f);
  windows.gather(x, v);
  EXPECT_NEAR(meanLocalSpeed(windows), 0.0, 1e-6);
  for (std::size_t k = 0; k < v.size(); ++k)
    if (x[k].x() < 5.0f) v[k] = Vec2f(1.0f, 0.0f);
  windows.gather(x, v);
  EXPECT_GT(meanLocalSpeed(windows), 0.4);
  EXPECT_LT(meanLocalSpeed(windows), 0.6);
  windows.gather({}, {});
  EXPECT_EQ(meanLocalSpeed(windows), 0.0);
}

TEST(CrowdPressure, StrainRateIsZeroWhereNobodyIs) {
  const GridSpec<2> spec(Vec2(0.0, 0.0), 1.0, IVec<2>(9, 9));
  Grid<float, 2> strain(spec);
  const std::vector<Vec2f> x{Vec2f(4.5f, 4.5f), Vec2f(4.6f, 4.4f)}, v{Vec2f(1.0f, 0.0f), Vec2f(-1.0f, 0.0f)};
  CrowdWindows windows(spec, 1);
  windows.gather(x, v);
  strainRate(windows, strain);
  EXPECT_EQ(strain(IVec<2>(0, 0)), 0.0f);
  EXPECT_EQ(strain(IVec<2>(8, 8)), 0.0f);
}

TEST(CrowdPressure, TemporalPressureEqualsTheWeightedVarianceOverStoredSamples) {
  // Cells 1 m wide, window 1 (3 x 3 cells), half-life 1.5 s; 60 samples 0.05-0.15 s apart of 30
  // agents wandering at random (cells empty in some samples). The reference keeps every sample and
  // weighs the one taken at t_k by dt_k 2^(-(T - t_k) / 1.5).
  const GridSpec<2> spec(Vec2(0.0, 0.0), 1.0, IVec<2>(6, 5));
  const double seconds = 3.0;
  TemporalPressure temporal(spec, seconds);
  CrowdWindows windows(spec, 1);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  struct Sample {
    double t, dt;
    std::vector<double> count, vx, vy;  // per cell: the window's count and mean velocity
  };
  std::vector<Sample> samples;
  std::vector<Vec2f> x(30), v(30);
  for (Vec2f& p : x) p = Vec2f(float(6.0 * u(rng)), float(5.0 * u(rng)));
  double t = 0.0;
  for (int s = 0; s < 60; ++s) {
    const double dt = 0.05 + 0.1 * u(rng);
    t += dt;
    for (std::size_t k = 0; k < x.size(); ++k) {
      v[k] = Vec2f(float(2.0 * u(rng) - 1.0), float(2.0 * u(rng) - 1.0));
      x[k] = (x[k] + 0.8f * v[k]).cwiseMax(Vec2f(0.01f, 0.01f)).cwiseMin(Vec2f(5.99f, 4.99f));
    }
    windows.gather(x, v);
    temporal.add(windows, dt);
    Sample sample{t, dt, std::vector<double>(spec.cellCount(), 0.0), std::vector<double>(spec.cellCount(), 0.0),
                  std::vector<double>(spec.cellCount(), 0.0)};
    for (std::size_t k = 0; k < x.size(); ++k) {
      const int i = int(x[k].x()), j = int(x[k].y());
      for (int b = j - 1; b <= j + 1; ++b)
        for (int a = i - 1; a <= i + 1; ++a) {
          if (a < 0 || b < 0 || a >= 6 || b >= 5) continue;
          const std::size_t c = std::size_t(a + 6 * b);
          sample.count[c] += 1.0;
          sample.vx[c] += v[k].x();
          sample.vy[c] += v[k].y();
        }
    }
    samples.push_back(std::move(sample));
  }
  Grid<float, 2> p(spec);
  temporal.pressure(p);
  int checked = 0;
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 6; ++i) {
      const std::size_t c = std::size_t(i + 6 * j);
      const int cells = (std::min(5, i + 1) - std::max(0, i - 1) + 1) * (std::min(4, j + 1) - std::max(0, j - 1) + 1);
      double all = 0.0, occupied = 0.0, density = 0.0, mx = 0.0, my = 0.0, m2 = 0.0;
      int hits = 0;
      for (const Sample& s : samples) {
        const double w = s.dt * std::pow(2.0, -(t - s.t) / (0.5 * seconds));
        all += w;
        if (s.count[c] == 0.0) continue;
        ++hits;
        const double vx = s.vx[c] / s.count[c], vy = s.vy[c] / s.count[c];
        occupied += w;
        density += w * s.count[c] / cells;
        mx += w * vx;
        my += w * vy;
        m2 += w * (vx * vx + vy * vy);
      }
      if (hits < 2) {
        EXPECT_EQ(p[c], 0.0f);
        continue;
      }
      mx /= occupied;
      my /= occupied;
      const double expected = density / all * (m2 / occupied - mx * mx - my * my);
      EXPECT_NEAR(p[c], expected, 1e-5 * std::max(1.0, expected)) << i << "," << j;
      ++checked;
    }
  EXPECT_GT(checked, 20);
}

TEST(CrowdPressure, TemporalPressureOfASteadyCrowdIsZero) {
  const GridSpec<2> spec(Vec2(0.0, 0.0), 0.5, IVec<2>(8, 8));
  TemporalPressure temporal(spec, 3.0);
  CrowdWindows windows(spec, 1);
  std::vector<Vec2f> x, v;
  quarterPoints(spec, [](const Vec2&) { return Vec2(0.9, 0.2); }, x, v);
  windows.gather(x, v);
  for (int s = 0; s < 20; ++s) temporal.add(windows, 0.05);
  Grid<float, 2> p(spec);
  temporal.pressure(p);
  for (std::size_t c = 0; c < p.count(); ++c) EXPECT_NEAR(p[c], 0.0f, 1e-9f);
}

// The samples by density (checks T10, T12, T15: at which densities P > 0.02, and how people move
// there): on 1 m cells, a block at 4 /m^2 (four agents a cell) pushed to and fro (each agent's
// velocity turns through a full circle over 8 steps while it wants to walk east) beside a block at
// 1 /m^2 walking steadily east. Every window inside the steady block is calm and its agents walk
// straight on, every one inside the pushed block turbulent, its agents moving backwards in half the
// frames and as fast sideways as forwards; windows across the border hold both and fall in between.
TEST(CrowdPressure, SamplesByDensityTellTheTurbulentDensitiesApart) {
  const GridSpec<2> grid(Vec2(0.0, 0.0), 1.0, IVec<2>(12, 6));
  Agents a;
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 12; ++i)
      for (int k = 0; k < (i < 6 ? 4 : 1); ++k) {
        AgentSpec s;
        s.position = Vec2f(i + 0.2f + 0.2f * k, j + 0.5f);
        const std::size_t n = a.add(s);
        a.preferredVelocity[n] = Vec2f(1.2f, 0.0f);
      }
  TurbulenceMetrics metrics(grid);
  for (int step = 0; step < 100; ++step) {
    const float angle = 0.25f * 3.14159265f * static_cast<float>(step % 8);
    for (std::size_t n = 0; n < a.size(); ++n)
      a.velocity[n] = a.position[n].x() < 6.0f ? 0.5f * Vec2f(std::cos(angle), std::sin(angle)) : Vec2f(1.0f, 0.0f);
    metrics.sample(a, 0.05);
    if (step % 10 == 9) metrics.measure(a);
  }
  const SamplesByDensity& bins = metrics.samplesByDensity();
  long cells = 0, agents = 0;
  for (std::size_t b = 0; b < bins.cells.size(); ++b) cells += bins.cells[b], agents += bins.agents[b];
  EXPECT_EQ(cells, 10 * grid.cellCount());  // every cell's window holds someone in each of 10 frames
  EXPECT_EQ(agents, 10 * static_cast<long>(a.size()));
  const std::size_t steady = SamplesByDensity::bin(1.0), pushed = SamplesByDensity::bin(4.0);
  EXPECT_EQ(bins.cells[steady], 10 * 5 * 6);  // the steady block's windows off the border: 5 columns
  EXPECT_EQ(bins.turbulentCells[steady], 0);
  EXPECT_EQ(bins.cells[pushed], 10 * 5 * 6);
  EXPECT_EQ(bins.turbulentCells[pushed], bins.cells[pushed]);  // rho Var(v) = 4 x 0.25 = 1 /s^2
  // Agents: the steady block's 5 columns x 6 agents, the pushed block's 5 columns x 24.
  EXPECT_EQ(bins.agents[steady], 10 * 30);
  EXPECT_EQ(bins.backward[steady], 0);
  EXPECT_NEAR(bins.sideways2[steady], 0.0, 1e-9);
  EXPECT_NEAR(bins.forward2[steady], 10 * 30 * 1.0, 1e-6);
  EXPECT_EQ(bins.agents[pushed], 10 * 120);
  // The measured steps 9, 19, ..., 99 point the velocity at 45, 135, 225, 315, 45, 135, 225, 315,
  // 45 and 135 degrees from east: backward in 5 of the 10 frames.
  EXPECT_EQ(bins.backward[pushed], 5 * 120);
  EXPECT_NEAR(bins.forward2[pushed] + bins.sideways2[pushed], 10 * 120 * 0.25, 1e-4);
}

// A run's summaries leave out the frames before it asks for them (a start's transient): the
// frames measured without summarizing add no samples and no peak, the ones after add theirs, and
// the frame's own figures are the same either way.
TEST(CrowdPressure, SummariesGatherOnlyTheFramesAskedFor) {
  const GridSpec<2> grid(Vec2(0.0, 0.0), 1.0, IVec<2>(6, 6));
  Agents a;
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 6; ++i) {
      AgentSpec s;
      s.position = Vec2f(i + 0.5f, j + 0.5f);
      const std::size_t n = a.add(s);
      a.preferredVelocity[n] = Vec2f(1.0f, 0.0f);
    }
  TurbulenceMetrics metrics(grid), every(grid);
  double pressureMax = 0.0;
  for (int step = 0; step < 40; ++step) {
    const float sign = step % 2 == 0 ? 1.0f : -1.0f;  // pushed to and fro: turbulent everywhere
    for (std::size_t n = 0; n < a.size(); ++n) a.velocity[n] = Vec2f(sign, 0.0f);
    metrics.sample(a, 0.05);
    every.sample(a, 0.05);
    if (step % 10 != 9) continue;
    const bool summarize = step >= 20;
    const TurbulenceFrame f = metrics.measure(a, summarize), g = every.measure(a);
    EXPECT_EQ(f.temporalPressureMax, g.temporalPressureMax);
    pressureMax = std::max(pressureMax, double(f.temporalPressureMax));
    if (summarize) continue;
    for (const long c : metrics.samplesByDensity().cells) ASSERT_EQ(c, 0);
    EXPECT_EQ(*std::max_element(metrics.peakTemporalPressure().data().begin(), metrics.peakTemporalPressure().data().end()),
              0.0f);
  }
  long cells = 0, everyCells = 0, agents = 0;
  for (std::size_t b = 0; b < metrics.samplesByDensity().cells.size(); ++b) {
    cells += metrics.samplesByDensity().cells[b];
    everyCells += every.samplesByDensity().cells[b];
    agents += metrics.samplesByDensity().agents[b];
  }
  EXPECT_EQ(cells, 2 * grid.cellCount());  // the frames at steps 29 and 39
  EXPECT_EQ(everyCells, 4 * grid.cellCount());
  EXPECT_EQ(agents, 2 * static_cast<long>(a.size()));
  EXPECT_GT(pressureMax, TurbulenceMetrics::kTurbulentPressure);
  EXPECT_GT(*std::max_element(metrics.peakTemporalPressure().data().begin(), metrics.peakTemporalPressure().data().end()),
            0.0f);
}
