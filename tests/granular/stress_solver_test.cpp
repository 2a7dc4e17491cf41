// The granular stress solve (Narain 2011 ch. 5.3, 5.5) on hand-built grid states, against
// closed forms: hydrostatic pressure in a resting column, Coulomb friction of a sliding block,
// no tension in diverging flow, the volume-fraction bound in converging flow, and a body
// carried by the material's pressure.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "msim/granular/stress_solver.hpp"

using namespace msim;
using namespace msim::granular;

namespace {

constexpr double kSolverRho = 1500.0, kSolverG = 9.81, kSolverDx = 0.1, kSolverDt = 0.01;

// A closed box of res cells, material (phi = 1, rho) in the cells of [lo, hi). A face beside
// material counts as full (phi = 1): with the mean of the two cells, phi v would carry half the
// flux out of a packed cell's leading face, and uniform motion would appear to compress it.
GranularGridState block(const IVec3& res, const IVec3& lo, const IVec3& hi, double alpha) {
  GranularGridState st;
  st.spec = GridSpec<3>(Vec3::Zero(), kSolverDx, res);
  const std::size_t n = st.spec.cellCount();
  st.phi.assign(n, 0.0);
  st.alpha.assign(n, alpha);
  auto cellPhi = [&](const IVec3& c) {
    for (int a = 0; a < 3; ++a)
      if (c[a] < lo[a] || c[a] >= hi[a]) return 0.0;
    return 1.0;
  };
  for (int k = 0; k < res[2]; ++k)
    for (int j = 0; j < res[1]; ++j)
      for (int i = 0; i < res[0]; ++i) st.phi[(static_cast<std::size_t>(k) * res[1] + j) * res[0] + i] = cellPhi({i, j, k});
  st.phiFace = FaceField(res);
  st.rhoFace = FaceField(res);
  st.open = FaceField(res, 1.0);
  for (int a = 0; a < 3; ++a) {
    const IVec3 fn = st.open.size(a);
    for (int k = 0; k < fn[2]; ++k)
      for (int j = 0; j < fn[1]; ++j)
        for (int i = 0; i < fn[0]; ++i) {
          const IVec3 f(i, j, k);
          IVec3 below = f;
          below[a] -= 1;
          const std::size_t idx = st.open.index(a, f);
          if (f[a] == 0 || f[a] == res[a]) st.open.values[a][idx] = 0.0;  // domain walls
          const double phi = std::max(cellPhi(f), cellPhi(below));
          st.phiFace.values[a][idx] = phi;
          st.rhoFace.values[a][idx] = phi > 0.0 ? kSolverRho : 0.0;
        }
  }
  return st;
}

GranularGridState column(const IVec3& res, int height, double alpha) {
  return block(res, IVec3::Zero(), IVec3(res[0], height, res[2]), alpha);
}

// The predicted velocity with gravity on every open face that has material, plus `vx` along x.
FaceField predicted(const GranularGridState& st, double vx) {
  FaceField v(st.spec.res);
  for (int a = 0; a < 3; ++a)
    for (std::size_t i = 0; i < v.values[a].size(); ++i)
      if (st.open.values[a][i] != 0.0 && st.rhoFace.values[a][i] > 0.0)
        v.values[a][i] = a == 1 ? -kSolverG * kSolverDt : (a == 0 ? vx : 0.0);
  return v;
}

double maxAbs(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

}  // namespace

TEST(GranularStress, RestingColumnIsHydrostatic) {
  const IVec3 res(6, 12, 6);
  const int height = 8;
  GranularGridState st = column(res, height, 0.0);
  StressSolver solver(StressSolverSettings{.staggeredIterations = 2, .friction = false});
  FaceField v = predicted(st, 0.0);
  solver.solve(st, kSolverDt, v, {});
  // Gravity is held: the material does not move into the floor or compress.
  for (int a = 0; a < 3; ++a) EXPECT_LT(maxAbs(v.values[a]), 1e-3 * kSolverG * kSolverDt) << "axis " << a;
  // p rises by rho g dx per cell downwards, and p >= 0 everywhere.
  const std::vector<double>& p = solver.pressure();
  for (double x : p) EXPECT_GE(x, 0.0);
  for (int j = 0; j + 1 < height; ++j) {
    const std::size_t lo = (static_cast<std::size_t>(2) * res[1] + j) * res[0] + 2;
    const std::size_t hi = lo + static_cast<std::size_t>(res[0]);
    EXPECT_NEAR(p[lo] - p[hi], kSolverRho * kSolverG * kSolverDx, 1e-3 * kSolverRho * kSolverG * kSolverDx) << "row " << j;
  }
}

// A packed block in rows 2..9 of a 4 x 12 x 4 box pulled apart: faces with material in the upper
// half move up at 1 m/s, those in the lower half down.
struct PulledApartBlock {
  IVec3 res{4, 12, 4};
  GranularGridState st;
  FaceField v{res};
  explicit PulledApartBlock(double alpha) : st(block(res, IVec3(0, 2, 0), IVec3(4, 10, 4), alpha)) {
    for (std::size_t i = 0; i < v.values[1].size(); ++i) {
      const int j = static_cast<int>(i / res[0] % (res[1] + 1));
      if (st.open.values[1][i] != 0.0 && st.rhoFace.values[1][i] > 0.0) v.values[1][i] = j >= res[1] / 2 ? 1.0 : -1.0;
    }
  }
};

TEST(GranularStress, DivergingFlowFeelsNoPressure) {
  // No cohesion: material pulled apart keeps its velocity; an incompressible fluid would be held
  // together.
  PulledApartBlock pulled(0.5);
  const GranularGridState& st = pulled.st;
  FaceField& v = pulled.v;
  const FaceField before = v;
  StressSolver solver;
  solver.solve(st, kSolverDt, v, {});
  EXPECT_EQ(maxAbs(solver.pressure()), 0.0);
  for (std::size_t i = 0; i < v.values[1].size(); ++i) EXPECT_DOUBLE_EQ(v.values[1][i], before.values[1][i]);
}

TEST(GranularStress, BilateralMaterialIsHeldTogetherLikeALiquid) {
  // The same pull as above with the bilateral (liquid) constraint: the material resists the
  // expansion with negative pressure, and div(phi v) vanishes in every full cell: the column
  // moves as one, with the mean of the face velocities it had (momentum is conserved; the faces
  // of the material, 2..10, carry 4 x -1 and 5 x +1, so 1/9 m/s).
  PulledApartBlock pulled(0.0);
  const GranularGridState& st = pulled.st;
  FaceField& v = pulled.v;
  StressSolver solver(StressSolverSettings{.friction = false, .tolerance = 1e-8, .bilateral = true});
  solver.solve(st, kSolverDt, v, {});
  const std::vector<double>& p = solver.pressure();
  EXPECT_LT(*std::min_element(p.begin(), p.end()), 0.0);
  for (int j = 2; j < 10; ++j) {
    const std::size_t lo = st.open.index(1, IVec3(1, j, 1)), hi = st.open.index(1, IVec3(1, j + 1, 1));
    EXPECT_NEAR(v.values[1][hi], v.values[1][lo], 1e-5) << "row " << j;  // div v = 0 in the full cell
    EXPECT_NEAR(v.values[1][hi], 1.0 / 9.0, 1e-4) << "row " << j;
  }
}

TEST(GranularStress, ConvergingFlowStopsAtTheDensityBound) {
  // Packed material squeezed from both sides: after the step phi^{n+1} = phi - dt div(phi v) <= 1.
  const IVec3 res(10, 4, 4);
  GranularGridState st = column(res, 4, 0.0);
  FaceField v(res);
  for (std::size_t i = 0; i < v.values[0].size(); ++i) {
    const int fi = static_cast<int>(i % (res[0] + 1));
    if (st.open.values[0][i] != 0.0) v.values[0][i] = fi < res[0] / 2 ? 2.0 : -2.0;
  }
  StressSolver solver(StressSolverSettings{.friction = false});
  solver.solve(st, kSolverDt, v, {});
  // Net flux into each cell <= its free volume (zero here).
  for (int i = 0; i < res[0]; ++i) {
    const std::size_t lo = st.open.index(0, IVec3(i, 1, 1)), hi = st.open.index(0, IVec3(i + 1, 1, 1));
    const double phiNext = 1.0 - kSolverDt * (v.values[0][hi] - v.values[0][lo]) / kSolverDx;
    EXPECT_LE(phiNext, 1.0 + 1e-4) << "cell " << i;
  }
  EXPECT_GT(solver.stats().activePressureCells, 0);
  for (double x : solver.pressure()) EXPECT_GE(x, 0.0);
}

// A long low block of packed material sliding along the floor of a wide box. Its ends are free
// vertical faces, which a cohesionless material cannot hold: they slump, so the measurements
// are taken in the middle, more than the slumping zone away from either end.
struct SlidingBlock {
  IVec3 res{32, 5, 4};
  int height = 3;
  double alpha = 0.4;
  GranularGridState st = block(res, IVec3(4, 0, 0), IVec3(28, height, res[2]), alpha);
  StressSolver solver{StressSolverSettings{.staggeredIterations = 4}};

  // Solves one step from a uniform x velocity v0 (after a step at rest to warm up the pressure:
  // a step's first friction solve uses the last step's p); returns the block's mean x velocity.
  double step(double v0) {
    FaceField warm = predicted(st, 0.0);
    solver.solve(st, kSolverDt, warm, {});
    FaceField v = predicted(st, v0);
    solver.solve(st, kSolverDt, v, {});
    double sum = 0.0;
    int count = 0;
    for (int k = 0; k < res[2]; ++k)
      for (int j = 0; j < height; ++j)
        for (int i = 13; i <= 19; ++i, ++count) sum += v.values[0][st.open.index(0, IVec3(i, j, k))];
    return sum / count;
  }
};

TEST(GranularStress, SlowBlockIsStoppedByStaticFriction) {
  // Coulomb friction can remove up to dt alpha p per unit floor area per step: a block slower
  // than about dt alpha g stops within one step (v0 = 0.01 m/s against 0.04 m/s here).
  SlidingBlock b;
  EXPECT_LT(std::abs(b.step(0.01)), 1e-4);
}

TEST(GranularStress, FastBlockSlidesWithFrictionAtItsBound) {
  // A fast block slows down but keeps sliding, and the floor friction under it is at its bound
  // |s_xy| = alpha p (kinetic Coulomb friction of eq. 5.15).
  SlidingBlock b;
  const double v0 = 1.0;
  const double v1 = b.step(v0);
  EXPECT_LT(v1, v0);
  EXPECT_GT(v1, 0.9 * v0);
  // Deceleration of a rigid block from the floor (alpha p_0) and the two z walls (alpha p_j over
  // its sides), within 10%.
  const std::vector<double>& p = b.solver.pressure();
  auto pAt = [&](int i, int j, int k) { return p[(static_cast<std::size_t>(k) * b.res[1] + j) * b.res[0] + i]; };
  double sides = 0.0;
  for (int j = 0; j < b.height; ++j) sides += pAt(16, j, 0) * kSolverDx;
  const double width = b.res[2] * kSolverDx, depth = b.height * kSolverDx;
  const double decel = b.alpha * (pAt(16, 0, 1) * width + 2.0 * sides) / (kSolverRho * width * depth);
  EXPECT_NEAR(v0 - v1, kSolverDt * decel, 0.1 * kSolverDt * decel);
  // The floor edges under the middle of the block carry s_xy = alpha p (the floor row's face gets
  // -s_xy / dx: opposing +x motion), with
  // p the pressure iterate before the last one (the staggered projections solve friction first):
  // within 10% of the final p.
  const std::vector<double>& sxy = b.solver.stress(StressComponent::OffDiagonal(0, 1));
  const IVec3 lattice = latticeSize(StressComponent::OffDiagonal(0, 1), b.res);
  for (int i = 14; i <= 18; ++i) {
    const double s = sxy[(static_cast<std::size_t>(1) * lattice[1] + 0) * lattice[0] + i];
    const double bound = b.alpha * 0.5 * (pAt(i - 1, 0, 1) + pAt(i, 0, 1));
    EXPECT_GT(s, 0.0) << "edge " << i;
    EXPECT_NEAR(std::abs(s), bound, 0.1 * bound) << "edge " << i;
  }
}
