#include "msim/solids/collision/triangle_intersection.hpp"

#include <algorithm>
#include <cfloat>
#include <climits>
#include <cmath>
#include <cstdint>
#include <span>

#include <boost/multiprecision/cpp_int.hpp>

namespace msim::solids {

namespace {

using boost::multiprecision::cpp_int;

// ---- Orientation predicates, exact for the given doubles ----

// Static error bounds relative to the determinants' permanents: Shewchuk's (7 + 56u) u for orient3d
// and (3 + 16u) u for orient2d (u = 2^-53) with a margin of more than two, plus DBL_MIN for the
// absolute error of products that underflow. Beyond the bound the double's sign is the exact sign.
constexpr double kOrient3dBound = 8.0 * DBL_EPSILON;
constexpr double kOrient2dBound = 4.0 * DBL_EPSILON;

int signOf(double v) { return (v > 0.0) - (v < 0.0); }

// Whether a difference is so small (yet non-zero) that a product of three such could underflow
// to zero. Without such differences, a zero permanent means that every term of the determinant
// has an exactly zero factor (a difference of doubles rounds to zero only when it is zero), so
// the determinant is exactly zero: the common case of coplanar cloth at rest, decided without the
// exact arithmetic.
constexpr double kUnderflowRisk = 0x1.0p-300;
template <class Derived>
bool hasUnderflowRisk(const Eigen::MatrixBase<Derived>& differences) {
  return ((differences.array() != 0.0) && (differences.array().abs() < kUnderflowRisk)).any();
}

// The doubles v_k = m_k 2^e_k (integers m_k of at most 53 bits) as integers over their smallest
// exponent: a determinant of these is the doubles' exact determinant times a positive power of two.
template <std::size_t N>
std::array<cpp_int, N> exactIntegers(const std::array<double, N>& values) {
  std::array<std::int64_t, N> mantissa{};
  std::array<int, N> exponent{};
  int smallest = INT_MAX;
  for (std::size_t k = 0; k < N; ++k) {
    int e = 0;
    mantissa[k] = static_cast<std::int64_t>(std::ldexp(std::frexp(values[k], &e), DBL_MANT_DIG));
    exponent[k] = e - DBL_MANT_DIG;
    if (mantissa[k] != 0) smallest = std::min(smallest, exponent[k]);
  }
  std::array<cpp_int, N> integers;
  for (std::size_t k = 0; k < N; ++k)
    if (mantissa[k] != 0) integers[k] = cpp_int(mantissa[k]) << static_cast<unsigned>(exponent[k] - smallest);
  return integers;
}

int orient3dExact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const auto v = exactIntegers<12>(
      {a.x(), a.y(), a.z(), b.x(), b.y(), b.z(), c.x(), c.y(), c.z(), d.x(), d.y(), d.z()});
  const cpp_int bax = v[3] - v[0], bay = v[4] - v[1], baz = v[5] - v[2];
  const cpp_int cax = v[6] - v[0], cay = v[7] - v[1], caz = v[8] - v[2];
  const cpp_int dax = v[9] - v[0], day = v[10] - v[1], daz = v[11] - v[2];
  const cpp_int det = bax * (cay * daz - caz * day) + bay * (caz * dax - cax * daz) + baz * (cax * day - cay * dax);
  return det.sign();
}

// The sign of (b - a) x (c - a) . (d - a): positive when d lies on the side that the normal of
// triangle abc (counter-clockwise) points to, zero when the four points are coplanar.
int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3 ba = b - a, ca = c - a, da = d - a;
  const double yz = ca.y() * da.z(), zy = ca.z() * da.y(), zx = ca.z() * da.x(), xz = ca.x() * da.z(),
               xy = ca.x() * da.y(), yx = ca.y() * da.x();
  const double det = ba.x() * (yz - zy) + ba.y() * (zx - xz) + ba.z() * (xy - yx);
  const double permanent = std::abs(ba.x()) * (std::abs(yz) + std::abs(zy)) +
                           std::abs(ba.y()) * (std::abs(zx) + std::abs(xz)) +
                           std::abs(ba.z()) * (std::abs(xy) + std::abs(yx));
  const double bound = kOrient3dBound * permanent + DBL_MIN;
  if (std::abs(det) > bound) return signOf(det);
  if (permanent == 0.0 && !hasUnderflowRisk(ba) && !hasUnderflowRisk(ca) && !hasUnderflowRisk(da)) return 0;
  return orient3dExact(a, b, c, d);
}

// The sign of triangle abc's area projected along axis `dropped` onto the other two (in cyclic
// order), i.e. of component `dropped` of (b - a) x (c - a).
int orient2d(const Vec3& a, const Vec3& b, const Vec3& c, int dropped) {
  const int i = (dropped + 1) % 3, j = (dropped + 2) % 3;
  const Eigen::Vector4d differences(b[i] - a[i], c[j] - a[j], b[j] - a[j], c[i] - a[i]);
  const double left = differences[0] * differences[1], right = differences[2] * differences[3];
  const double permanent = std::abs(left) + std::abs(right);
  if (std::abs(left - right) > kOrient2dBound * permanent + DBL_MIN) return signOf(left - right);
  if (permanent == 0.0 && !hasUnderflowRisk(differences)) return 0;
  const auto v = exactIntegers<6>({a[i], a[j], b[i], b[j], c[i], c[j]});
  const cpp_int det = (v[2] - v[0]) * (v[5] - v[1]) - (v[3] - v[1]) * (v[4] - v[0]);
  return det.sign();
}

// ---- Coplanar configurations ----
// When all the points of a test lie in one plane (or line, or point), the test is made in the three
// coordinate planes. Projecting keeps every intersection, and at least one projection (along an
// axis the plane is not parallel to) is one-to-one on the plane, so it also keeps every miss: the
// points meet in 3D exactly when they meet in all three projections. No projection has to be chosen
// (a choice made in floating point could pick a degenerate one), and a projection in which a
// triangle collapses to a segment is handled like any other.

// Whether r, known to be collinear with p and q in the projection along `dropped`, lies on pq there.
bool onSegment2d(const Vec3& r, const Vec3& p, const Vec3& q, int dropped) {
  for (int k = 0; k < 3; ++k)
    if (k != dropped && (r[k] < std::min(p[k], q[k]) || r[k] > std::max(p[k], q[k]))) return false;
  return true;
}

bool segmentsIntersect2d(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& s, int dropped) {
  const int rSide = orient2d(p, q, r, dropped), sSide = orient2d(p, q, s, dropped);
  const int pSide = orient2d(r, s, p, dropped), qSide = orient2d(r, s, q, dropped);
  if (rSide * sSide < 0 && pSide * qSide < 0) return true;  // a proper crossing
  // Otherwise they meet only where an endpoint lies on the other segment (collinear overlaps and
  // zero-length segments included).
  return (rSide == 0 && onSegment2d(r, p, q, dropped)) || (sSide == 0 && onSegment2d(s, p, q, dropped)) ||
         (pSide == 0 && onSegment2d(p, r, s, dropped)) || (qSide == 0 && onSegment2d(q, r, s, dropped));
}

bool segmentMeetsTriangle2d(const Vec3& p, const Vec3& q, const std::array<Vec3, 3>& t, int dropped) {
  for (int e = 0; e < 3; ++e)
    if (segmentsIntersect2d(p, q, t[e], t[(e + 1) % 3], dropped)) return true;
  // Missing the edges, the segment is inside the triangle or outside it; a triangle collapsed to a
  // segment in this projection is all edges.
  const int orientation = orient2d(t[0], t[1], t[2], dropped);
  if (orientation == 0) return false;
  for (int e = 0; e < 3; ++e)
    if (orient2d(t[e], t[(e + 1) % 3], p, dropped) == -orientation) return false;
  return true;
}

bool coplanarSegmentsIntersect(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& s) {
  return segmentsIntersect2d(p, q, r, s, 0) && segmentsIntersect2d(p, q, r, s, 1) &&
         segmentsIntersect2d(p, q, r, s, 2);
}

bool coplanarSegmentMeetsTriangle(const Vec3& p, const Vec3& q, const std::array<Vec3, 3>& t) {
  return segmentMeetsTriangle2d(p, q, t, 0) && segmentMeetsTriangle2d(p, q, t, 1) &&
         segmentMeetsTriangle2d(p, q, t, 2);
}

// ---- Segments and triangles in 3D ----

bool segmentsIntersect3d(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& s) {
  return orient3d(p, q, r, s) == 0 && coplanarSegmentsIntersect(p, q, r, s);
}

// A triangle of zero area (its vertices collinear or coincident) has a zero normal.
bool hasZeroArea(const std::array<Vec3, 3>& t) {
  return orient2d(t[0], t[1], t[2], 0) == 0 && orient2d(t[0], t[1], t[2], 1) == 0 &&
         orient2d(t[0], t[1], t[2], 2) == 0;
}

// Whether the closed segment pq meets the closed triangle t, given pSide and qSide, the orientations
// of p and q against t, and whether t has zero area (then every orientation against it is zero).
bool segmentMeetsTriangle(const Vec3& p, const Vec3& q, int pSide, int qSide, const std::array<Vec3, 3>& t,
                          bool zeroArea) {
  if (pSide * qSide > 0) return false;  // both strictly on one side of t's plane
  if (pSide == 0 && qSide == 0) {
    if (!zeroArea) return coplanarSegmentMeetsTriangle(p, q, t);
    return segmentsIntersect3d(p, q, t[0], t[1]) || segmentsIntersect3d(p, q, t[1], t[2]) ||
           segmentsIntersect3d(p, q, t[2], t[0]);
  }
  // The segment crosses t's plane at one point, which is in t exactly when the line pq passes on
  // the same side of (or through) each of t's edges.
  const int ab = orient3d(p, q, t[0], t[1]), bc = orient3d(p, q, t[1], t[2]), ca = orient3d(p, q, t[2], t[0]);
  return !((ab < 0 || bc < 0 || ca < 0) && (ab > 0 || bc > 0 || ca > 0));
}

bool allOnOneSide(const std::array<int, 3>& sides) {
  return (sides[0] > 0 && sides[1] > 0 && sides[2] > 0) || (sides[0] < 0 && sides[1] < 0 && sides[2] < 0);
}

bool allZero(const std::array<int, 3>& sides) { return sides[0] == 0 && sides[1] == 0 && sides[2] == 0; }

// ---- Broad phase: a uniform grid of axis-aligned boxes ----

struct Box {
  Vec3 lo, hi;
};

Box triangleBox(const std::vector<Vec3>& x, const std::array<int, 3>& triangle) {
  const Vec3& a = x[triangle[0]];
  const Vec3& b = x[triangle[1]];
  const Vec3& c = x[triangle[2]];
  return {a.cwiseMin(b).cwiseMin(c), a.cwiseMax(b).cwiseMax(c)};
}

std::vector<Box> triangleBoxes(const std::vector<Vec3>& x, const std::vector<std::array<int, 3>>& triangles) {
  std::vector<Box> boxes;
  boxes.reserve(triangles.size());
  for (const auto& triangle : triangles) boxes.push_back(triangleBox(x, triangle));
  return boxes;
}

bool boxesOverlap(const Box& a, const Box& b) {
  return (a.lo.array() <= b.hi.array()).all() && (b.lo.array() <= a.hi.array()).all();
}

// Cells about as large as the boxes (their mean largest side), so that a box overlaps a few cells
// and a cell holds a few boxes; coarsened until there are at most a few cells per box.
class BoxGrid {
 public:
  BoxGrid(std::span<const Box> layout, std::span<const Box> contents) {
    if (layout.empty()) return;
    origin_ = layout.front().lo;
    Vec3 top = layout.front().hi;
    double meanSide = 0.0;
    for (const Box& box : layout) {
      origin_ = origin_.cwiseMin(box.lo);
      top = top.cwiseMax(box.hi);
      meanSide += (box.hi - box.lo).maxCoeff();
    }
    meanSide /= static_cast<double>(layout.size());
    const Vec3 extent = top - origin_;
    double cellSize = std::max(meanSide, 1e-6 * extent.maxCoeff());
    const auto cellsAlong = [&](int k) {
      return cellSize > 0.0 ? std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(extent[k] / cellSize)))
                            : std::int64_t{1};
    };
    const auto maxCells = static_cast<std::int64_t>(4 * layout.size() + 64);
    while (cellsAlong(0) * cellsAlong(1) * cellsAlong(2) > maxCells) cellSize *= 2.0;
    for (int k = 0; k < 3; ++k) dims_[k] = static_cast<int>(cellsAlong(k));
    inverseCellSize_ = cellSize > 0.0 ? 1.0 / cellSize : 0.0;

    // Counting sort of (cell, box) by cell: first the counts, then the entries.
    start_.assign(static_cast<std::size_t>(dims_.prod()) + 1, 0);
    for (const Box& box : contents) forEachCell(box, [&](int cell) { ++start_[static_cast<std::size_t>(cell) + 1]; });
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    entries_.resize(static_cast<std::size_t>(start_.back()));
    std::vector<int> fill(start_.begin(), start_.end() - 1);
    for (int b = 0; b < static_cast<int>(contents.size()); ++b)
      forEachCell(contents[static_cast<std::size_t>(b)], [&](int cell) { entries_[fill[cell]++] = b; });
  }

  int cellCount() const { return static_cast<int>(start_.size()) - 1; }
  std::span<const int> boxesIn(int cell) const {
    return std::span<const int>(entries_).subspan(start_[cell], start_[cell + 1] - start_[cell]);
  }

  int cellOf(const Vec3& p) const { return index(coordinates(p)); }

  template <class Visit>
  void forEachCell(const Box& box, const Visit& visit) const {
    const IVec3 lo = coordinates(box.lo), hi = coordinates(box.hi);
    for (int k = lo.z(); k <= hi.z(); ++k)
      for (int j = lo.y(); j <= hi.y(); ++j)
        for (int i = lo.x(); i <= hi.x(); ++i) visit(index(IVec3(i, j, k)));
  }

  // A pair of overlapping boxes shares several cells; it is handled only in the one holding the
  // lowest corner of their overlap.
  bool isPairsCell(const Box& a, const Box& b, int cell) const { return cellOf(a.lo.cwiseMax(b.lo)) == cell; }

 private:
  IVec3 coordinates(const Vec3& p) const {
    IVec3 cell;
    for (int k = 0; k < 3; ++k)
      cell[k] = std::clamp(static_cast<int>(std::floor((p[k] - origin_[k]) * inverseCellSize_)), 0, dims_[k] - 1);
    return cell;
  }
  int index(const IVec3& cell) const { return (cell.z() * dims_.y() + cell.y()) * dims_.x() + cell.x(); }

  Vec3 origin_ = Vec3::Zero();
  double inverseCellSize_ = 0.0;
  IVec3 dims_ = IVec3::Ones();
  std::vector<int> start_ = {0};
  std::vector<int> entries_;
};

std::array<Vec3, 3> corners(const std::vector<Vec3>& x, const std::array<int, 3>& triangle) {
  return {x[triangle[0]], x[triangle[1]], x[triangle[2]]};
}

bool shareVertex(const std::array<int, 3>& a, const std::array<int, 3>& b) {
  for (const int i : a)
    if (i == b[0] || i == b[1] || i == b[2]) return true;
  return false;
}

}  // namespace

bool trianglesIntersect(const std::array<Vec3, 3>& t, const std::array<Vec3, 3>& u) {
  const std::array<int, 3> uSides = {orient3d(t[0], t[1], t[2], u[0]), orient3d(t[0], t[1], t[2], u[1]),
                                     orient3d(t[0], t[1], t[2], u[2])};
  if (allOnOneSide(uSides)) return false;
  const std::array<int, 3> tSides = {orient3d(u[0], u[1], u[2], t[0]), orient3d(u[0], u[1], u[2], t[1]),
                                     orient3d(u[0], u[1], u[2], t[2])};
  if (allOnOneSide(tSides)) return false;
  // A triangle with a non-zero orientation somewhere has a plane (non-zero area).
  const bool tZeroArea = allZero(uSides) && hasZeroArea(t), uZeroArea = allZero(tSides) && hasZeroArea(u);
  for (int e = 0; e < 3; ++e) {
    const int f = (e + 1) % 3;
    if (segmentMeetsTriangle(t[e], t[f], tSides[e], tSides[f], u, uZeroArea)) return true;
    if (segmentMeetsTriangle(u[e], u[f], uSides[e], uSides[f], t, tZeroArea)) return true;
  }
  return false;
}

std::size_t countSelfIntersections(const std::vector<Vec3>& x, const std::vector<std::array<int, 3>>& triangles) {
  const std::vector<Box> boxes = triangleBoxes(x, triangles);
  const BoxGrid grid(boxes, boxes);
  std::size_t count = 0;
  for (int cell = 0; cell < grid.cellCount(); ++cell) {
    const std::span<const int> inCell = grid.boxesIn(cell);
    for (std::size_t i = 0; i < inCell.size(); ++i) {
      for (std::size_t j = i + 1; j < inCell.size(); ++j) {
        const int a = inCell[i], b = inCell[j];
        if (!boxesOverlap(boxes[a], boxes[b]) || !grid.isPairsCell(boxes[a], boxes[b], cell)) continue;
        if (shareVertex(triangles[a], triangles[b])) continue;
        if (trianglesIntersect(corners(x, triangles[a]), corners(x, triangles[b]))) ++count;
      }
    }
  }
  return count;
}

std::size_t countIntersections(const std::vector<Vec3>& xA, const std::vector<std::array<int, 3>>& trianglesA,
                               const std::vector<Vec3>& xB, const std::vector<std::array<int, 3>>& trianglesB) {
  const std::vector<Box> boxesA = triangleBoxes(xA, trianglesA), boxesB = triangleBoxes(xB, trianglesB);
  std::vector<Box> both = boxesA;
  both.insert(both.end(), boxesB.begin(), boxesB.end());
  const BoxGrid grid(both, boxesA);
  std::size_t count = 0;
  for (std::size_t b = 0; b < boxesB.size(); ++b) {
    grid.forEachCell(boxesB[b], [&](int cell) {
      for (const int a : grid.boxesIn(cell)) {
        if (!boxesOverlap(boxesA[a], boxesB[b]) || !grid.isPairsCell(boxesA[a], boxesB[b], cell)) continue;
        if (trianglesIntersect(corners(xA, trianglesA[a]), corners(xB, trianglesB[b]))) ++count;
      }
    });
  }
  return count;
}

}  // namespace msim::solids
