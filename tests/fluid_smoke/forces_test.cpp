// Vorticity confinement and buoyancy against closed-form fields.
#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/Geometry>

#include "msim/fluid/smoke/buoyancy.hpp"
#include "msim/fluid/smoke/vorticity_confinement.hpp"

using namespace msim;
using namespace msim::fluid;

namespace {

// Face velocities of u(x) sampled exactly at each face centre.
template <int D, typename F>
MacGrid<D> sampled(const GridSpec<D>& spec, F field) {
  MacGrid<D> u(spec);
  for (int a = 0; a < D; ++a) {
    auto& g = u.component(a);
    for (std::size_t i = 0; i < g.count(); ++i) g[i] = static_cast<float>(field(g.position(g.coord(i)))[a]);
  }
  return u;
}

}  // namespace

TEST(Vorticity, SolidBodyRotationHasTwiceItsAngularVelocity) {
  const double omega = 1.7;
  const GridSpec<3> spec(Vec3::Zero(), 0.1, IVec3(10, 12, 8));
  const Vec3 axis = Vec3(0.3, -0.5, 0.8).normalized();
  const auto u = sampled<3>(spec, [&](const Vec3& x) { return Vec3(omega * axis.cross(x - Vec3(0.5, 0.6, 0.4))); });
  Vorticity<3> w(spec);
  computeVorticity<3>(u, w);
  for (std::size_t i = 0; i < w.count(); ++i)
    ASSERT_NEAR((w[i].cast<double>() - 2.0 * omega * axis).norm(), 0.0, 1e-4);

  const GridSpec<2> plane(Vec2::Zero(), 0.1, IVec2(9, 7));
  const auto u2 = sampled<2>(plane, [&](const Vec2& x) { return Vec2(-omega * x.y(), omega * x.x()); });
  Vorticity<2> w2(plane);
  computeVorticity<2>(u2, w2);
  for (std::size_t i = 0; i < w2.count(); ++i) ASSERT_NEAR(w2[i][0], 2.0 * omega, 1e-4);
}

// A Gaussian vortex: the confinement force must push along the flow (spinning the core up), be
// orthogonal to the radial direction, and scale with epsilon * dx.
TEST(VorticityConfinement, AmplifiesAGaussianVortexAlongItsFlow) {
  const int n = 48;
  const GridSpec<2> spec(Vec2::Zero(), 1.0 / n, IVec2(n, n));
  const Vec2 c(0.5, 0.5);
  const double R = 0.12;
  auto field = [&](const Vec2& x) {
    const Vec2 r = x - c;
    const double s = std::exp(-r.squaredNorm() / (R * R));
    return Vec2(-r.y() * s, r.x() * s);
  };
  MacGrid<2> u = sampled<2>(spec, field);
  const MacGrid<2> before = u;
  VorticityConfinement<2> confinement(spec);
  const double epsilon = 2.0, dt = 0.01;
  confinement.apply(u, epsilon, dt);
  double alongFlow = 0.0, radial = 0.0, norm = 0.0;
  for (std::size_t i = 0; i < confinement.force().count(); ++i) {
    const IVec2 cell = confinement.force().coord(i);
    const Vec2 r = spec.cellCenter(cell) - c;
    if (r.norm() < 0.02 || r.norm() > 0.3) continue;
    const Vec2 f = confinement.force()[i].cast<double>();
    alongFlow += f.dot(field(spec.cellCenter(cell)));
    radial += std::abs(f.dot(r.normalized()));
    norm += f.norm();
  }
  EXPECT_GT(alongFlow, 0.0);
  EXPECT_LT(radial, 0.05 * norm);
  // Twice epsilon: twice the velocity change.
  MacGrid<2> u2 = before;
  VorticityConfinement<2> again(spec);
  again.apply(u2, 2 * epsilon, dt);
  const auto& a = u.component(0);
  const auto& b = u2.component(0);
  const auto& base = before.component(0);
  const std::size_t probe = a.index(IVec2(30, 24));
  EXPECT_NEAR((b[probe] - base[probe]) / (a[probe] - base[probe]), 2.0, 1e-4);
}

TEST(Buoyancy, HotGasRisesAndSmokeSinksOnUpFaces) {
  const GridSpec<2> spec(Vec2::Zero(), 0.1, IVec2(4, 5));
  MacGrid<2> u(spec);
  Grid<float, 2> rho(spec, 0.0f), T(spec, 300.0f);
  rho(IVec2(1, 2)) = 2.0f;
  T(IVec2(1, 1)) = 310.0f;
  const BuoyancyParams p{.alpha = 0.5, .beta = 0.1, .ambientTemperature = 300.0, .upAxis = 1};
  addBuoyancy<2>(u, rho, T, p, 0.2);
  const auto& v = u.component(1);
  // Face between cells (1,1) and (1,2): mean of (+0.1*10) and (-0.5*2) = 0.
  EXPECT_NEAR(v(IVec2(1, 2)), 0.0, 1e-6);
  // Face below (1,1): mean of 0 and 1.0 -> 0.5 m/s^2 for 0.2 s.
  EXPECT_NEAR(v(IVec2(1, 1)), 0.1, 1e-6);
  // Face above (1,2): mean of -1.0 and 0 -> -0.5 m/s^2.
  EXPECT_NEAR(v(IVec2(1, 3)), -0.1, 1e-6);
  EXPECT_EQ(v(IVec2(1, 0)), 0.0f);  // boundary faces untouched
  for (std::size_t i = 0; i < u.component(0).count(); ++i) EXPECT_EQ(u.component(0)[i], 0.0f);
}
