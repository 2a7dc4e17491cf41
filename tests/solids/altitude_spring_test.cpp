// Tetrahedral altitude springs (Selle ch. 5.3.4, Theorem 1): the shortest of a tetrahedron's
// seven altitudes has its feet inside the face or the edges (weights in [0, 1]), on random and on
// near-degenerate tetrahedra, so its forces stay bounded; a flattened and an inverted tetrahedron
// recover with altitude springs, while edge springs alone leave the flat one flat.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Geometry>

#include "msim/core/rng.hpp"
#include "msim/solids/altitude_spring.hpp"
#include "msim/solids/mass_spring.hpp"
#include "msim/solids/newmark.hpp"

using namespace msim;
using namespace msim::solids;

namespace {

double volume6(const std::array<Vec3, 4>& x) { return (x[1] - x[0]).cross(x[2] - x[0]).dot(x[3] - x[0]); }

// Theorem 1's guarantees for tetrahedron x: the weights of each side in [0, 1] summing to 1, the
// altitude the shortest of the seven and equal to 6 V / |u x v| along the unit normal.
void expectTheorem1(const std::array<Vec3, 4>& x, const std::string& what) {
  const AltitudeChoice a = chooseAltitude(x);
  ASSERT_GE(a.candidate, 0) << what;
  double positive = 0.0, negative = 0.0;
  for (const double w : a.weights) {
    EXPECT_GE(std::abs(w), 0.0);
    EXPECT_LE(std::abs(w), 1.0 + 1e-9) << what;
    (w >= 0.0 ? positive : negative) += w;
  }
  EXPECT_NEAR(positive, 1.0, 1e-9) << what;
  EXPECT_NEAR(negative, -1.0, 1e-9) << what;
  EXPECT_NEAR(a.normal.norm(), 1.0, 1e-12);
  Vec3 along = Vec3::Zero();
  for (int i = 0; i < 4; ++i) along += a.weights[static_cast<std::size_t>(i)] * x[i];
  EXPECT_NEAR(along.dot(a.normal), a.altitude, 1e-9 * (1.0 + std::abs(a.altitude)));
  EXPECT_NEAR(a.altitude, candidateAltitude(x, a.candidate), 1e-9 * (1.0 + std::abs(a.altitude)));
  EXPECT_GE(a.altitude * volume6(x), 0.0) << what << ": the altitude takes the volume's sign";
  for (int c = 0; c < 7; ++c) EXPECT_LE(std::abs(a.altitude), std::abs(candidateAltitude(x, c)) * (1.0 + 1e-9) + 1e-15);
}

}  // namespace

TEST(AltitudeSpring, ShortestAltitudeHasNonNegativeWeightsOnRandomTetrahedra) {
  Rng rng(7);
  for (int k = 0; k < 2000; ++k) {
    std::array<Vec3, 4> x;
    for (auto& p : x) p = Vec3(rng.uniform(), rng.uniform(), rng.uniform());
    expectTheorem1(x, "random tetrahedron " + std::to_string(k));
  }
}

TEST(AltitudeSpring, NearDegenerateTetrahedraKeepBoundedWeights) {
  Rng rng(11);
  for (int k = 0; k < 500; ++k) {
    std::array<Vec3, 4> flat, needle, sliver;
    for (int i = 0; i < 4; ++i) {
      flat[i] = Vec3(rng.uniform(), rng.uniform(), 1e-9 * rng.uniform());          // nearly coplanar
      needle[i] = Vec3(rng.uniform(), 1e-7 * rng.uniform(), 1e-7 * rng.uniform());  // nearly colinear
    }
    // A sliver: a square's corners lifted alternately by a hair.
    sliver = {Vec3(0, 0, 1e-8), Vec3(1, 0, -1e-8), Vec3(1, 1, 1e-8), Vec3(0, 1, -1e-8)};
    sliver[0] += 1e-3 * Vec3(rng.uniform(), rng.uniform(), 0.0);
    expectTheorem1(flat, "nearly flat " + std::to_string(k));
    expectTheorem1(needle, "needle " + std::to_string(k));
    expectTheorem1(sliver, "sliver " + std::to_string(k));
  }
  // Collapsed to a point: no altitude, no force.
  EXPECT_EQ(chooseAltitude({Vec3::Ones(), Vec3::Ones(), Vec3::Ones(), Vec3::Ones()}).candidate, -1);
}

namespace {

// A regular tetrahedron (edge 0.1 m, 10 g per vertex) with edge springs and, optionally, an
// altitude spring; vertex 3 is then moved to `apex` and the tetrahedron left to settle for 2 s.
double settledVolumeRatio(const Vec3& apex, bool altitude) {
  const double e = 0.1;
  MassSpringSystem tet;
  tet.gravity = Vec3::Zero();
  const std::array<Vec3, 4> rest = {Vec3(0, 0, 0), Vec3(e, 0, 0), Vec3(0.5 * e, std::sqrt(0.75) * e, 0),
                                    Vec3(0.5 * e, std::sqrt(0.75) * e / 3.0, std::sqrt(2.0 / 3.0) * e)};
  for (const Vec3& x : rest) tet.addParticle(x, 0.01);
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) tet.addSpring(i, j, 100.0, 0.2);
  if (altitude) tet.addTetrahedron({0, 1, 2, 3}, 100.0, 0.2);
  tet.x[3] = apex;
  NewmarkSettings settings;
  settings.implicitSprings = true;
  NewmarkStepper stepper(settings);
  for (int s = 0; s < 2000; ++s) stepper.step(tet, 1e-3);
  return volume6({tet.x[0], tet.x[1], tet.x[2], tet.x[3]}) / volume6(rest);
}

}  // namespace

TEST(AltitudeSpring, FlattenedAndInvertedTetrahedraRecover) {
  const double e = 0.1;
  const Vec3 centroid(0.5 * e, std::sqrt(0.75) * e / 3.0, 0.0);
  const double flat = settledVolumeRatio(centroid, true), inverted = settledVolumeRatio(centroid - Vec3(0, 0, 0.05), true);
  RecordProperty("flat_recovered", std::to_string(flat));
  RecordProperty("inverted_recovered", std::to_string(inverted));
  EXPECT_NEAR(flat, 1.0, 0.02);
  EXPECT_NEAR(inverted, 1.0, 0.02);
  // Edge springs alone: the flat tetrahedron's forces lie in its plane, so it stays flat.
  EXPECT_NEAR(settledVolumeRatio(centroid, false), 0.0, 1e-9);
}

TEST(AltitudeSpring, InvertedOrFlatRestShapeIsRefused) {
  MassSpringSystem tet;
  for (const Vec3& x : {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, -1)}) tet.addParticle(x, 1.0);
  EXPECT_THROW(tet.addTetrahedron({0, 1, 2, 3}, 1.0, 0.0), std::invalid_argument);  // negative volume
  EXPECT_NO_THROW(tet.addTetrahedron({0, 2, 1, 3}, 1.0, 0.0));
  EXPECT_THROW(tet.addTetrahedron({0, 2, 1, 1}, 1.0, 0.0), std::invalid_argument);
}
