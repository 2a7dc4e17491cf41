#include "msim/render/floor_plan.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "msim/core/parallel.hpp"

namespace msim::render {

namespace {

// Even-odd rule: the ray towards +x crosses the polygon's edges an odd number of times inside.
bool insidePolygon(const std::vector<Vec2>& poly, const Vec2& p) {
  bool inside = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
      inside = !inside;
  }
  return inside;
}

std::uint8_t toSrgbByte(double linear) {
  const double v = std::clamp(linear, 0.0, 1.0);
  const double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  return static_cast<std::uint8_t>(std::lround(s * 255.0));
}

}  // namespace

Vec3 colourMap(double t) {
  static const std::array<Vec3, 5> anchors = {Vec3(0.070, 0.004, 0.085), Vec3(0.048, 0.121, 0.330),
                                              Vec3(0.017, 0.343, 0.323), Vec3(0.217, 0.631, 0.075),
                                              Vec3(0.976, 0.815, 0.010)};
  const double x = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * (anchors.size() - 1);
  const std::size_t i = std::min<std::size_t>(static_cast<std::size_t>(x), anchors.size() - 2);
  const double f = x - static_cast<double>(i);
  return (1.0 - f) * anchors[i] + f * anchors[i + 1];
}

void FloorPlan::validate() const {
  if (!(hi.x() > lo.x()) || !(hi.y() > lo.y()) || !lo.allFinite() || !hi.allFinite())
    throw std::invalid_argument("floor plan: the box must have hi > lo on both axes");
  if (width < 1) throw std::invalid_argument("floor plan: width must be at least 1 pixel, got " + std::to_string(width));
  if (!(valueMax > valueMin)) throw std::invalid_argument("floor plan: valueMax must exceed valueMin");
}

io::Image renderFloorPlan(const FloorPlan& plan, const Discs& discs, const std::vector<std::vector<Vec2>>& obstacles) {
  plan.validate();
  const std::size_t n = discs.centres.size();
  if (discs.radii.size() != n && discs.radii.size() != 1 && !(n == 0 && discs.radii.empty()))
    throw std::invalid_argument("floor plan: " + std::to_string(discs.radii.size()) + " radii for " +
                                std::to_string(n) + " discs (give one per disc or one for all)");
  if (!discs.values.empty() && discs.values.size() != n)
    throw std::invalid_argument("floor plan: " + std::to_string(discs.values.size()) + " values for " +
                                std::to_string(n) + " discs");
  for (double r : discs.radii)
    if (!(r > 0.0) || !std::isfinite(r)) throw std::invalid_argument("floor plan: disc radii must be positive");
  for (const Vec2& c : discs.centres)
    if (!c.allFinite()) throw std::invalid_argument("floor plan: a disc centre is not finite");

  const double pixel = (plan.hi.x() - plan.lo.x()) / plan.width;
  const int height = std::max(1, static_cast<int>(std::lround((plan.hi.y() - plan.lo.y()) / pixel)));
  auto radius = [&](std::size_t k) { return discs.radii.size() == 1 ? discs.radii[0] : discs.radii[k]; };

  // Bin discs into rows of pixels so each image row only looks at the discs that reach it.
  std::vector<std::vector<std::size_t>> rows(static_cast<std::size_t>(height));
  for (std::size_t k = 0; k < n; ++k) {
    const double r = radius(k) + pixel;
    const int top = static_cast<int>(std::floor((plan.hi.y() - (discs.centres[k].y() + r)) / pixel));
    const int bottom = static_cast<int>(std::floor((plan.hi.y() - (discs.centres[k].y() - r)) / pixel));
    for (int y = std::max(0, top); y <= std::min(height - 1, bottom); ++y) rows[static_cast<std::size_t>(y)].push_back(k);
  }

  io::Image image(plan.width, height);
  parallelFor(0, static_cast<std::size_t>(height), [&](std::size_t row) {
    for (int col = 0; col < plan.width; ++col) {
      const Vec2 p(plan.lo.x() + (col + 0.5) * pixel, plan.hi.y() - (static_cast<double>(row) + 0.5) * pixel);
      Vec3 colour = plan.floor;
      for (const auto& poly : obstacles)
        if (poly.size() >= 3 && insidePolygon(poly, p)) colour = plan.obstacle;
      // Discs in index order; each covers what is below it by the fraction of the pixel it covers,
      // taken as the clamped signed distance of the pixel centre to the edge over the pixel size.
      for (std::size_t k : rows[row]) {
        const double coverage = std::clamp(0.5 - ((p - discs.centres[k]).norm() - radius(k)) / pixel, 0.0, 1.0);
        if (coverage <= 0.0) continue;
        const Vec3 disc = discs.values.empty()
                              ? Vec3::Constant(0.35)
                              : colourMap((discs.values[k] - plan.valueMin) / (plan.valueMax - plan.valueMin));
        colour = (1.0 - coverage) * colour + coverage * disc;
      }
      std::uint8_t* px = image.pixel(col, static_cast<int>(row));
      for (int c = 0; c < 3; ++c) px[c] = toSrgbByte(colour[c]);
    }
  }, 4);
  return image;
}

}  // namespace msim::render
