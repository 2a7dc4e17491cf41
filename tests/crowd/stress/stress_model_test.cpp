// The inter-personal stress model's laws and friction solve (Golas ch. 4.3; the seed notes' checks
// T1-T8): discomfort, friction coefficient and walking speed; splatting with the obstacle
// correction; the acceleration clamp; the friction QP's bounds, optimality and dissipation, and
// its sign: friction between sliding layers of a packed crowd slows their relative motion.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "msim/crowd/lookahead/continuum_lookahead.hpp"
#include "msim/crowd/stress/crowd_pressure.hpp"
#include "msim/crowd/stress/stress_grid.hpp"
#include "msim/crowd/stress/stress_laws.hpp"

using namespace msim;
using namespace msim::crowd;
using namespace msim::crowd::stress;

namespace {

// Agents on a square lattice of spacing a filling [x0, x1] x [y0, y1], velocities from `flow`.
template <typename Flow>
void lattice(double a, double x0, double x1, double y0, double y1, Flow&& flow, std::vector<Vec2f>& x,
             std::vector<Vec2f>& v) {
  for (double y = y0 + 0.5 * a; y < y1; y += a)
    for (double px = x0 + 0.5 * a; px < x1; px += a) {
      x.emplace_back(static_cast<float>(px), static_cast<float>(y));
      v.push_back(flow(Vec2(px, y)).template cast<float>());
    }
}

// The face momenta rho v of the grid's cell velocities, averaged onto each open face.
Eigen::VectorXd faceMomenta(const StressGrid& g) {
  const int nx = g.grid().res.x(), ny = g.grid().res.y();
  Eigen::VectorXd m = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(g.faceCount()));
  const auto cell = [&](const Grid<float, 2>& f, int i, int j) { return double(f(IVec<2>(i, j))); };
  for (int j = 0; j < ny; ++j)
    for (int i = 1; i < nx; ++i) {
      const std::size_t face = static_cast<std::size_t>(i + (nx + 1) * j);
      if (g.activeFace(face))
        m[static_cast<Eigen::Index>(face)] = 0.5 * (cell(g.density(), i - 1, j) * cell(g.velocityX(), i - 1, j) +
                                                    cell(g.density(), i, j) * cell(g.velocityX(), i, j));
    }
  const std::size_t xFaces = static_cast<std::size_t>((nx + 1) * ny);
  for (int j = 1; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const std::size_t face = xFaces + static_cast<std::size_t>(i + nx * j);
      if (g.activeFace(face))
        m[static_cast<Eigen::Index>(face)] = 0.5 * (cell(g.density(), i, j - 1) * cell(g.velocityY(), i, j - 1) +
                                                    cell(g.density(), i, j) * cell(g.velocityY(), i, j));
    }
  return m;
}

Grid<float, 2> allFree(const GridSpec<2>& spec) { return Grid<float, 2>(spec, 1.0f); }

}  // namespace

TEST(CrowdStress, T1DiscomfortIsFlatBelowCriticalSteepThenPlateaus) {
  const StressLaws laws;
  // Zero gradient below rho_crit, continuous there (the lower branch at the middle one's value).
  EXPECT_EQ(discomfort(1.0, laws), discomfort(3.49, laws));
  EXPECT_EQ(discomfortSlope(3.0, laws), 0.0);
  EXPECT_NEAR(discomfort(3.5 - 1e-9, laws), discomfort(3.5, laws), 1e-6);
  EXPECT_NEAR(discomfort(3.5, laws), 13.33 * 3.5 / std::sqrt(2.01) - 1.5, 1e-9);  // 31.41
  // Continuous at rho_yield with c3 = c1 / sqrt(eps) = 133.3: g(5.5) = 731.65.
  EXPECT_NEAR(discomfort(5.5, laws), 133.3 * 5.5 - 1.5, 1e-9);
  EXPECT_NEAR(discomfort(5.5 - 1e-10, laws), discomfort(5.5, laws), 1e-4);
  // Monotone; the slope just above yield (133.3) far below the slope just below (about 3.7e4).
  double last = discomfort(0.0, laws);
  for (double rho = 0.0; rho <= 8.0; rho += 0.001) {
    const double g = discomfort(rho, laws);
    EXPECT_GE(g, last - 1e-12) << rho;
    last = g;
  }
  EXPECT_NEAR(discomfortSlope(5.5 + 1e-6, laws), 133.3, 1e-9);
  EXPECT_NEAR(discomfortSlope(5.5 - 1e-9, laws), 3.68e4, 0.01e4);
  EXPECT_NEAR(discomfortSlope(3.5, laws), 17.6, 0.05);
  // The slope is g's derivative (central differences inside the middle branch).
  for (double rho : {3.7, 4.5, 5.2, 5.45})
    EXPECT_NEAR(discomfortSlope(rho, laws), (discomfort(rho + 1e-6, laws) - discomfort(rho - 1e-6, laws)) / 2e-6,
                1e-4 * discomfortSlope(rho, laws));
  // The literal reading: 0 below rho_crit.
  StressLaws literal;
  literal.continuousLowerBranch = false;
  EXPECT_EQ(discomfort(3.4, literal), 0.0);
}

TEST(CrowdStress, T2FrictionCoefficientRisesLinearlyBetweenCriticalAndYield) {
  const StressLaws laws;
  EXPECT_EQ(frictionCoefficient(3.4, laws), 0.0);
  EXPECT_DOUBLE_EQ(frictionCoefficient(4.5, laws), 0.375);
  EXPECT_EQ(frictionCoefficient(5.6, laws), 0.75);
  // The inscribed box: 2 b^2 + 2 b^2 = 3 alpha^2 g^2, the Drucker-Prager cone's radius.
  const double b = frictionBound(5.0, laws);
  EXPECT_NEAR(std::sqrt(4.0 * b * b), std::sqrt(3.0) * frictionCoefficient(5.0, laws) * discomfort(5.0, laws), 1e-9);
}

TEST(CrowdStress, T3WalkingSpeedIsFlooredAndNonIncreasing) {
  const lookahead::ContinuumSettings s;  // Chapter 3's f, floored at Chapter 4's 0.01 m/s
  double last = 1e9;
  for (double rho = 0.0; rho <= 12.0; rho += 0.01) {
    const double f = lookahead::continuumSpeed(rho, 1.4, s);
    EXPECT_GE(f, 0.01);
    EXPECT_LE(f, last);
    last = f;
  }
}

TEST(CrowdStress, T4SplattingKeepsEveryAgent) {
  // 2500 agents at random inside a 20 x 20 m grid of 0.5 m cells, away from its walls.
  const GridSpec<2> spec(Vec2(0.0, 0.0), 0.5, IVec<2>(40, 40));
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(1.0f, 19.0f);
  std::vector<Vec2f> x(2500), v(2500, Vec2f(1.0f, 0.0f));
  for (Vec2f& p : x) p = Vec2f(u(rng), u(rng));
  StressGrid g(spec);
  g.splat(x, v, allFree(spec));
  double mass = 0.0;
  for (std::size_t c = 0; c < g.density().count(); ++c) mass += g.density()[c] * 0.25;
  EXPECT_NEAR(mass, 2500.0, 2500.0 * 1e-6);
  for (std::size_t c = 0; c < g.density().count(); ++c) {
    if (g.density()[c] > 0.0f) {
      EXPECT_NEAR(g.velocityX()[c], 1.0f, 1e-6f);
    }
  }
}

TEST(CrowdStress, T5DiscomfortPushesAlongWallsNotIntoThem) {
  // A wall fills the columns x in [6, 8) of a 10 x 10 m grid; a dense crowd presses against it
  // from the left, sparser further away. Its covered cells take their neighbours' density, so the
  // discomfort's gradient on the faces at the wall is 0, while inside the crowd it is not.
  const GridSpec<2> spec(Vec2(0.0, 0.0), 0.5, IVec<2>(20, 20));
  Grid<float, 2> free = allFree(spec);
  for (int j = 0; j < 20; ++j)
    for (int i = 12; i < 16; ++i) free(IVec<2>(i, j)) = 0.0f;
  std::vector<Vec2f> x, v;
  lattice(0.42, 3.0, 6.0, 0.0, 10.0, [](const Vec2&) { return Vec2(1.0, 0.0); }, x, v);  // 5.7 /m^2
  lattice(0.6, 0.5, 3.0, 0.0, 10.0, [](const Vec2&) { return Vec2(1.0, 0.0); }, x, v);   // 2.8 /m^2
  StressGrid g(spec);
  g.splat(x, v, free);
  const StressLaws laws;
  MacGrid<2> gradient;
  g.discomfortGradient(laws, gradient);
  double inside = 0.0;
  for (int j = 2; j < 18; ++j) {
    EXPECT_EQ(gradient.component(0)(IVec<2>(12, j)), 0.0f) << "face at the wall, row " << j;
    EXPECT_EQ(g.density()(IVec<2>(12, j)), g.density()(IVec<2>(11, j)));
    inside = std::max(inside, std::abs(double(gradient.component(0)(IVec<2>(6, j)))));
  }
  EXPECT_GT(inside, 10.0);  // the crowd's edge at x = 3 m pushes outwards
}

TEST(CrowdStress, T6AccelerationIsClampedKeepingItsDirection) {
  std::mt19937 rng(4);
  std::normal_distribution<double> n(0.0, 10.0);
  for (int k = 0; k < 1000; ++k) {
    const Vec2 a(n(rng), n(rng));
    const Vec2 c = clampAcceleration(a, 3.0);
    EXPECT_LE(c.norm(), 3.0 * (1.0 + 1e-9));
    if (a.norm() <= 3.0) {
      EXPECT_EQ(c, a);
    }
    else EXPECT_NEAR(c.normalized().dot(a.normalized()), 1.0, 1e-12);
  }
}

TEST(CrowdStress, DivergenceOfALinearStressIsExactAndItsTransposeIsTheAdjoint) {
  // 12 x 8 cells of 0.5 m with a covered 2 x 2 block: D of s_d = a x + b y (cell centres),
  // s_o = c x + e y (corners) is (a + e, c - b) on every open face (central differences are exact
  // on linear fields) and 0 on the others; and <D s, f> = <s, D^T f> for any s and f, f taken on
  // the open faces only.
  const GridSpec<2> spec(Vec2(0.0, 0.0), 0.5, IVec<2>(12, 8));
  Grid<float, 2> free = allFree(spec);
  for (int j = 3; j < 5; ++j)
    for (int i = 5; i < 7; ++i) free(IVec<2>(i, j)) = 0.0f;
  StressGrid g(spec);
  g.splat({}, {}, free);
  const int nx = 12, ny = 8, cells = nx * ny;
  const double a = 0.7, b = -1.3, c = 2.1, e = 0.4, h = 0.5;
  Eigen::VectorXd s(cells + (nx + 1) * (ny + 1));
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) s[i + nx * j] = a * (i + 0.5) * h + b * (j + 0.5) * h;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) s[cells + i + (nx + 1) * j] = c * i * h + e * j * h;
  Eigen::VectorXd faces;
  g.divergence(s, faces);
  ASSERT_EQ(faces.size(), static_cast<Eigen::Index>(g.faceCount()));
  const std::size_t xFaces = static_cast<std::size_t>((nx + 1) * ny);
  int open = 0;
  for (std::size_t f = 0; f < g.faceCount(); ++f) {
    const double expected = !g.activeFace(f) ? 0.0 : f < xFaces ? a + e : c - b;
    EXPECT_NEAR(faces[static_cast<Eigen::Index>(f)], expected, 1e-12) << "face " << f;
    open += g.activeFace(f) ? 1 : 0;
  }
  EXPECT_EQ(open, (nx - 1) * ny + nx * (ny - 1) - 12);  // the block closes 6 x faces and 6 y faces
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 5; ++trial) {
    for (Eigen::Index k = 0; k < s.size(); ++k) s[k] = u(rng);
    Eigen::VectorXd f(faces.size()), openF(faces.size()), back;
    for (Eigen::Index k = 0; k < f.size(); ++k) {
      f[k] = u(rng);
      openF[k] = g.activeFace(static_cast<std::size_t>(k)) ? f[k] : 0.0;
    }
    g.divergence(s, faces);
    g.divergenceTranspose(f, back);
    EXPECT_NEAR(faces.dot(openF), s.dot(back), 1e-12 * (1.0 + std::abs(s.dot(back)))) << trial;
  }
}

TEST(CrowdStress, T7T8FrictionStaysInItsBoxAndDissipates) {
  // A crowd just past the critical density (4.3 /m^2 on a 0.48 m lattice, alpha = 0.3) in a
  // 12 x 12 m box with random velocities: the solve converges, every stress lies within its bound,
  // and the energy of eq. 4.12 falls step after step. (Packed at 6 /m^2 the bounds are so wide that
  // one step stops every relative motion.)
  const GridSpec<2> spec(Vec2(0.0, 0.0), 0.5, IVec<2>(24, 24));
  std::mt19937 rng(9);
  std::normal_distribution<double> n(0.0, 0.8);
  std::vector<Vec2f> x, v;
  lattice(0.48, 0.0, 12.0, 0.0, 12.0, [&](const Vec2&) { return Vec2(n(rng), n(rng)); }, x, v);
  StressGrid g(spec);
  g.splat(x, v, allFree(spec));
  const StressLaws laws;
  numerics::BoundQpSettings settings;
  settings.tolerance = 1e-6;
  settings.maxIterations = 2000;
  Eigen::VectorXd m = faceMomenta(g), change;
  double energy = m.squaredNorm() / (2.0 * laws.yield);
  for (int step = 0; step < 5; ++step) {
    const FrictionResult r = g.friction(m, 0.05, laws, settings, change);
    EXPECT_TRUE(r.qp.converged) << step;
    EXPECT_LT(r.qp.relativeProjectedGradient, 1e-4) << step;
    EXPECT_NEAR(r.energyBefore, energy, 1e-9 * energy);
    EXPECT_LT(r.energyAfter, r.energyBefore) << step;
    for (Eigen::Index k = 0; k < g.stress().size(); ++k)
      EXPECT_LE(std::abs(g.stress()[k]), g.bound()[k] * (1.0 + 1e-12)) << k;
    // The optimum, judged by the energy itself: no nearby stress within the box does better
    // (beyond the solver's tolerance).
    const double best = g.energy(m, g.stress(), 0.05, laws);
    EXPECT_NEAR(best, r.energyAfter, 1e-9 * r.energyBefore);
    std::uniform_real_distribution<double> nudge(-1.0, 1.0);
    for (int trial = 0; trial < 20; ++trial) {
      Eigen::VectorXd s = g.stress();
      for (Eigen::Index k = 0; k < s.size(); ++k)
        s[k] = std::clamp(s[k] + 0.05 * g.bound()[k] * nudge(rng), -g.bound()[k], g.bound()[k]);
      EXPECT_GE(g.energy(m, s, 0.05, laws), best - 1e-6 * r.energyBefore) << "step " << step << " trial " << trial;
    }
    m += change;
    energy = r.energyAfter;
  }
  EXPECT_LT(energy, 0.99 * faceMomenta(g).squaredNorm() / (2.0 * laws.yield));
}

TEST(CrowdStress, FrictionSlowsLayersSlidingPastEachOther) {
  // Simple shear of a packed crowd, v_x = 0.5 (y - 6) / 6 m/s: friction pulls the fast layers back
  // and the slow ones forward, and does nothing below the critical density.
  const GridSpec<2> spec(Vec2(0.0, 0.0), 0.5, IVec<2>(24, 24));
  const auto shear = [](const Vec2& p) { return Vec2(0.5 * (p.y() - 6.0) / 6.0, 0.0); };
  const StressLaws laws;
  numerics::BoundQpSettings settings;
  settings.tolerance = 1e-6;
  settings.maxIterations = 2000;
  for (const double spacing : {0.4, 0.7}) {  // 6.25 and 2.0 /m^2
    std::vector<Vec2f> x, v;
    lattice(spacing, 0.0, 12.0, 0.0, 12.0, shear, x, v);
    StressGrid g(spec);
    g.splat(x, v, allFree(spec));
    const Eigen::VectorXd m = faceMomenta(g);
    Eigen::VectorXd change;
    const FrictionResult r = g.friction(m, 0.05, laws, settings, change);
    if (spacing > 0.5) {
      EXPECT_EQ(change.norm(), 0.0);
      continue;
    }
    EXPECT_LT(r.energyAfter, 0.999 * r.energyBefore);
    // The x-momentum change, row by row in the interior: against the shear.
    for (int j = 3; j < 21; ++j) {
      if (std::abs(j - 11.5) < 2.0) continue;
      double rowChange = 0.0;
      for (int i = 3; i < 21; ++i) rowChange += change[i + 25 * j];
      EXPECT_LT(rowChange * (j - 11.5), 0.0) << "row " << j;
    }
  }
}

TEST(CrowdStress, PressureIsDensityTimesVelocityVariance) {
  // 4 agents per 1 m cell, two walking east and two west at 0.5 m/s: Var = 0.25 m^2/s^2 and
  // rho = 4 /m^2, P = 1 /s^2 in every cell; all walking alike, P = 0.
  const GridSpec<2> spec(Vec2(0.0, 0.0), 1.0, IVec<2>(6, 6));
  std::vector<Vec2f> x, v, same;
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 6; ++i)
      for (int k = 0; k < 4; ++k) {
        x.emplace_back(i + 0.2f + 0.2f * k, j + 0.5f);
        v.emplace_back(k % 2 == 0 ? 0.5f : -0.5f, 0.0f);
        same.emplace_back(0.7f, 0.1f);
      }
  Grid<float, 2> p(spec);
  CrowdWindows windows(spec, 1);
  windows.gather(x, v);
  spatialPressure(windows, p);
  for (std::size_t c = 0; c < p.count(); ++c) EXPECT_NEAR(p[c], 1.0f, 1e-5f);
  windows.gather(x, same);
  spatialPressure(windows, p);
  for (std::size_t c = 0; c < p.count(); ++c) EXPECT_NEAR(p[c], 0.0f, 1e-5f);
}
