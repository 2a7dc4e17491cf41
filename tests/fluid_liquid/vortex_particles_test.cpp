// Vortex particles in a liquid (Selle ch. 3.3-3.5, Fig. 3.3): they live in the water only (seeded
// in the air, or carried out of it, they are deleted), and in still water a particle spins the
// water about its own vorticity.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "../cell_field.hpp"
#include "msim/core/interpolation.hpp"
#include "msim/fluid/liquid/liquid_solver.hpp"
#include "msim/fluid/vortex/grid_vorticity.hpp"

using namespace msim;
using namespace msim::fluid;

namespace {

constexpr int kN = 20;
constexpr double kDepth = 0.6;

std::unique_ptr<LiquidSolver<3>> tank() {
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / kN, IVec3::Constant(kN));
  auto solver = std::make_unique<LiquidSolver<3>>(spec, LiquidParams<3>{});
  solver->addLiquid(test::cellField<3>(spec, [](const Vec3& x) { return x[1] - kDepth; }));
  return solver;
}

VortexLayerSettings<3> settings(const Vec3& lo, const Vec3& hi, std::size_t count) {
  VortexLayerSettings<3> s;
  s.seed.regionMin = lo;
  s.seed.regionMax = hi;
  s.seed.vorticity = SeedVorticity::Vertical;
  s.seed.magnitude = 1.0;
  s.seed.radius = 3.0 / kN;
  s.seed.strength = 2e-4;
  s.initialCount = count;
  return s;
}

}  // namespace

TEST(LiquidVortexParticles, LiveInTheWaterOnly) {
  auto solver = tank();
  solver->setVortexLayer(std::make_unique<VortexLayer<3>>(settings(Vec3::Zero(), Vec3::Ones(), 400), solver->spec(), "test"));
  const auto& particles = solver->vortexLayer()->particles();
  // About 60% of the box is water; the particles seeded above the surface are gone.
  EXPECT_GT(particles.size(), 200u);
  EXPECT_LT(particles.size(), 280u);
  for (int s = 0; s < 10; ++s) solver->step(1.0 / 120.0);
  EXPECT_GT(particles.size(), 200u);
  for (std::size_t p = 0; p < particles.size(); ++p)
    ASSERT_LT(sampleLinear<3>(solver->phi(), Vec3(particles.positions()[p].cast<double>())), 0.0f) << "particle " << p;
  EXPECT_EQ(solver->statistics().vortexParticles, particles.size());
}

TEST(LiquidVortexParticles, SpinStillWaterAboutTheirVorticity) {
  auto solver = tank();
  const Vec3 centre(0.5, 0.3, 0.5);
  solver->setVortexLayer(std::make_unique<VortexLayer<3>>(
      settings(centre - Vec3::Constant(1e-3), centre + Vec3::Constant(1e-3), 1), solver->spec(), "test"));
  ASSERT_EQ(solver->vortexLayer()->particles().size(), 1u);
  const double before = solver->statistics().enstrophy;
  for (int s = 0; s < 5; ++s) solver->step(1.0 / 120.0);
  const auto& particles = solver->vortexLayer()->particles();
  ASSERT_EQ(particles.size(), 1u);
  const Vec3 omega = particles.vorticities()[0];
  EXPECT_NEAR(omega.norm(), 1.0, 1e-12);  // stretching with rescale keeps |omega_p|
  Vorticity<3> curl(solver->spec());
  computeVorticity(solver->velocity(), curl);
  const Vec3 x = particles.positions()[0].cast<double>();
  const IVec3 cell = (x / solver->spec().dx).cast<int>();  // the cell holding the particle
  const Vec3 w = curl(cell).cast<double>();
  // From rest the water turns about omega_p: the grid's curl there points along it.
  const double cosine = w.dot(omega) / (w.norm() * omega.norm());
  EXPECT_GT(cosine, 0.95) << w.transpose();
  testing::Test::RecordProperty("cosine", std::to_string(cosine));
  EXPECT_GT(solver->statistics().enstrophy, 100.0 * before + 1e-12);
}
