#include "msim/render/floor_plan.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "msim/core/parallel.hpp"

namespace msim::render {

namespace {

// Columns of one pixel row inside the polygon by the even-odd rule at the pixel centres: a centre
// is inside when the ray towards +x crosses an odd number of edges, i.e. when it lies between
// crossing 2k and 2k + 1 of the sorted crossings of the row (scanline fill, O(edges) per row).
template <typename Fill>
void fillPolygonRow(const std::vector<Vec2>& poly, double y, double x0, double pixel, int width,
                    std::vector<double>& crossings, Fill&& fill) {
  crossings.clear();
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[j];
    if ((a.y() > y) != (b.y() > y)) crossings.push_back((b.x() - a.x()) * (y - a.y()) / (b.y() - a.y()) + a.x());
  }
  std::sort(crossings.begin(), crossings.end());
  for (std::size_t k = 0; k + 1 < crossings.size(); k += 2) {
    // Centres x0 + (col + 0.5) pixel in [c_2k, c_2k+1).
    const int first = std::max(0, static_cast<int>(std::ceil((crossings[k] - x0) / pixel - 0.5)));
    const int last = std::min(width - 1, static_cast<int>(std::ceil((crossings[k + 1] - x0) / pixel - 0.5)) - 1);
    for (int col = first; col <= last; ++col) fill(col);
  }
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

io::Image renderFloorPlan(const FloorPlan& plan, const Discs& discs, const std::vector<std::vector<Vec2>>& obstacles,
                          const CellField* floorField) {
  plan.validate();
  if (floorField != nullptr && floorField->values.size() != floorField->spec.cellCount())
    throw std::invalid_argument("floor plan: " + std::to_string(floorField->values.size()) + " field values for " +
                                std::to_string(floorField->spec.cellCount()) + " cells");
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

  std::vector<Vec2> polygonLo(obstacles.size()), polygonHi(obstacles.size());
  for (std::size_t k = 0; k < obstacles.size(); ++k) {
    polygonLo[k] = Vec2::Constant(std::numeric_limits<double>::infinity());
    polygonHi[k] = -polygonLo[k];
    for (const Vec2& v : obstacles[k]) {
      polygonLo[k] = polygonLo[k].cwiseMin(v);
      polygonHi[k] = polygonHi[k].cwiseMax(v);
    }
  }

  io::Image image(plan.width, height);
  parallelFor(0, static_cast<std::size_t>(height), [&](std::size_t row) {
    const double y = plan.hi.y() - (static_cast<double>(row) + 0.5) * pixel;
    std::vector<Vec3> colours(static_cast<std::size_t>(plan.width), plan.floor);
    if (floorField != nullptr && y >= floorField->spec.origin.y() && y <= floorField->spec.upper().y())
      for (int col = 0; col < plan.width; ++col) {
        const Vec2 p(plan.lo.x() + (col + 0.5) * pixel, y);
        if (!floorField->spec.contains(p)) continue;
        const float v = floorField->values[floorField->spec.clampedCellIndex(p)];
        if (v > 0.0f) colours[static_cast<std::size_t>(col)] = colourMap((v - plan.valueMin) / (plan.valueMax - plan.valueMin));
      }
    std::vector<double> crossings;
    for (std::size_t k = 0; k < obstacles.size(); ++k)
      if (obstacles[k].size() >= 3 && y >= polygonLo[k].y() && y <= polygonHi[k].y())
        fillPolygonRow(obstacles[k], y, plan.lo.x(), pixel, plan.width, crossings,
                       [&](int col) { colours[static_cast<std::size_t>(col)] = plan.obstacle; });
    // Discs in index order; each covers what is below it by the fraction of the pixel it covers,
    // taken as the clamped signed distance of the pixel centre to the edge over the pixel size.
    for (std::size_t k : rows[row]) {
      const double r = radius(k);
      const Vec3 disc = discs.values.empty() ? Vec3::Constant(0.35)
                                             : colourMap((discs.values[k] - plan.valueMin) / (plan.valueMax - plan.valueMin));
      const double cx = discs.centres[k].x();
      const int first = std::max(0, static_cast<int>(std::floor((cx - r - pixel - plan.lo.x()) / pixel)));
      const int last = std::min(plan.width - 1, static_cast<int>(std::ceil((cx + r + pixel - plan.lo.x()) / pixel)));
      for (int col = first; col <= last; ++col) {
        const Vec2 p(plan.lo.x() + (col + 0.5) * pixel, y);
        const double coverage = std::clamp(0.5 - ((p - discs.centres[k]).norm() - r) / pixel, 0.0, 1.0);
        if (coverage > 0.0) colours[col] = (1.0 - coverage) * colours[col] + coverage * disc;
      }
    }
    for (int col = 0; col < plan.width; ++col) {
      std::uint8_t* px = image.pixel(col, static_cast<int>(row));
      for (int c = 0; c < 3; ++c) px[c] = toSrgbByte(colours[static_cast<std::size_t>(col)][c]);
    }
  }, 4);
  return image;
}

}  // namespace msim::render
