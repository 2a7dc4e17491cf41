// Pairwise collision resolution (Narain 2011, ch. 4.3.3): dense random clusters end up separated,
// the centroid is conserved (pair pushes are equal and opposite), agents leave obstacles and
// stay in the domain, scripted agents do not move. Gauss-Seidel (the default) and Jacobi sweeps.
#include <cmath>
#include <iostream>
#include <random>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "msim/crowd/collision_resolution.hpp"

namespace msim::crowd {
namespace {

// n agents with radii in [0.2, 0.3] uniformly in a disc sized for the given area fraction.
Agents cluster(std::size_t n, double fraction, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const double area = static_cast<double>(n) * M_PI * 0.25 * 0.25 / fraction;
  const float R = static_cast<float>(std::sqrt(area / M_PI));
  Agents a;
  for (std::size_t i = 0; i < n; ++i) {
    AgentSpec s;
    const float rho = R * std::sqrt(u(rng)), phi = 6.2831853f * u(rng);
    s.position = Vec2f(rho * std::cos(phi), rho * std::sin(phi));
    s.radius = 0.2f + 0.1f * u(rng);
    a.add(s);
  }
  return a;
}

// Smallest centre distance over d_min = r_i + r_j among all pairs (brute force).
double minDistanceRatio(const Agents& a) {
  double worst = 1e30;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = i + 1; j < a.size(); ++j)
      worst = std::min(worst, (a.position[i] - a.position[j]).cast<double>().norm() /
                                  (a.radius[i] + a.radius[j]));
  return worst;
}

Vec2 centroid(const Agents& a) {
  Vec2 c = Vec2::Zero();
  for (const auto& x : a.position) c += x.cast<double>();
  return c / static_cast<double>(a.size());
}

const DomainBox kOpen{Vec2f(-1e4f, -1e4f), Vec2f(1e4f, 1e4f)};

TEST(CollisionResolution, DenseClusterSeparatesAndConservesCentroid) {
  Agents a = cluster(3000, 0.45, 1);
  const Vec2 before = centroid(a);
  const double initial = minDistanceRatio(a);
  CollisionResolver resolver;
  CollisionResolutionParams params;
  // 45% area fraction is 65% at 1.2 d_min, close to jamming, where Jacobi sweeps converge slowly:
  // separate to 1.1 d_min (the earlier default) to test convergence to d_min.
  params.separation = 1.1f;
  params.iterations = 30;
  // Near jamming the pushes on an agent nearly cancel, so a sweep moves it little while overlaps
  // remain: a tight tolerance (the default 0.03 d_min stops at 0.95 d_min here).
  params.tolerance = 0.01f;
  resolver.resolve(a, StaticObstacles(), kOpen, params);
  const double ratio = minDistanceRatio(a);
  std::cout << "[ measure ] 3000 agents at 45% area fraction: min |x_i - x_j| / d_min " << initial << " -> "
            << ratio << " after " << params.iterations << " sweeps (s = " << params.separation << ")\n";
  EXPECT_GE(ratio, 0.999);
  const double drift = (centroid(a) - before).norm();
  std::cout << "[ measure ] centroid drift " << drift << " m\n";
  EXPECT_LT(drift, 1e-5);
}

TEST(CollisionResolution, FewSweepsMostlySeparate) {
  // The default 12 sweeps from uniformly random positions (far worse than after a UIC step, where
  // only small overlaps remain): report how close the worst pair still is.
  Agents a = cluster(3000, 0.3, 2);
  CollisionResolver resolver;
  resolver.resolve(a, StaticObstacles(), kOpen);
  const double ratio = minDistanceRatio(a);
  std::cout << "[ measure ] 3000 agents at 30% area fraction, " << CollisionResolutionParams().iterations
            << " sweeps: min ratio " << ratio << "\n";
  EXPECT_GE(ratio, 0.8);
}

TEST(CollisionResolution, DeterministicAcrossRuns) {
  Agents a = cluster(5000, 0.4, 3), b = a;
  CollisionResolver r1, r2;
  r1.resolve(a, StaticObstacles(), kOpen);
  r2.resolve(b, StaticObstacles(), kOpen);
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a.position[i], b.position[i]);
}

// The textbook Jacobi sweeps, brute force over all pairs: what resolve() computes with its buckets.
void referenceResolve(Agents& a, const DomainBox& domain, const CollisionResolutionParams& params) {
  const std::size_t n = a.size();
  std::vector<Vec2f> next(n);
  for (int it = 0; it < params.iterations; ++it) {
    for (std::size_t i = 0; i < n; ++i) {
      Vec2f d = Vec2f::Zero();
      for (std::size_t j = 0; j < n; ++j) {
        const float target = params.separation * (a.radius[i] + a.radius[j]);
        const Vec2f diff = a.position[i] - a.position[j];
        const float dist = diff.norm();
        if (j == i || dist >= target) continue;
        d += (a.model[j] == AgentModel::Scripted ? 1.0f : 0.5f) * (target - dist) * diff / dist;
      }
      Vec2f x = a.position[i] + d;
      for (int k = 0; k < 2; ++k) x[k] = std::clamp(x[k], domain.lo[k] + a.radius[i], domain.hi[k] - a.radius[i]);
      next[i] = a.model[i] == AgentModel::Scripted ? a.position[i] : x;
    }
    a.position = next;
  }
}

TEST(CollisionResolution, MatchesBruteForceSweeps) {
  // Gentle overlaps (few re-bucketings) and a random start at 35% (agents move far, so the
  // buckets are redone during the sweeps): the same pairs are pushed as by brute force, so the
  // results agree to round-off (the sums are taken in another order).
  for (const double fraction : {0.15, 0.35}) {
    Agents a = cluster(600, fraction, 11);  // disc radius 16 or 10 m
    for (std::size_t i = 0; i < a.size(); i += 17) a.model[i] = AgentModel::Scripted;
    Agents b = a;
    const DomainBox domain{Vec2f(-40, -40), Vec2f(40, 40)};  // wide: no coincident clamped agents
    CollisionResolver resolver;
    CollisionResolutionParams all;
    all.sweeps = CollisionResolutionParams::Sweeps::Jacobi;
    all.tolerance = 0.0f;  // every sweep, as the reference
    resolver.resolve(a, StaticObstacles(), domain, all);
    referenceResolve(b, domain, all);
    double worst = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i)
      worst = std::max(worst, static_cast<double>((a.position[i] - b.position[i]).norm()));
    std::cout << "[ measure ] " << fraction * 100 << "% area fraction: " << resolver.lastBucketings()
              << " bucketings in 12 sweeps, max |x - x_brute force| " << worst << " m\n";
    EXPECT_LT(worst, 1e-4);
  }
}

TEST(CollisionResolution, StopsOnceConverged) {
  // Two overlapping agents far apart from three others: the first sweep pushes them exactly to
  // 1.2 d_min, the second moves nobody, and resolve() stops there instead of running all 12.
  Agents a;
  for (const Vec2f& x : {Vec2f(0, 0), Vec2f(0.3f, 0), Vec2f(10, 10), Vec2f(12, 10), Vec2f(14, 10)}) {
    AgentSpec s;
    s.position = x;
    a.add(s);
  }
  CollisionResolver resolver;
  resolver.resolve(a, StaticObstacles(), kOpen);
  EXPECT_EQ(resolver.lastSweeps(), 2);
  EXPECT_NEAR((a.position[1] - a.position[0]).norm(), 1.2f * 0.5f, 1e-6);
  EXPECT_EQ(a.position[2], Vec2f(10, 10));
}

TEST(CollisionResolution, IndependentOfThreadCount) {
  for (const auto sweeps : {CollisionResolutionParams::Sweeps::GaussSeidel, CollisionResolutionParams::Sweeps::Jacobi}) {
    Agents a = cluster(20000, 0.4, 5), b = a;
    CollisionResolutionParams params;
    params.sweeps = sweeps;
    CollisionResolver r1, r2;
    {
      tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
      r1.resolve(a, StaticObstacles(), kOpen, params);
    }
    r2.resolve(b, StaticObstacles(), kOpen, params);
    for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a.position[i], b.position[i]);
  }
}

// Sum over pairs of max(0, separation * d_min - distance) / d_min (brute force).
double totalOverlap(const Agents& a, float separation) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = i + 1; j < a.size(); ++j) {
      const double dmin = a.radius[i] + a.radius[j];
      sum += std::max(0.0, separation * dmin - (a.position[i] - a.position[j]).cast<double>().norm()) / dmin;
    }
  return sum;
}

TEST(CollisionResolution, GaussSeidelConvergesFasterThanJacobi) {
  // The same number of sweeps from the same random start: Gauss-Seidel leaves less overlap, and
  // half as many of its sweeps leave about what Jacobi's leave.
  const Agents start = cluster(3000, 0.3, 8);
  auto run = [&](CollisionResolutionParams::Sweeps sweeps, int iterations) {
    Agents a = start;
    CollisionResolutionParams params;
    params.sweeps = sweeps;
    params.iterations = iterations;
    params.tolerance = 0.0f;
    CollisionResolver resolver;
    resolver.resolve(a, StaticObstacles(), kOpen, params);
    return a;
  };
  const Agents gs6 = run(CollisionResolutionParams::Sweeps::GaussSeidel, 6);
  const Agents gs12 = run(CollisionResolutionParams::Sweeps::GaussSeidel, 12);
  const Agents j12 = run(CollisionResolutionParams::Sweeps::Jacobi, 12);
  const double o6 = totalOverlap(gs6, 1.2f), o12 = totalOverlap(gs12, 1.2f), oj = totalOverlap(j12, 1.2f);
  std::cout << "[ measure ] 3000 agents at 30% from random: sum of overlaps / d_min after Gauss-Seidel 6 " << o6
            << ", 12 " << o12 << ", Jacobi 12 " << oj << "; min ratio " << minDistanceRatio(gs6) << ", "
            << minDistanceRatio(gs12) << ", " << minDistanceRatio(j12) << "\n";
  EXPECT_LT(o12, oj);
  EXPECT_GE(minDistanceRatio(gs12), minDistanceRatio(j12));
  EXPECT_GE(minDistanceRatio(gs6), 0.8);
}

TEST(CollisionResolution, GaussSeidelConvergedStateKeepsEveryPairApart) {
  // Run to convergence from random positions, with buckets redone while agents move far: if a
  // pair within range were ever missed by the buckets, it would stay overlapped.
  Agents a = cluster(2000, 0.3, 9);
  for (std::size_t i = 0; i < a.size(); i += 23) a.model[i] = AgentModel::Scripted;
  const Vec2 before = centroid(a);
  CollisionResolver resolver;
  CollisionResolutionParams params;
  params.separation = 1.1f;
  params.iterations = 100;
  params.tolerance = 1e-5f;
  resolver.resolve(a, StaticObstacles(), kOpen, params);
  // Two scripted agents placed overlapping stay so: pairs with a movable agent only.
  double ratio = 1e30;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = i + 1; j < a.size(); ++j)
      if (a.model[i] != AgentModel::Scripted || a.model[j] != AgentModel::Scripted)
        ratio = std::min(ratio, (a.position[i] - a.position[j]).cast<double>().norm() / (a.radius[i] + a.radius[j]));
  std::cout << "[ measure ] Gauss-Seidel to convergence: " << resolver.lastSweeps() << " sweeps, "
            << resolver.lastBucketings() << " bucketings, " << resolver.lastRedoneSweeps()
            << " sweeps redone, min ratio " << ratio << " (target 1.1), centroid drift "
            << (centroid(a) - before).norm() << " m (scripted agents take whole pushes)\n";
  EXPECT_GE(ratio, 1.1 * 0.999);
}

// Smallest centre distance over the target separation * (r_i + r_j) among all pairs (brute force).
double minTargetRatio(const Agents& a, float separation) {
  double worst = 1e30;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = i + 1; j < a.size(); ++j)
      worst = std::min(worst, (a.position[i] - a.position[j]).cast<double>().norm() /
                                  (separation * (a.radius[i] + a.radius[j])));
  return worst;
}

TEST(CollisionResolution, LocalSweepsFindEveryOverlap) {
  // A crowd separated to convergence, then every agent walked 0.1 m in a random direction (a
  // step's worth): few pairs overlap, so after the first whole sweep only the neighbourhoods of
  // active agents are projected. A pair the local sweeps missed would keep the walk's overlap (up
  // to a third of the target); converged, no agent is more than the tolerance (0.01 d_min) from
  // where its pairs were last projected, which leaves each pair within a few tolerances, 5% of
  // its target at most. The same start resolved by whole sweeps only is the reference.
  Agents a = cluster(4000, 0.3, 12);
  CollisionResolver resolver;
  CollisionResolutionParams settle;
  settle.iterations = 200;
  settle.tolerance = 1e-4f;
  resolver.resolve(a, StaticObstacles(), kOpen, settle);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 6.2831853f);
  for (std::size_t i = 0; i < a.size(); ++i) a.position[i] += 0.1f * Vec2f(std::cos(u(rng)), std::sin(u(rng)));
  CollisionResolutionParams params;  // 1.2 d_min (the default), tolerance 0.01 d_min
  params.tolerance = 0.01f;
  params.iterations = 60;
  const double walked = minTargetRatio(a, params.separation);
  ASSERT_LT(walked, 0.8);
  Agents whole = a;
  CollisionResolutionParams noTolerance = params;
  noTolerance.tolerance = 0.0f;  // whole sweeps only, to convergence
  noTolerance.iterations = 200;
  resolver.resolve(whole, StaticObstacles(), kOpen, noTolerance);
  resolver.resolve(a, StaticObstacles(), kOpen, params);
  const double local = minTargetRatio(a, params.separation), reference = minTargetRatio(whole, params.separation);
  std::cout << "[ measure ] walked crowd: min distance / target " << walked << " -> " << local << " after "
            << resolver.lastSweeps() << " sweeps (" << resolver.lastLocalSweeps() << " local); whole sweeps to "
            << "convergence " << reference << "\n";
  ASSERT_LT(resolver.lastSweeps(), params.iterations) << "did not converge";
  EXPECT_GT(resolver.lastLocalSweeps(), 0);
  EXPECT_GE(local, 0.95);
  EXPECT_GE(reference, 0.999);
}

TEST(CollisionResolution, GaussSeidelConservesCentroidWithoutScriptedAgents) {
  Agents a = cluster(5000, 0.35, 10);
  const Vec2 before = centroid(a);
  CollisionResolver resolver;
  resolver.resolve(a, StaticObstacles(), kOpen);
  const double drift = (centroid(a) - before).norm();
  std::cout << "[ measure ] Gauss-Seidel, 5000 agents at 35%: centroid drift " << drift << " m after "
            << resolver.lastSweeps() << " sweeps\n";
  EXPECT_LT(drift, 1e-5);
}

TEST(CollisionResolution, PushesOutOfObstaclesAndKeepsInDomain) {
  Agents a = cluster(2000, 0.2, 4);
  const std::vector<Polygon> obstacles{rectangle(Vec2(-3, -3), Vec2(3, 1)), regularPolygon(Vec2(8, 0), 2.0, 7)};
  const DomainBox domain{Vec2f(-12, -9), Vec2f(12, 9)};
  CollisionResolver resolver;
  CollisionResolutionParams params;
  params.iterations = 10;
  resolver.resolve(a, StaticObstacles(obstacles, 0.3f), domain, params);
  double worst = 1e30;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Vec2 x = a.position[i].cast<double>();
    const double r = a.radius[i];
    for (const auto& poly : obstacles) worst = std::min(worst, signedDistance(poly, x) - r);
    EXPECT_GE(x.x(), domain.lo.x() + r - 1e-5);
    EXPECT_LE(x.x(), domain.hi.x() - r + 1e-5);
    EXPECT_GE(x.y(), domain.lo.y() + r - 1e-5);
    EXPECT_LE(x.y(), domain.hi.y() - r + 1e-5);
  }
  std::cout << "[ measure ] worst (distance to obstacle - radius) " << worst << " m\n";
  EXPECT_GE(worst, -1e-4);
}

TEST(CollisionResolution, ScriptedAgentsDoNotMove) {
  Agents a;
  AgentSpec s;
  s.model = AgentModel::Scripted;
  a.add(s);
  s.model = AgentModel::Uic;
  s.position = Vec2f(0.3f, 0.0f);
  a.add(s);
  CollisionResolver resolver;
  CollisionResolutionParams params;
  params.iterations = 1;
  resolver.resolve(a, StaticObstacles(), kOpen, params);
  EXPECT_EQ(a.position[0], Vec2f::Zero());
  // The movable one took the whole push, to separation * d_min in one sweep.
  EXPECT_NEAR(a.position[1].x(), params.separation * 0.5f, 1e-6f);
}

TEST(CollisionResolution, CoincidentAgentsSeparate) {
  Agents a;
  AgentSpec s;
  for (int k = 0; k < 3; ++k) a.add(s);
  CollisionResolver resolver;
  CollisionResolutionParams params;
  params.iterations = 20;
  resolver.resolve(a, StaticObstacles(), kOpen, params);
  EXPECT_GE(minDistanceRatio(a), 0.999);
}

}  // namespace
}  // namespace msim::crowd
