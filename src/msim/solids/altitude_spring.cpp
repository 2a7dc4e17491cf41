#include "msim/solids/altitude_spring.hpp"

#include <cmath>

#include <Eigen/Geometry>

namespace msim::solids {

namespace {

// The vertex and face of point/face candidate i, and the two edges of edge/edge candidates.
constexpr std::array<std::array<int, 3>, 4> kFaces = {{{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}}};
constexpr std::array<std::array<int, 4>, 3> kEdgePairs = {{{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2}}};
// (sum_i w_i x_i) . (u x v) = sign 6 V for every candidate (a triple product of the vertices;
// the sign follows the permutation of the vertex order), so n = sign (u x v) / |u x v| measures
// the altitude 6 V / |u x v| with V's sign: an inverted tetrahedron has a negative altitude.
constexpr std::array<double, 7> kSign = {-1.0, 1.0, -1.0, 1.0, 1.0, -1.0, 1.0};

// Candidate c's u x v (not normalised) and, given the normal, the weights of its feet.
Vec3 candidateCross(const std::array<Vec3, 4>& x, int c) {
  if (c < 4) {
    const auto& f = kFaces[static_cast<std::size_t>(c)];
    return (x[f[1]] - x[f[0]]).cross(x[f[2]] - x[f[0]]);
  }
  const auto& e = kEdgePairs[static_cast<std::size_t>(c - 4)];
  return (x[e[1]] - x[e[0]]).cross(x[e[3]] - x[e[2]]);
}

double signedVolume6(const std::array<Vec3, 4>& x) { return (x[1] - x[0]).cross(x[2] - x[0]).dot(x[3] - x[0]); }

}  // namespace

double candidateAltitude(const std::array<Vec3, 4>& x, int c) {
  const double cross = candidateCross(x, c).norm();
  return cross > 0.0 ? signedVolume6(x) / cross : 0.0;
}

AltitudeChoice chooseAltitude(const std::array<Vec3, 4>& x) {
  AltitudeChoice choice;
  double best = 0.0;
  Vec3 bestCross = Vec3::Zero();
  for (int c = 0; c < 7; ++c) {
    const Vec3 cross = candidateCross(x, c);
    if (cross.squaredNorm() > best) {
      best = cross.squaredNorm();
      bestCross = cross;
      choice.candidate = c;
    }
  }
  // Relative to the tetrahedron's size: a collapse to a line or point has no altitude to restore.
  double scale = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) scale = std::max(scale, (x[j] - x[i]).squaredNorm());
  if (choice.candidate < 0 || !(best > 1e-24 * scale * scale)) return AltitudeChoice{};
  const int c = choice.candidate;
  const Vec3 n = kSign[static_cast<std::size_t>(c)] * bestCross / std::sqrt(best);
  if (c < 4) {
    const auto& f = kFaces[static_cast<std::size_t>(c)];
    // Barycentric weights of the vertex's projection onto the face (areas measured along n).
    const Vec3 p = x[c] - (x[c] - x[f[0]]).dot(n) * n;
    const Vec3 a = x[f[0]], b = x[f[1]], d = x[f[2]];
    const double area = (b - a).cross(d - a).dot(n);
    const double w0 = (b - p).cross(d - p).dot(n) / area, w1 = (d - p).cross(a - p).dot(n) / area;
    choice.weights[static_cast<std::size_t>(c)] = 1.0;
    choice.weights[static_cast<std::size_t>(f[0])] = -w0;
    choice.weights[static_cast<std::size_t>(f[1])] = -w1;
    choice.weights[static_cast<std::size_t>(f[2])] = -(1.0 - w0 - w1);
  } else {
    const auto& e = kEdgePairs[static_cast<std::size_t>(c - 4)];
    // The closest points of the two lines: x_e0 + s u and x_e2 + t v.
    const Vec3 u = x[e[1]] - x[e[0]], v = x[e[3]] - x[e[2]], w = x[e[0]] - x[e[2]];
    const double uu = u.dot(u), uv = u.dot(v), vv = v.dot(v), uw = u.dot(w), vw = v.dot(w);
    const double denominator = uu * vv - uv * uv;  // = |u x v|^2 > 0
    const double s = (uv * vw - vv * uw) / denominator, t = (uu * vw - uv * uw) / denominator;
    choice.weights[static_cast<std::size_t>(e[0])] = 1.0 - s;
    choice.weights[static_cast<std::size_t>(e[1])] = s;
    choice.weights[static_cast<std::size_t>(e[2])] = -(1.0 - t);
    choice.weights[static_cast<std::size_t>(e[3])] = -t;
  }
  Vec3 altitudeVector = Vec3::Zero();
  for (int i = 0; i < 4; ++i) altitudeVector += choice.weights[static_cast<std::size_t>(i)] * x[i];
  choice.normal = n;
  choice.altitude = altitudeVector.dot(n);
  return choice;
}

}  // namespace msim::solids
