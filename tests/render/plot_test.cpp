// The PNG chart: size, axes and data where the documented layout puts them, the bitmap font, and
// rejection of bad data.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <string>

#include "expect_invalid.hpp"
#include "msim/render/plot.hpp"
#include "msim/render/plot_font.hpp"

namespace msim::render {
namespace {

bool isColour(const io::Image& image, int x, int y, int r, int g, int b) {
  const std::uint8_t* p = image.pixel(x, y);
  return p[0] == r && p[1] == g && p[2] == b;
}

// 0..10 by 0..5 over a 600 x 400 image with margins 100/20/40/70: the axes box spans x in
// [100, 579] and y in [40, 329].
Plot fixedPlot() {
  Plot plot;
  plot.width = 600;
  plot.height = 400;
  plot.xMin = 0.0, plot.xMax = 10.0, plot.yMin = 0.0, plot.yMax = 5.0;
  plot.legend = false;
  plot.title = "Test (1/m^2)";
  plot.xLabel = std::string("x");  // move-assigned: GCC 12 -O3 warns falsely (-Wrestrict) on char* assignment
  plot.yLabel = std::string("y");
  return plot;
}

TEST(Plot, ImageSizeAndAxesBox) {
  const io::Image image = renderPlot(fixedPlot());
  EXPECT_EQ(image.width, 600);
  EXPECT_EQ(image.height, 400);
  for (int y = 40; y <= 329; ++y) {
    EXPECT_TRUE(isColour(image, 100, y, 0, 0, 0)) << y;
    EXPECT_TRUE(isColour(image, 579, y, 0, 0, 0)) << y;
  }
  for (int x = 100; x <= 579; ++x) {
    EXPECT_TRUE(isColour(image, x, 329, 0, 0, 0)) << x;
    EXPECT_TRUE(isColour(image, x, 40, 0, 0, 0)) << x;
  }
  // A tick mark below the x axis at x = 0 and none halfway between ticks (step 2 over 0..10).
  EXPECT_TRUE(isColour(image, 100, 332, 0, 0, 0));
  EXPECT_TRUE(isColour(image, 100 + 479 / 20, 332, 255, 255, 255));
}

TEST(Plot, MarkersAndLinesLandWhereTheDataMapsTo) {
  Plot plot = fixedPlot();
  PlotSeries dots;
  dots.x = {2.5, 7.5};
  dots.y = {1.25, 3.75};
  dots.colour = Vec3(1, 0, 0);
  dots.line = false;
  dots.markers = true;
  dots.markerRadius = 2;
  PlotSeries line;
  line.x = {1.0, 9.0};
  line.y = {2.5, 2.5};
  line.colour = Vec3(0, 0, 1);
  plot.series = {dots, line};
  const io::Image image = renderPlot(plot);
  // x -> 100 + x / 10 * 479, y -> 329 - y / 5 * 289, rounded.
  const int x0 = static_cast<int>(std::lround(100 + 0.25 * 479)), y0 = static_cast<int>(std::lround(329 - 0.25 * 289));
  const int x1 = static_cast<int>(std::lround(100 + 0.75 * 479)), y1 = static_cast<int>(std::lround(329 - 0.75 * 289));
  for (int d : {-2, 0, 2}) {
    EXPECT_TRUE(isColour(image, x0 + d, y0 + d, 255, 0, 0));
    EXPECT_TRUE(isColour(image, x1 - d, y1 + d, 255, 0, 0));
  }
  EXPECT_FALSE(isColour(image, x0 + 3, y0, 255, 0, 0));
  const int yLine = static_cast<int>(std::lround(329 - 0.5 * 289));
  for (double x : {1.0, 5.0, 9.0}) EXPECT_TRUE(isColour(image, static_cast<int>(std::lround(100 + x / 10 * 479)), yLine, 0, 0, 255)) << x;
  EXPECT_FALSE(isColour(image, static_cast<int>(std::lround(100 + 0.5 / 10 * 479)), yLine, 0, 0, 255));
}

TEST(Plot, AutoRangeCoversTheData) {
  Plot plot = fixedPlot();
  plot.xMin.reset(), plot.xMax.reset(), plot.yMin.reset(), plot.yMax.reset();
  PlotSeries s;
  s.x = {0.0, 10.0};
  s.y = {0.0, 5.0};
  s.colour = Vec3(0, 1, 0);
  s.line = false;
  s.markers = true;
  plot.series = {s};
  // The data range 0..10 x 0..5 is already whole ticks, so the corners are the extreme points.
  const io::Image image = renderPlot(plot);
  EXPECT_TRUE(isColour(image, 102, 327, 0, 255, 0));
  EXPECT_TRUE(isColour(image, 577, 42, 0, 255, 0));
}

TEST(Plot, RejectsNonFiniteAndMismatchedData) {
  Plot plot = fixedPlot();
  PlotSeries s;
  s.name = "speed";
  s.x = {1.0, std::numeric_limits<double>::quiet_NaN()};
  s.y = {1.0, 2.0};
  plot.series = {s};
  expectInvalidArgument([&] { renderPlot(plot); }, "speed");
  expectInvalidArgument([&] { renderPlot(plot); }, "non-finite");
  plot.series[0].x = {1.0, 2.0};
  plot.series[0].y = {1.0, std::numeric_limits<double>::infinity()};
  expectInvalidArgument([&] { renderPlot(plot); }, "non-finite");
  plot.series[0].y = {1.0};
  expectInvalidArgument([&] { renderPlot(plot); }, "differ in size");
  plot.series.clear();
  plot.xMax = 0.0;
  expectInvalidArgument([&] { renderPlot(plot); }, "range");
}

TEST(PlotFont, GlyphsAreDistinctAndCoverTheLabelCharacters) {
  const std::string chars = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz.-/^()%+:,=_";
  std::set<std::string> bitmaps;
  for (char c : chars) {
    std::string bits;
    for (int row = 0; row < font::kGlyphHeight; ++row)
      for (int col = 0; col < font::kGlyphWidth; ++col) bits += font::ink(c, col, row) ? '#' : '.';
    EXPECT_NE(bits.find('#'), std::string::npos) << c;
    bitmaps.insert(bits);
  }
  EXPECT_EQ(bitmaps.size(), chars.size());
  EXPECT_TRUE(font::ink('1', 2, 0));
  EXPECT_FALSE(font::ink(' ', 2, 3));
  EXPECT_EQ(font::textWidth("ab", 2), 22);
}

}  // namespace
}  // namespace msim::render
