// Fundamental-diagram binning (exact means and sample deviations) and Weidmann's curve.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "msim/crowd/fundamental_diagram.hpp"
#include "msim/crowd/metric_plots.hpp"
#include "msim/crowd/metrics_json.hpp"
#include "msim/render/plot.hpp"

#include <nlohmann/json.hpp>

namespace msim::crowd {
namespace {

TEST(FundamentalDiagram, WeidmannCurveLimits) {
  EXPECT_DOUBLE_EQ(weidmannSpeed(5.4), 0.0);
  EXPECT_DOUBLE_EQ(weidmannSpeed(7.0), 0.0);
  EXPECT_NEAR(weidmannSpeed(1e-3), 1.34, 1e-12);
  EXPECT_DOUBLE_EQ(weidmannSpeed(0.0), 1.34);
  // By hand: 1.34 (1 - exp(-1.913 (1 - 1/5.4))) = 1.05806.
  EXPECT_NEAR(weidmannSpeed(1.0), 1.05806, 1e-5);
  for (double rho = 0.1; rho < 5.4; rho += 0.1) EXPECT_LT(weidmannSpeed(rho + 0.05), weidmannSpeed(rho));
}

TEST(FundamentalDiagram, BinsHaveExactMeansAndSampleDeviations) {
  const std::vector<FdSample> samples = {{0.2, 1.0}, {0.4, 3.0}, {1.2, 2.0}, {7.0, 0.5}};
  const std::vector<FdBin> bins = binByDensity(samples, 1.0, 2.0);
  ASSERT_EQ(bins.size(), 2u);
  EXPECT_EQ(bins[0].count, 2u);
  EXPECT_DOUBLE_EQ(bins[0].meanSpeed, 2.0);
  EXPECT_DOUBLE_EQ(bins[0].stdSpeed, std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(bins[0].meanDensity, 0.3);
  EXPECT_DOUBLE_EQ(bins[0].densityHi, 1.0);
  EXPECT_EQ(bins[1].count, 2u);  // 7.0 is beyond maxDensity: last bin
  EXPECT_DOUBLE_EQ(bins[1].meanSpeed, 1.25);
  EXPECT_DOUBLE_EQ(bins[1].stdSpeed, std::sqrt(1.125));
  EXPECT_DOUBLE_EQ(bins[1].meanDensity, 4.1);
  const std::vector<FdBin> empty = binByDensity({}, 0.5, 1.0);
  ASSERT_EQ(empty.size(), 2u);
  EXPECT_EQ(empty[1].count, 0u);
  EXPECT_EQ(toJson(std::span<const FdBin>(bins)).size(), 2u);
  EXPECT_THROW(binByDensity(samples, 0.0, 2.0), std::invalid_argument);
  const std::vector<FdSample> negative = {{-1.0, 1.0}};
  EXPECT_THROW(binByDensity(negative, 1.0, 2.0), std::invalid_argument);
}

TEST(FundamentalDiagram, SamplesAreDensityAndSpeedPerAgent) {
  const std::vector<double> density = {1.5, 2.5};
  const std::vector<Vec2f> velocity = {Vec2f(0.6f, 0.8f), Vec2f(0.0f, -0.5f)};
  const std::vector<FdSample> s = fdSamples(density, velocity);
  EXPECT_DOUBLE_EQ(s[0].density, 1.5);
  EXPECT_NEAR(s[0].speed, 1.0, 1e-7);
  EXPECT_NEAR(s[1].speed, 0.5, 1e-7);
  EXPECT_THROW(fdSamples(std::vector<double>{1.0}, velocity), std::invalid_argument);
}

TEST(FundamentalDiagram, SpeedDensityPlotRenders) {
  std::vector<FdSample> samples;
  for (int k = 0; k < 50; ++k) samples.push_back({0.1 * k, weidmannSpeed(0.1 * k) * (0.9 + 0.004 * k)});
  const std::vector<FdBin> bins = binByDensity(samples, 0.5, 5.5);
  const render::Plot plot = speedDensityPlot(samples, bins);
  ASSERT_EQ(plot.series.size(), 3u);
  const io::Image image = render::renderPlot(plot);
  EXPECT_EQ(image.width, plot.width);
  EXPECT_EQ(image.height, plot.height);
}

}  // namespace
}  // namespace msim::crowd
