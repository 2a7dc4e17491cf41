// StressProblem::solve (stress_problem.hpp) restricts a QP to the samples that can move: the
// bounding box of them, or, when they fill less than half of it, the list of them with the held
// samples' products moved to the right-hand side. Either way the result must be the solution of
// the whole-lattice problem: checked here by the KKT conditions on the whole lattice, with the
// operator applied independently (the structured grid operator over every sample plus the body
// term), for held samples at nonzero values and a coupled body.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "msim/granular/stress_problem.hpp"

using namespace msim;
using namespace msim::granular;

namespace {

constexpr double kProblemDx = 0.1, kProblemDt = 0.01;

GranularGridState packedBox(const IVec3& res) {
  GranularGridState st;
  st.spec = GridSpec<3>(Vec3::Zero(), kProblemDx, res);
  st.phi.assign(st.spec.cellCount(), 1.0);
  st.alpha.assign(st.spec.cellCount(), 0.5);
  st.phiFace = FaceField(res, 1.0);
  st.rhoFace = FaceField(res, 1500.0);
  st.open = FaceField(res, 1.0);
  for (int a = 0; a < 3; ++a) {
    const IVec3 n = st.open.size(a);
    for (std::size_t i = 0; i < st.open.values[a].size(); ++i) {
      const int c = static_cast<int>(a == 0 ? i % n[0] : a == 1 ? i / n[0] % n[1] : i / n[0] / n[1]);
      if (c == 0 || c == res[a]) st.open.values[a][i] = 0.0;  // domain walls
    }
  }
  return st;
}

// Worst violation of the KKT conditions of min 1/2 x^T A x - b^T x over lo <= x <= hi, relative
// to |b|: the gradient g = A x - b must vanish where x is strictly inside, be >= 0 at a lower
// bound and <= 0 at an upper one.
double kktViolation(const StressProblem& pr, const numerics::QpOperator& a) {
  Eigen::VectorXd g(pr.x.size());
  a.apply(pr.x, g);
  g -= pr.b;
  double worst = 0.0;
  for (Eigen::Index i = 0; i < g.size(); ++i) {
    if (pr.x[i] < pr.lo[i] - 1e-12 || pr.x[i] > pr.hi[i] + 1e-12) return INFINITY;
    if (!(pr.lo[i] < pr.hi[i])) continue;
    const bool atLower = pr.x[i] <= pr.lo[i], atUpper = pr.x[i] >= pr.hi[i];
    const double v = atLower ? std::max(-g[i], 0.0) : atUpper ? std::max(g[i], 0.0) : std::abs(g[i]);
    worst = std::max(worst, v);
  }
  return worst / pr.b.norm();
}

// A friction problem on a packed box with a body in one corner; `freeShare` of the samples can
// move, the others are held at +-0.2 of their bound scale (nonzero, so that their products
// matter).
double solveAndCheck(double freeShare, unsigned seed) {
  const IVec3 res(10, 8, 6);
  const GranularGridState st = packedBox(res);
  CoupledBody body;
  body.inverseMass = Eigen::Matrix<double, 6, 6>::Identity() * 0.5;
  body.centre = Vec3(0.25, 0.25, 0.25);
  body.cover(res, LatticeBox::whole(res));
  for (int a = 0; a < 3; ++a)
    for (std::size_t i = 0; i < body.faceFraction[a].size(); i += 7) body.faceFraction[a][i] = 0.5;

  StressProblem pr;
  pr.terms = {{StressComponent::OffDiagonal(0, 1), 1.0}};
  FaceField weight(res, 1.0 / 1500.0);
  std::vector<std::vector<BodyFace>> faces(1);
  collectBodyFaces(st, body, faces[0]);
  pr.build(st, weight, kProblemDt, {&body}, faces);
  const Eigen::Index n = static_cast<Eigen::Index>(pr.lattice.prod());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), pick(0.0, 1.0);
  const double scale = 1e-4;  // b of the size dt^2 / (rho dx^2) makes x of order 1
  pr.b.resize(n);
  pr.lo.resize(n);
  pr.hi.resize(n);
  pr.x = Eigen::VectorXd::Zero(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    pr.b[i] = scale * u(rng);
    if (pick(rng) < freeShare) {
      pr.lo[i] = -0.5;
      pr.hi[i] = 0.5;
    } else {
      pr.lo[i] = pr.hi[i] = 0.2 * u(rng);
    }
  }
  numerics::BoundQpSettings settings;
  settings.tolerance = 1e-10;
  settings.maxIterations = 20000;
  pr.solve(settings);

  // The whole-lattice operator, applied independently of the solve's restriction.
  CoupledOperator whole;
  whole.grid().assign(pr.lattice, pr.lower, pr.diagonal);
  whole.bodies() = pr.bodies;
  whole.setBodyWeight(kProblemDt * kProblemDt * st.spec.cellVolume());
  return kktViolation(pr, whole);
}

}  // namespace

TEST(GranularStressProblem, FreeSampleListSolvesTheWholeLatticeProblem) {
  // A quarter free: the list of free samples is used.
  for (unsigned seed : {1u, 2u, 3u}) EXPECT_LT(solveAndCheck(0.25, seed), 1e-8) << "seed " << seed;
}

TEST(GranularStressProblem, BoxSolvesTheWholeLatticeProblem) {
  // Nine in ten free: the bounding box is used (with the held samples inside it).
  for (unsigned seed : {1u, 2u, 3u}) EXPECT_LT(solveAndCheck(0.9, seed), 1e-8) << "seed " << seed;
}
