// Open face fractions against brute-force supersampling of the face (an independent reference).
#include <gtest/gtest.h>

#include <cmath>

#include "msim/core/rng.hpp"
#include "msim/numerics/pressure/face_fractions.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

// Fraction of the unit square where the plane phi(x, y) = n.(x, y) - d is negative, by midpoint
// sampling on a fine lattice.
double sampledInside(double nx, double ny, double d) {
  constexpr int kN = 1000;
  int inside = 0;
  for (int j = 0; j < kN; ++j)
    for (int i = 0; i < kN; ++i)
      if (nx * (i + 0.5) / kN + ny * (j + 0.5) / kN - d < 0.0) ++inside;
  return double(inside) / (kN * kN);
}

}  // namespace

TEST(FaceFractions, SegmentIsExactForLinearPhi) {
  EXPECT_FLOAT_EQ(fractionInside(-1.0f, -2.0f), 1.0f);
  EXPECT_FLOAT_EQ(fractionInside(1.0f, 2.0f), 0.0f);
  EXPECT_FLOAT_EQ(fractionInside(-1.0f, 3.0f), 0.25f);
  EXPECT_FLOAT_EQ(fractionInside(3.0f, -1.0f), 0.25f);
}

TEST(FaceFractions, SquareMatchesSupersampledPlanes) {
  Rng rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const double angle = 2.0 * M_PI * rng.uniform();
    const double nx = std::cos(angle), ny = std::sin(angle);
    const double d = -0.5 + 2.0 * rng.uniform() * (std::abs(nx) + std::abs(ny)) * 0.75;
    auto phi = [&](double x, double y) { return float(nx * x + ny * y - d); };
    const float f = fractionInside(phi(0, 0), phi(1, 0), phi(0, 1), phi(1, 1));
    EXPECT_NEAR(f, sampledInside(nx, ny, d), 2e-3) << "trial " << trial;
  }
}

TEST(FaceFractions, SphereGridFacesCoverItsCrossSection) {
  // The open area of the x-faces in the plane x = 0.5 through a sphere's centre must equal the
  // plane's area minus the disc pi r^2 (to the O(h^2) error of linear phi along edges).
  const int n = 64;
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / n, IVec3::Constant(n));
  const double r = 0.3;
  const MacGrid<3> open = openFaceFractionsFromSdf<3>(spec, [&](const Vec3& x) { return (x - Vec3::Constant(0.5)).norm() - r; });
  const auto& u = open.component(0);
  double openArea = 0.0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j) openArea += u(IVec3(n / 2, j, k)) * spec.dx * spec.dx;
  EXPECT_NEAR(1.0 - openArea, M_PI * r * r, 2e-3);
  // Faces far inside the sphere are closed, faces outside fully open.
  EXPECT_EQ(u(IVec3(n / 2, n / 2, n / 2)), 0.0f);
  EXPECT_EQ(u(IVec3(2, 2, 2)), 1.0f);
}
