#pragma once
// Simple 2D charts as PNG images, with no plotting dependency: axes with "nice" ticks (1, 2, 5
// times a power of ten) and numeric labels, axis titles, a legend, and series drawn as lines,
// markers and vertical error bars. Text uses a built-in 5x7 bitmap font (plot_font.hpp).
// Used for fundamental diagrams (speed against density) and time series of crowd runs.
#include <optional>
#include <string>
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/io/png.hpp"

namespace msim::render {

struct PlotSeries {
  std::string name;               // legend entry; series with an empty name are left out of it
  std::vector<double> x, y;       // same size, finite
  std::vector<double> yError;     // empty, or one half-length per point (drawn y +- e); >= 0
  Vec3 colour = Vec3(0.0, 0.3, 0.7);  // sRGB in [0, 1]
  bool line = true;               // join consecutive points
  bool markers = false;           // a filled square of side 2 markerRadius + 1 at each point
  int markerRadius = 2;           // [pixels]
  int lineWidth = 1;              // [pixels], 1 to 5
};

struct Plot {
  int width = 800, height = 500;  // [pixels]
  std::string title, xLabel, yLabel;
  std::vector<PlotSeries> series;
  // Axis ranges; each bound left empty is found from the data (with the range widened to whole
  // ticks).
  std::optional<double> xMin, xMax, yMin, yMax;
  bool legend = true;
  int fontScale = 2;  // each font pixel drawn as fontScale x fontScale image pixels, 1 to 8
  // The axes box in pixels from the image edges: data (xMin, yMin) maps to the pixel
  // (marginLeft, height - 1 - marginBottom), (xMax, yMax) to (width - 1 - marginRight, marginTop).
  int marginLeft = 100, marginRight = 20, marginTop = 40, marginBottom = 70;
};

// Default colours for series k (a qualitative palette of distinct hues).
Vec3 plotColour(int k);

// std::invalid_argument naming the series and the index for non-finite data, mismatched sizes,
// negative error bars, an empty or inverted range, or margins that leave no room to draw.
io::Image renderPlot(const Plot& plot);

}  // namespace msim::render
