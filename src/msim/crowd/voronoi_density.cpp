// Boost.Polygon's Voronoi diagram (Fortune's sweep with exact predicates on integer sites) gives
// each agent's Voronoi neighbours; the cells themselves are built here from the exact positions by
// half-plane clipping, which also handles the unbounded cells at the edge of the crowd.
#include "msim/crowd/voronoi_density.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include <boost/polygon/voronoi.hpp>

#include "msim/core/parallel.hpp"

namespace msim::crowd {
namespace {

// Boost.Polygon's Voronoi builder takes 32-bit integer coordinates: positions are scaled so the
// crowd's extent spans 2^31 units around its centre.
using Site = boost::polygon::point_data<std::int32_t>;
constexpr double kSiteUnits = 2147483648.0;  // 2^31

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Signed area of (triangle (0, a, b)) ∩ disc(0, r): the edge is split where it meets the circle;
// pieces inside contribute their triangle, pieces outside the circular sector they subtend.
double triangleDiscArea(const Vec2& a, const Vec2& b, double r) {
  const Vec2 d = b - a;
  const double qa = d.squaredNorm();
  if (qa == 0.0) return 0.0;
  const double qb = a.dot(d), qc = a.squaredNorm() - r * r;
  double cuts[4] = {0.0, 0.0, 0.0, 1.0};
  int n = 1;
  const double disc = qb * qb - qa * qc;
  if (disc > 0.0) {
    const double s = std::sqrt(disc);
    for (double t : {(-qb - s) / qa, (-qb + s) / qa})
      if (t > 0.0 && t < 1.0) cuts[n++] = t;
  }
  cuts[n] = 1.0;
  double area = 0.0;
  for (int k = 0; k < n; ++k) {
    const Vec2 p = a + cuts[k] * d, q = a + cuts[k + 1] * d;
    // By convexity a piece lies in the disc iff both ends do; testing the ends (with a margin
    // for the rounded cut points) also gets a segment tangent to the circle right.
    const double inside = r * r * (1.0 + 1e-9);
    if (p.squaredNorm() <= inside && q.squaredNorm() <= inside)
      area += 0.5 * cross(p, q);
    else
      area += 0.5 * r * r * std::atan2(cross(p, q), p.dot(q));
  }
  return area;
}

void requireFinite(std::span<const Vec2f> positions) {
  for (std::size_t i = 0; i < positions.size(); ++i)
    if (!positions[i].allFinite())
      throw std::invalid_argument("voronoiCells: position " + std::to_string(i) + " is not finite");
}

}  // namespace

double polygonDiscArea(const Polygon& polygon, const Vec2& centre, double radius) {
  double area = 0.0;
  const std::size_t n = polygon.size();
  for (std::size_t k = 0; k < n; ++k)
    area += triangleDiscArea(polygon.vertex(k) - centre, polygon.vertex(k + 1) - centre, radius);
  return std::abs(area);
}

Polygon clipHalfPlane(const Polygon& polygon, const Vec2& normal, double offset) {
  Polygon out;
  const std::size_t n = polygon.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Vec2& p = polygon.vertex(k);
    const Vec2& q = polygon.vertex(k + 1);
    const double sp = normal.dot(p) - offset, sq = normal.dot(q) - offset;
    if (sp <= 0.0) out.vertices.push_back(p);
    if ((sp < 0.0 && sq > 0.0) || (sp > 0.0 && sq < 0.0)) out.vertices.push_back(p + (sp / (sp - sq)) * (q - p));
  }
  return out;
}

double VoronoiCells::area(std::size_t i) const {
  return polygonDiscArea(cells[i], centres[i], cutoffRadius) / multiplicity[i];
}

VoronoiCells voronoiCells(std::span<const Vec2f> positions, const VoronoiOptions& options) {
  requireFinite(positions);
  const double r = options.cutoffRadius;
  if (!(r > 0.0) || !std::isfinite(r)) throw std::invalid_argument("voronoiCells: cutoffRadius must be > 0");
  if (options.domainLo.has_value() != options.domainHi.has_value())
    throw std::invalid_argument("voronoiCells: give both domainLo and domainHi or neither");

  VoronoiCells out;
  out.cutoffRadius = r;
  const std::size_t n = positions.size();
  out.centres.resize(n);
  for (std::size_t i = 0; i < n; ++i) out.centres[i] = positions[i].cast<double>();

  Vec2 lo = Vec2::Constant(-std::numeric_limits<double>::infinity()), hi = -lo;
  if (options.domainLo) {
    lo = *options.domainLo;
    hi = *options.domainHi;
    if (!(lo.array() < hi.array()).all()) throw std::invalid_argument("voronoiCells: empty domain box");
    for (std::size_t i = 0; i < n; ++i)
      if ((out.centres[i].array() < lo.array()).any() || (out.centres[i].array() > hi.array()).any())
        throw std::invalid_argument("voronoiCells: agent " + std::to_string(i) + " lies outside the domain box");
  }

  // One site per distinct position (to 2^-31 of the crowd's extent): sort, then group equal sites.
  Vec2 first = Vec2::Constant(std::numeric_limits<double>::infinity()), last = -first;
  for (const Vec2& x : out.centres) first = first.cwiseMin(x), last = last.cwiseMax(x);
  const Vec2 middle = 0.5 * (first + last);
  const double scale = n > 0 && (last - first).maxCoeff() > 0.0 ? kSiteUnits / (last - first).maxCoeff() : 1.0;
  std::vector<Site> sites(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 s = ((out.centres[i] - middle) * scale).array().round();  // within +-2^30
    sites[i] = Site(static_cast<std::int32_t>(s.x()), static_cast<std::int32_t>(s.y()));
  }
  std::vector<std::uint32_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<std::uint32_t>(i);
  const auto less = [&](std::uint32_t a, std::uint32_t b) {
    return std::pair(sites[a].x(), sites[a].y()) < std::pair(sites[b].x(), sites[b].y());
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<std::uint32_t> groupOf(n), groupStart;
  for (std::size_t k = 0; k < n; ++k) {
    if (k == 0 || sites[order[k]] != sites[order[k - 1]]) groupStart.push_back(static_cast<std::uint32_t>(k));
    groupOf[order[k]] = static_cast<std::uint32_t>(groupStart.size() - 1);
  }
  const std::size_t groups = groupStart.size();
  groupStart.push_back(static_cast<std::uint32_t>(n));

  std::vector<Site> groupSites(groups);
  for (std::size_t g = 0; g < groups; ++g) groupSites[g] = sites[order[groupStart[g]]];
  boost::polygon::voronoi_diagram<double> diagram;
  boost::polygon::construct_voronoi(groupSites.begin(), groupSites.end(), &diagram);

  // The Voronoi cell is the intersection of the bisector half-planes of the sites it shares an
  // edge with (its Delaunay neighbours); each edge is stored twice, once per side.
  std::vector<std::vector<std::uint32_t>> neighbours(groups);
  for (const auto& edge : diagram.edges()) {
    const auto a = static_cast<std::uint32_t>(edge.cell()->source_index());
    const auto b = static_cast<std::uint32_t>(edge.twin()->cell()->source_index());
    if (a != b) neighbours[a].push_back(b);
  }

  std::vector<Polygon> groupCells(groups);
  parallelFor(0, groups, [&](std::size_t g) {
    const Vec2& x = out.centres[order[groupStart[g]]];
    Polygon cell = rectangle((x - Vec2::Constant(r)).cwiseMax(lo), (x + Vec2::Constant(r)).cwiseMin(hi));
    for (std::uint32_t h : neighbours[g]) {
      const Vec2& y = out.centres[order[groupStart[h]]];
      cell = clipHalfPlane(cell, y - x, (y - x).dot(0.5 * (x + y)));
    }
    groupCells[g] = std::move(cell);
  }, 64);

  out.cells.resize(n);
  out.multiplicity.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t g = groupOf[i];
    out.cells[i] = groupCells[g];
    out.multiplicity[i] = static_cast<int>(groupStart[g + 1] - groupStart[g]);
  }
  return out;
}

std::vector<double> voronoiDensity(const VoronoiCells& cells) {
  std::vector<double> density(cells.centres.size());
  parallelFor(0, density.size(), [&](std::size_t i) { density[i] = 1.0 / cells.area(i); }, 256);
  return density;
}

AreaMeasurement measureArea(const VoronoiCells& cells, std::span<const Vec2f> velocities, const Polygon& area) {
  AreaMeasurement m;
  m.area = std::abs(signedArea(area));
  if (area.size() < 3 || !(m.area > 0.0) || !std::isfinite(m.area))
    throw std::invalid_argument("measureArea: the measurement area must be a polygon with positive area");
  if (!velocities.empty() && velocities.size() != cells.centres.size())
    throw std::invalid_argument("measureArea: velocities must be empty or one per agent");
  double agents = 0.0, overlapArea = 0.0, speedWeighted = 0.0;
  for (std::size_t i = 0; i < cells.centres.size(); ++i) {
    // The cell is convex and counter-clockwise (it started as a box), so M ∩ cell is M clipped to
    // the inner side of each cell edge.
    Polygon clipped = area;
    const Polygon& cell = cells.cells[i];
    for (std::size_t k = 0; k < cell.size() && clipped.size() >= 3; ++k) {
      const Vec2 p = cell.vertex(k), q = cell.vertex(k + 1);
      const Vec2 outward(q.y() - p.y(), p.x() - q.x());
      clipped = clipHalfPlane(clipped, outward, outward.dot(p));
    }
    if (clipped.size() < 3) continue;
    const double overlap = polygonDiscArea(clipped, cells.centres[i], cells.cutoffRadius) / cells.multiplicity[i];
    agents += overlap / cells.area(i);
    overlapArea += overlap;
    if (!velocities.empty()) speedWeighted += overlap * static_cast<double>(velocities[i].norm());
  }
  m.density = agents / m.area;
  m.speed = overlapArea > 0.0 ? speedWeighted / overlapArea : 0.0;
  return m;
}

}  // namespace msim::crowd
