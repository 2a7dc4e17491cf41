// The layer a grid solver drives (vortex_layer.hpp): the source seeds at its rate only inside its
// window, particles that enter an obstacle are deleted, and those that leave the domain dropped.
#include <gtest/gtest.h>

#include <stdexcept>

#include "msim/core/mac_grid.hpp"
#include "msim/fluid/vortex/vortex_layer.hpp"

using namespace msim;
using namespace msim::fluid;

namespace {

const GridSpec<3> kDomain(Vec3::Zero(), 1.0 / 16.0, IVec3(16, 16, 16));

VortexLayerSettings<3> settings() {
  VortexLayerSettings<3> s;
  s.seed.regionMin = Vec3(0.25, 0.25, 0.25);
  s.seed.regionMax = Vec3(0.75, 0.75, 0.75);
  s.seed.radius = 0.1;
  s.seed.magnitude = 1.0;
  return s;
}

}  // namespace

TEST(VortexLayer, SeedsAtItsRateOnlyWithinItsWindow) {
  VortexLayerSettings<3> s = settings();
  s.rate = 100.0;
  s.start = 0.1;
  s.end = 0.3;
  s.initialCount = 7;
  VortexLayer<3> layer(s, kDomain, "test");
  layer.seedInitial(nullptr);
  EXPECT_EQ(layer.particles().size(), 7u);
  const MacGrid<3> still(kDomain, 0.0f);
  const double dt = 0.013;  // steps that straddle the window's ends
  for (double t = 0.0; t < 0.5; t += dt) layer.advance(still, dt, t, nullptr);
  // 100 per second over the 0.2 s window.
  EXPECT_NEAR(static_cast<double>(layer.particles().size()), 7.0 + 20.0, 1.0);
}

TEST(VortexLayer, DeletesParticlesInObstaclesAndOutsideTheDomain) {
  VortexLayerSettings<3> s = settings();
  s.initialCount = 400;
  VortexLayer<3> layer(s, kDomain, "test");
  layer.seedInitial(nullptr);
  // An obstacle filling x < 0.5 (nodal signed distance, negative inside).
  Grid<float, 3> phi(kDomain, (kDomain.res.array() + 1).matrix(), Vec3::Zero());
  for (std::size_t i = 0; i < phi.count(); ++i) phi[i] = static_cast<float>(phi.position(phi.coord(i)).x() - 0.5);
  layer.setSolid(phi);
  MacGrid<3> wind(kDomain, 0.0f);
  wind.component(2).fill(1.0f);  // along +z: a third of a domain per step
  layer.advance(wind, 0.3, 0.0, nullptr);
  ASSERT_GT(layer.particles().size(), 0u);
  for (const auto& x : layer.particles().positions()) {
    EXPECT_GE(x.x(), 0.5f);
    EXPECT_LE(x.z(), 1.0f);
  }
  EXPECT_LT(layer.particles().size(), 200u);  // about half in the obstacle, some blown out
}

TEST(VortexLayer, RejectsAnEmptyWindow) {
  VortexLayerSettings<3> s = settings();
  s.start = 0.4;
  s.end = 0.2;
  EXPECT_THROW(VortexLayer<3>(s, kDomain, "smoke.vortex_particles"), std::invalid_argument);
}
