// Fast-marching reinitialisation against exact distances: circles and spheres (first-order
// convergence of the band's error, the zero crossing kept), an axis-aligned plane at a sub-cell
// offset (exact), the band's clamp and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "msim/numerics/level_set/fast_marching.hpp"
#include "../unit_box.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

using msim::test::unitBox;

struct BandError {
  double maxError = 0.0;   // max |phi - exact| over cells within 3 cells of the interface [dx]
  double maxCrossing = 0.0;  // max |phi - exact| over the interface cells [dx]
  bool signsKept = true;
};

// A ball of radius R at c, given to the reinitialisation as a distorted function with the same
// zero set: (r - R)(1 + 4 (x - c_x)^2 + 2 y), whose gradient is far from unit length.
template <int D>
BandError reinitialisedBall(int n, double radius) {
  const GridSpec<D> spec = unitBox<D>(n);
  const Vec<D> centre = Vec<D>::Constant(0.51);
  Grid<float, D> phi(spec);
  Grid<float, D> exact(spec);
  for (std::size_t i = 0; i < phi.count(); ++i) {
    const Vec<D> x = phi.position(phi.coord(i));
    const double d = (x - centre).norm() - radius;
    exact[i] = static_cast<float>(d);
    phi[i] = static_cast<float>(d * (1.0 + 4.0 * (x[0] - centre[0]) * (x[0] - centre[0]) + 2.0 * x[1]));
  }
  const Grid<float, D> before = phi;
  reinitializeFastMarching(phi, 5.0);
  BandError e;
  for (std::size_t i = 0; i < phi.count(); ++i) {
    if ((before[i] < 0.0f) != (phi[i] < 0.0f)) e.signsKept = false;
    const double err = std::abs(phi[i] - exact[i]) / spec.dx;
    if (std::abs(exact[i]) < 3.0 * spec.dx) e.maxError = std::max(e.maxError, err);
    if (std::abs(exact[i]) < 0.5 * spec.dx) e.maxCrossing = std::max(e.maxCrossing, err);
  }
  return e;
}

}  // namespace

TEST(FastMarching, CircleBecomesItsDistanceAtSecondOrder) {
  const BandError coarse = reinitialisedBall<2>(64, 0.3);
  const BandError fine = reinitialisedBall<2>(128, 0.3);
  EXPECT_TRUE(coarse.signsKept);
  EXPECT_TRUE(fine.signsKept);
  // Second order: the error in cells halves with dx (in metres it quarters). Measured 0.032 and
  // 0.016 dx.
  EXPECT_LT(coarse.maxError, 0.05);
  EXPECT_LT(fine.maxError, 0.6 * coarse.maxError);
  EXPECT_LT(fine.maxCrossing, 0.02);
  RecordProperty("max_error_dx_64", std::to_string(coarse.maxError));
  RecordProperty("max_error_dx_128", std::to_string(fine.maxError));
}

TEST(FastMarching, SphereBecomesItsDistance) {
  const BandError e = reinitialisedBall<3>(48, 0.27);
  EXPECT_TRUE(e.signsKept);
  RecordProperty("max_error_dx_48", std::to_string(e.maxError));
  EXPECT_LT(e.maxError, 0.08);  // measured 0.058 dx
  EXPECT_LT(e.maxCrossing, 0.08);
}

TEST(FastMarching, AxisAlignedPlaneAtASubCellOffsetIsExact) {
  const GridSpec<3> spec = unitBox<3>(20);
  const double y0 = 0.4321;
  Grid<float, 3> phi(spec);
  for (std::size_t i = 0; i < phi.count(); ++i) phi[i] = static_cast<float>(5.0 * (phi.position(phi.coord(i))[1] - y0));
  const FastMarchingStats stats = reinitializeFastMarching(phi, 4.0);
  EXPECT_EQ(stats.interfaceCells, 2u * 20u * 20u);  // the layers on either side of the plane
  for (std::size_t i = 0; i < phi.count(); ++i) {
    const double d = phi.position(phi.coord(i))[1] - y0;
    const double expected = std::clamp(d, -4.0 * spec.dx, 4.0 * spec.dx);
    ASSERT_NEAR(phi[i], expected, 2e-6) << "cell " << i;
  }
}

TEST(FastMarching, BeyondTheBandTheSignIsKeptAtTheBandWidth) {
  const GridSpec<2> spec = unitBox<2>(50);
  Grid<float, 2> phi(spec);
  for (std::size_t i = 0; i < phi.count(); ++i) phi[i] = static_cast<float>(phi.position(phi.coord(i))[0] - 0.5);
  reinitializeFastMarching(phi, 3.0);
  EXPECT_FLOAT_EQ(phi(IVec<2>(0, 10)), static_cast<float>(-3.0 * spec.dx));
  EXPECT_FLOAT_EQ(phi(IVec<2>(49, 10)), static_cast<float>(3.0 * spec.dx));
}

TEST(FastMarching, RefusesBadInput) {
  Grid<float, 2> phi(unitBox<2>(8), 1.0f);
  EXPECT_THROW(reinitializeFastMarching(phi, 0.0), std::invalid_argument);
  phi[3] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(reinitializeFastMarching(phi, 3.0), std::invalid_argument);
}
