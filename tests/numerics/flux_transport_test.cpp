// Physics checks of the finite-volume advection-diffusion solver against analytic references.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "msim/numerics/flux_transport.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

double total(const Grid<float, 2>& g) {
  double s = 0.0;
  for (float v : g.data()) s += v;
  return s;
}

// Face velocities from a node-based stream function psi: u = dpsi/dy, v = -dpsi/dx, differenced
// between the two nodes bounding each face, so the discrete divergence is zero to round-off.
MacGrid<2> rotationalFlow(const GridSpec<2>& spec, double omega) {
  MacGrid<2> vel(spec);
  const Vec2 centre = spec.origin + 0.5 * spec.extent();
  auto psi = [&](double x, double y) {
    const double r2 = (x - centre.x()) * (x - centre.x()) + (y - centre.y()) * (y - centre.y());
    const double R = 0.45 * spec.extent().x();
    return 0.5 * omega * r2 * std::exp(-r2 / (R * R));  // rotation that decays towards the walls
  };
  const double h = spec.dx;
  for (int axis = 0; axis < 2; ++axis) {
    auto& u = vel.component(axis);
    for (std::size_t lin = 0; lin < u.count(); ++lin) {
      const IVec2 f = u.coord(lin);
      const Vec2 p = u.position(f);
      u[lin] = axis == 0 ? static_cast<float>((psi(p.x(), p.y() + 0.5 * h) - psi(p.x(), p.y() - 0.5 * h)) / h)
                         : static_cast<float>(-(psi(p.x() + 0.5 * h, p.y()) - psi(p.x() - 0.5 * h, p.y())) / h);
    }
  }
  return vel;
}

}  // namespace

TEST(FluxTransport, ClosedBoxConservesMassOver100Steps) {
  const GridSpec<2> spec(Vec2::Zero(), 1.0 / 64, IVec2(64, 64));
  Grid<float, 2> phi(spec);
  for (std::size_t i = 0; i < phi.count(); ++i) {
    const Vec2 p = phi.position(phi.coord(i));
    phi[i] = (p - Vec2(0.35, 0.5)).norm() < 0.15 ? 1.0f : 0.0f;
  }
  const MacGrid<2> vel = rotationalFlow(spec, 6.0);
  FluxTransport<2> transport(spec, TransportBoundaries<2>::allClosed());
  transport.setVelocity(vel);
  TransportSettings settings;
  settings.diffusivity = 1e-4;
  const double dt = 0.9 * transport.maxStableDt(settings.diffusivity);
  const double before = total(phi);
  float minValue = 1.0f, maxValue = 0.0f;
  for (int s = 0; s < 100; ++s) transport.step(phi, settings, dt);
  for (float v : phi.data()) {
    minValue = std::min(minValue, v);
    maxValue = std::max(maxValue, v);
  }
  RecordProperty("mass_ratio_minus_1", fmt::format("{:.4e}", total(phi) / before - 1.0));
  EXPECT_NEAR(total(phi) / before, 1.0, 1e-4);
  EXPECT_GE(minValue, -1e-6f);  // positivity preserved
  EXPECT_LE(maxValue, 1.0f + 1e-6f);  // no new maxima
  // The blob must actually have moved: check the centre of mass rotated.
  double cx = 0.0;
  for (std::size_t i = 0; i < phi.count(); ++i) cx += phi[i] * phi.position(phi.coord(i)).x();
  EXPECT_GT(std::abs(cx / total(phi) - 0.35), 0.01);
}

TEST(FluxTransport, DiffusionVarianceGrowsByTwoKappaT) {
  const int n = 96;
  const GridSpec<2> spec(Vec2::Zero(), 1.0 / n, IVec2(n, n));
  Grid<float, 2> phi(spec);
  const double sigma0 = 4.0 * spec.dx, kappa = 2e-4;
  const Vec2 c(0.5, 0.5);
  for (std::size_t i = 0; i < phi.count(); ++i) {
    const Vec2 p = phi.position(phi.coord(i));
    phi[i] = static_cast<float>(std::exp(-(p - c).squaredNorm() / (2 * sigma0 * sigma0)));
  }
  auto variance = [&](int axis) {
    double m = 0.0, m2 = 0.0;
    for (std::size_t i = 0; i < phi.count(); ++i) {
      const double x = phi.position(phi.coord(i))[axis] - c[axis];
      m += phi[i];
      m2 += phi[i] * x * x;
    }
    return m2 / m;
  };
  const double var0x = variance(0), var0y = variance(1);
  FluxTransport<2> transport(spec, TransportBoundaries<2>::allClosed());
  TransportSettings settings;
  settings.diffusivity = kappa;
  const double tEnd = 3.0 * sigma0 * sigma0 / (2 * kappa);  // variance quadruples
  const int steps = static_cast<int>(std::ceil(tEnd / (0.9 * transport.maxStableDt(kappa))));
  for (int s = 0; s < steps; ++s) transport.step(phi, settings, tEnd / steps);
  const double expected = 2 * kappa * tEnd;
  RecordProperty("variance_growth_ratio_x", fmt::format("{:.4e}", (variance(0) - var0x) / expected));
  EXPECT_NEAR((variance(0) - var0x) / expected, 1.0, 0.02);
  EXPECT_NEAR((variance(1) - var0y) / expected, 1.0, 0.02);
}

TEST(FluxTransport, AdvectiveFormKeepsConstantInDivergentFlow) {
  const GridSpec<3> spec(Vec3::Zero(), 0.1, IVec3(12, 10, 8));
  MacGrid<3> vel(spec);
  for (int a = 0; a < 3; ++a) {  // radial expansion: div u = 3 everywhere
    auto& u = vel.component(a);
    for (std::size_t i = 0; i < u.count(); ++i) u[i] = static_cast<float>(u.position(u.coord(i))[a] - 0.5);
  }
  Grid<float, 3> temperature(spec, 300.0f);
  FluxTransport<3> transport(spec, TransportBoundaries<3>::allOpen());
  transport.setVelocity(vel);
  TransportSettings settings;
  settings.form = TransportForm::Advective;
  settings.inflowValue = 300.0;
  const double dt = 0.9 * transport.maxStableDt(0.0);
  for (int s = 0; s < 20; ++s) transport.step(temperature, settings, dt);
  for (float v : temperature.data()) ASSERT_NEAR(v, 300.0f, 1e-3f);
}

// A smooth profile carried by uniform flow on a periodic-like long domain: the error against the
// exactly shifted profile must fall at least at order 1.5 (MUSCL is second order away from extrema).
TEST(FluxTransport, UniformAdvectionConvergesAtSecondOrder) {
  auto errorAt = [](int n) {
    const GridSpec<2> spec(Vec2::Zero(), 1.0 / n, IVec2(n, 4));
    MacGrid<2> vel(spec);
    vel.component(0).fill(1.0f);
    auto profile = [](double x) { return std::exp(-std::pow((x - 0.3) / 0.08, 2)); };
    Grid<float, 2> phi(spec);
    for (std::size_t i = 0; i < phi.count(); ++i) phi[i] = static_cast<float>(profile(phi.position(phi.coord(i)).x()));
    TransportBoundaries<2> bc = TransportBoundaries<2>::allClosed();
    bc.side[0] = {BoundaryKind::Open, BoundaryKind::Open};
    FluxTransport<2> transport(spec, bc);
    transport.setVelocity(vel);
    const double tEnd = 0.4;
    const int steps = static_cast<int>(std::ceil(tEnd / (0.8 * transport.maxStableDt(0.0))));
    for (int s = 0; s < steps; ++s) transport.step(phi, {}, tEnd / steps);
    double err = 0.0;
    for (std::size_t i = 0; i < phi.count(); ++i)
      err += std::abs(phi[i] - profile(phi.position(phi.coord(i)).x() - tEnd)) * spec.dx / 4;
    return err;
  };
  const double e1 = errorAt(100), e2 = errorAt(200), e3 = errorAt(400);
  const double order = std::log2(e2 / e3);
  RecordProperty("order_100_200", fmt::format("{:.4e}", std::log2(e1 / e2)));
  RecordProperty("order_200_400", fmt::format("{:.4e}", order));
  EXPECT_GT(std::log2(e1 / e2), 1.5);
  EXPECT_GT(order, 1.5);
}
