#include "msim/render/plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include "msim/render/plot_font.hpp"

namespace msim::render {
namespace {

using Rgb = std::array<std::uint8_t, 3>;

Rgb toRgb(const Vec3& c) {
  Rgb out;
  for (int k = 0; k < 3; ++k) out[k] = static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(c[k], 0.0, 1.0)));
  return out;
}

const Rgb kBlack = {0, 0, 0}, kWhite = {255, 255, 255}, kGridGrey = {225, 225, 225};

struct Canvas {
  io::Image& image;
  int x0, y0, x1, y1;  // clip box, inclusive [pixels]

  void set(int x, int y, const Rgb& c) {
    if (x < x0 || x > x1 || y < y0 || y > y1) return;
    std::copy(c.begin(), c.end(), image.pixel(x, y));
  }
  void fill(int xa, int ya, int xb, int yb, const Rgb& c) {
    for (int y = ya; y <= yb; ++y)
      for (int x = xa; x <= xb; ++x) set(x, y, c);
  }
  // Bresenham's line with a square brush of `width` pixels; the end points are first clipped to
  // the box (Liang & Barsky 1984) so that far-off data do not cost a walk across empty space.
  void line(double ax, double ay, double bx, double by, const Rgb& c, int width = 1) {
    double t0 = 0.0, t1 = 1.0;
    const double dx = bx - ax, dy = by - ay;
    const double pad = width;
    const double p[4] = {-dx, dx, -dy, dy};
    const double q[4] = {ax - (x0 - pad), (x1 + pad) - ax, ay - (y0 - pad), (y1 + pad) - ay};
    for (int k = 0; k < 4; ++k) {
      if (p[k] == 0.0) {
        if (q[k] < 0.0) return;
      } else {
        const double t = q[k] / p[k];
        if (p[k] < 0.0) t0 = std::max(t0, t);
        else t1 = std::min(t1, t);
      }
    }
    if (t0 > t1) return;
    int xa = static_cast<int>(std::lround(ax + t0 * dx)), ya = static_cast<int>(std::lround(ay + t0 * dy));
    const int xb = static_cast<int>(std::lround(ax + t1 * dx)), yb = static_cast<int>(std::lround(ay + t1 * dy));
    const int sx = xa < xb ? 1 : -1, sy = ya < yb ? 1 : -1;
    const int ex = std::abs(xb - xa), ey = -std::abs(yb - ya);
    int err = ex + ey;
    const int lo = -(width - 1) / 2, hi = width / 2;
    while (true) {
      fill(xa + lo, ya + lo, xa + hi, ya + hi, c);
      if (xa == xb && ya == yb) break;
      const int e2 = 2 * err;
      if (e2 >= ey) {
        err += ey;
        xa += sx;
      }
      if (e2 <= ex) {
        err += ex;
        ya += sy;
      }
    }
  }
  // Text with its top-left corner at (x, y); `vertical` turns it 90 degrees counter-clockwise
  // (reading upwards), with (x, y) then its bottom-left corner.
  void text(const std::string& s, int x, int y, int scale, const Rgb& c, bool vertical = false) {
    for (std::size_t k = 0; k < s.size(); ++k)
      for (int row = 0; row < font::kGlyphHeight; ++row)
        for (int col = 0; col < font::kGlyphWidth; ++col) {
          if (!font::ink(s[k], col, row)) continue;
          const int u = (static_cast<int>(k) * font::kAdvance + col) * scale, v = row * scale;
          if (vertical)
            fill(x + v, y - u - scale + 1, x + v + scale - 1, y - u, c);
          else
            fill(x + u, y + v, x + u + scale - 1, y + v + scale - 1, c);
        }
  }
};

// 1, 2 or 5 times a power of ten, giving about `target` intervals over `span`.
double niceStep(double span, int target = 6) {
  const double raw = span / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double norm = raw / mag;
  return (norm < 1.5 ? 1.0 : norm < 3.0 ? 2.0 : norm < 7.0 ? 5.0 : 10.0) * mag;
}

// Fills the bounds not given: the data range widened to whole ticks, or +-1 around a single value.
void autoRange(std::optional<double> lo, std::optional<double> hi, double dataLo, double dataHi, double& outLo,
               double& outHi) {
  if (!(dataLo <= dataHi)) dataLo = 0.0, dataHi = 1.0;  // no data
  if (lo) dataLo = std::min(*lo, dataHi), dataHi = std::max(dataHi, *lo);
  if (hi) dataHi = std::max(*hi, dataLo), dataLo = std::min(dataLo, *hi);
  if (dataLo == dataHi) dataLo -= 1.0, dataHi += 1.0;
  const double step = niceStep(dataHi - dataLo);
  outLo = lo ? *lo : std::floor(dataLo / step) * step;
  outHi = hi ? *hi : std::ceil(dataHi / step) * step;
}

std::string tickLabel(double v, double step) {
  const int decimals = std::clamp(static_cast<int>(-std::floor(std::log10(step) + 1e-9)), 0, 9);
  if (std::abs(v) < 0.5 * step) v = 0.0;  // no "-0.0"
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, v);
  return buffer;
}

std::vector<double> ticks(double lo, double hi, double step) {
  std::vector<double> out;
  const double eps = 1e-9 * step;
  for (double k = std::ceil((lo - eps) / step); k * step <= hi + eps; k += 1.0) out.push_back(k * step);
  return out;
}

void validate(const Plot& plot) {
  const auto fail = [](const std::string& m) { throw std::invalid_argument("renderPlot: " + m); };
  if (plot.fontScale < 1 || plot.fontScale > 8) fail("fontScale must be 1 to 8");
  if (plot.marginLeft < 0 || plot.marginRight < 0 || plot.marginTop < 0 || plot.marginBottom < 0 ||
      plot.width - plot.marginLeft - plot.marginRight < 2 || plot.height - plot.marginTop - plot.marginBottom < 2)
    fail("the image is too small for its margins");
  for (const auto& bound : {plot.xMin, plot.xMax, plot.yMin, plot.yMax})
    if (bound && !std::isfinite(*bound)) fail("axis bounds must be finite");
  if ((plot.xMin && plot.xMax && !(*plot.xMin < *plot.xMax)) || (plot.yMin && plot.yMax && !(*plot.yMin < *plot.yMax)))
    fail("empty axis range");
  for (const PlotSeries& s : plot.series) {
    const std::string name = "series '" + s.name + "'";
    if (s.x.size() != s.y.size()) fail(name + ": x and y differ in size");
    if (!s.yError.empty() && s.yError.size() != s.y.size()) fail(name + ": yError must be empty or one per point");
    if (s.markerRadius < 0 || s.lineWidth < 1 || s.lineWidth > 5) fail(name + ": bad markerRadius or lineWidth");
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const double e = s.yError.empty() ? 0.0 : s.yError[i];
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]) || !std::isfinite(e))
        fail(name + ": non-finite data at index " + std::to_string(i));
      if (e < 0.0) fail(name + ": negative yError at index " + std::to_string(i));
    }
  }
}

}  // namespace

Vec3 plotColour(int k) {
  static const std::array<Vec3, 6> palette = {Vec3(0.00, 0.45, 0.70), Vec3(0.90, 0.40, 0.00),
                                              Vec3(0.00, 0.60, 0.45), Vec3(0.80, 0.20, 0.50),
                                              Vec3(0.35, 0.35, 0.35), Vec3(0.95, 0.75, 0.10)};
  return palette[static_cast<std::size_t>(k) % palette.size()];
}

io::Image renderPlot(const Plot& plot) {
  validate(plot);
  const double inf = std::numeric_limits<double>::infinity();
  double xLo = inf, xHi = -inf, yLo = inf, yHi = -inf;
  for (const PlotSeries& s : plot.series)
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const double e = s.yError.empty() ? 0.0 : s.yError[i];
      xLo = std::min(xLo, s.x[i]), xHi = std::max(xHi, s.x[i]);
      yLo = std::min(yLo, s.y[i] - e), yHi = std::max(yHi, s.y[i] + e);
    }
  double xMin, xMax, yMin, yMax;
  autoRange(plot.xMin, plot.xMax, xLo, xHi, xMin, xMax);
  autoRange(plot.yMin, plot.yMax, yLo, yHi, yMin, yMax);

  io::Image image(plot.width, plot.height);
  std::fill(image.rgb.begin(), image.rgb.end(), std::uint8_t(255));
  const int left = plot.marginLeft, right = plot.width - 1 - plot.marginRight;
  const int top = plot.marginTop, bottom = plot.height - 1 - plot.marginBottom;
  Canvas page{image, 0, 0, plot.width - 1, plot.height - 1};
  Canvas box{image, left, top, right, bottom};
  const auto px = [&](double x) { return left + (x - xMin) / (xMax - xMin) * (right - left); };
  const auto py = [&](double y) { return bottom - (y - yMin) / (yMax - yMin) * (bottom - top); };
  const int scale = plot.fontScale, glyphH = font::kGlyphHeight * scale;

  const double xStep = niceStep(xMax - xMin), yStep = niceStep(yMax - yMin);
  const std::vector<double> xTicks = ticks(xMin, xMax, xStep), yTicks = ticks(yMin, yMax, yStep);
  for (double t : xTicks) box.line(px(t), top, px(t), bottom, kGridGrey);
  for (double t : yTicks) box.line(left, py(t), right, py(t), kGridGrey);

  for (const PlotSeries& s : plot.series) {
    const Rgb c = toRgb(s.colour);
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const double x = px(s.x[i]), y = py(s.y[i]);
      if (s.line && i > 0) box.line(px(s.x[i - 1]), py(s.y[i - 1]), x, y, c, s.lineWidth);
      if (!s.yError.empty() && s.yError[i] > 0.0) {
        const double ya = py(s.y[i] - s.yError[i]), yb = py(s.y[i] + s.yError[i]);
        box.line(x, ya, x, yb, c);
        box.line(x - s.markerRadius, ya, x + s.markerRadius, ya, c);
        box.line(x - s.markerRadius, yb, x + s.markerRadius, yb, c);
      }
      if (s.markers) {
        const int cx = static_cast<int>(std::lround(x)), cy = static_cast<int>(std::lround(y));
        box.fill(cx - s.markerRadius, cy - s.markerRadius, cx + s.markerRadius, cy + s.markerRadius, c);
      }
    }
  }

  // Axes box, ticks and labels on top of the data.
  page.line(left, top, right, top, kBlack);
  page.line(left, bottom, right, bottom, kBlack);
  page.line(left, top, left, bottom, kBlack);
  page.line(right, top, right, bottom, kBlack);
  const int tickLength = 5;
  for (double t : xTicks) {
    const double x = px(t);
    page.line(x, bottom, x, bottom + tickLength, kBlack);
    const std::string label = tickLabel(t, xStep);
    page.text(label, static_cast<int>(std::lround(x)) - font::textWidth(label, scale) / 2, bottom + tickLength + 4,
              scale, kBlack);
  }
  int widestYLabel = 0;
  for (double t : yTicks) {
    const double y = py(t);
    page.line(left - tickLength, y, left, y, kBlack);
    const std::string label = tickLabel(t, yStep);
    const int w = font::textWidth(label, scale);
    widestYLabel = std::max(widestYLabel, w);
    page.text(label, left - tickLength - 4 - w, static_cast<int>(std::lround(y)) - glyphH / 2, scale, kBlack);
  }
  page.text(plot.xLabel, (left + right - font::textWidth(plot.xLabel, scale)) / 2,
            bottom + tickLength + 4 + glyphH + 2 * scale + 4, scale, kBlack);
  page.text(plot.yLabel, std::max(2, left - tickLength - 4 - widestYLabel - 6 - glyphH),
            (top + bottom + font::textWidth(plot.yLabel, scale)) / 2, scale, kBlack, true);
  page.text(plot.title, (plot.width - font::textWidth(plot.title, scale)) / 2, std::max(2, (top - glyphH) / 2), scale,
            kBlack);

  // Legend in the top-right corner of the axes box: a sample of each named series and its name.
  std::vector<const PlotSeries*> named;
  int nameWidth = 0;
  for (const PlotSeries& s : plot.series)
    if (!s.name.empty()) {
      named.push_back(&s);
      nameWidth = std::max(nameWidth, font::textWidth(s.name, scale));
    }
  if (plot.legend && !named.empty()) {
    const int pad = 6, sample = 24, rowH = glyphH + 6;
    const int w = pad + sample + pad + nameWidth + pad, h = pad + rowH * static_cast<int>(named.size()) + pad - 6;
    const int bx1 = right - 8, bx0 = bx1 - w, by0 = top + 8, by1 = by0 + h;
    box.fill(bx0, by0, bx1, by1, kWhite);
    box.line(bx0, by0, bx1, by0, kBlack);
    box.line(bx0, by1, bx1, by1, kBlack);
    box.line(bx0, by0, bx0, by1, kBlack);
    box.line(bx1, by0, bx1, by1, kBlack);
    for (std::size_t k = 0; k < named.size(); ++k) {
      const PlotSeries& s = *named[k];
      const Rgb c = toRgb(s.colour);
      const int rowTop = by0 + pad + static_cast<int>(k) * rowH, cy = rowTop + glyphH / 2, cx = bx0 + pad + sample / 2;
      if (s.line) box.line(bx0 + pad, cy, bx0 + pad + sample, cy, c, s.lineWidth);
      if (s.markers) box.fill(cx - s.markerRadius, cy - s.markerRadius, cx + s.markerRadius, cy + s.markerRadius, c);
      box.text(s.name, bx0 + pad + sample + pad, rowTop, scale, kBlack);
    }
  }
  return image;
}

}  // namespace msim::render
