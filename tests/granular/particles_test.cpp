// Granular particle storage, material validation and seeding (Narain 2011 ch. 5.4).
#include "msim/granular/granular_particles.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace msim::granular {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(GranularMaterial, RejectsNonPhysicalValues) {
  EXPECT_NO_THROW(validate(GranularMaterial{1600.0, 0.0}));
  EXPECT_NO_THROW(validate(GranularMaterial{1600.0, 2.0}));
  for (double density : {0.0, -1.0, kNaN}) EXPECT_THROW(validate(GranularMaterial{density, 0.5}), std::invalid_argument);
  for (double friction : {-0.1, 2.1, kNaN}) EXPECT_THROW(validate(GranularMaterial{1600.0, friction}), std::invalid_argument);
  try {
    validate(std::vector<GranularMaterial>{{1600.0, 0.5}, {1600.0, 3.0}});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("material 1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("friction"), std::string::npos) << e.what();
  }
}

TEST(GranularParticles, ShapeRoundTripsThroughSixFloats) {
  Eigen::Matrix3d a;
  a << 4, 1, 2, 1, 5, 3, 2, 3, 6;
  const ParticleShape s = toShape(a);
  EXPECT_EQ(s, (ParticleShape{4, 5, 6, 1, 2, 3}));
  EXPECT_EQ(shapeMatrix(s), a);
}

TEST(GranularSeeding, EightJitteredParticlesPerCellWithTheSeedMassAndShape) {
  const GridSpec<3> grid(Vec3(-1, 0, 0), 0.1, IVec3(10, 8, 6));
  const std::vector<GranularMaterial> materials{{1600.0, 0.5}, {2500.0, 0.8}};
  SeedOptions options;
  options.fillFraction = 0.6;
  options.velocity = Vec3(1, -2, 3);
  options.material = 1;
  options.seed = 7;
  GranularParticles p;
  // A box of exactly 4 x 3 x 2 cells.
  const Vec3 lo(-0.8, 0.2, 0.1), hi(-0.4, 0.5, 0.3);
  EXPECT_EQ(seedBox(p, grid, lo, hi, materials, options), 8u * 4 * 3 * 2);
  const double dx = grid.dx, r = dx / 4;
  double totalMass = 0.0;
  int perSubCell[2][2][2] = {};
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3 x = p.position[i].cast<double>();
    EXPECT_TRUE((x.array() >= lo.array() - 1e-6).all() && (x.array() <= hi.array() + 1e-6).all());
    EXPECT_FLOAT_EQ(p.mass[i], float(0.6 * 2500.0 * dx * dx * dx / 8));
    EXPECT_TRUE(shapeMatrix(p.shape[i]).isApprox(r * r * Eigen::Matrix3d::Identity(), 1e-6));
    EXPECT_EQ(p.velocity[i], Vecf<3>(1, -2, 3));
    EXPECT_EQ(p.material[i], 1);
    totalMass += p.mass[i];
    // Which half of its cell the particle is in, per axis.
    const Vec3 s = (x - grid.origin) / dx;
    ++perSubCell[int(2 * (s[0] - std::floor(s[0])))][int(2 * (s[1] - std::floor(s[1])))][int(2 * (s[2] - std::floor(s[2])))];
  }
  // The box holds phi rho_max V of material.
  EXPECT_NEAR(totalMass, 0.6 * 2500.0 * 0.4 * 0.3 * 0.2, 1e-6 * totalMass);
  for (auto& a : perSubCell)
    for (auto& b : a)
      for (int c : b) EXPECT_EQ(c, 4 * 3 * 2);  // one per sub-cell of every cell
}

TEST(GranularSeeding, DeterministicPerSeedAndIndependentOfTheRegion) {
  const GridSpec<3> grid(Vec3::Zero(), 0.1, IVec3::Constant(8));
  const std::vector<GranularMaterial> materials{{1600.0, 0.5}};
  GranularParticles a, b, c, whole;
  SeedOptions options;
  options.seed = 3;
  seedBox(a, grid, Vec3::Zero(), Vec3::Constant(0.4), materials, options);
  seedBox(b, grid, Vec3::Zero(), Vec3::Constant(0.4), materials, options);
  EXPECT_EQ(a.position, b.position);
  options.seed = 4;
  seedBox(c, grid, Vec3::Zero(), Vec3::Constant(0.4), materials, options);
  EXPECT_NE(a.position, c.position);
  // The same cells seeded as part of a larger region get the same jitter.
  options.seed = 3;
  seedBox(whole, grid, Vec3::Zero(), Vec3::Constant(0.8), materials, options);
  std::size_t found = 0;
  for (const Vecf<3>& x : a.position)
    for (const Vecf<3>& y : whole.position) found += x == y;
  EXPECT_EQ(found, a.size());
}

TEST(GranularSeeding, InsidePredicateSeedsTheRegionVolume) {
  const GridSpec<3> grid(Vec3::Zero(), 0.05, IVec3::Constant(40));
  const std::vector<GranularMaterial> materials{{1600.0, 0.5}};
  const Vec3 centre = Vec3::Constant(1.0);
  const double radius = 0.6;
  GranularParticles p;
  const std::size_t n = seedRegion(
      p, grid, centre.array() - radius, centre.array() + radius,
      [&](const Vec3& x) { return (x - centre).norm() <= radius; }, materials);
  const double expected = 8.0 * (4.0 / 3.0) * M_PI * radius * radius * radius / std::pow(grid.dx, 3);
  std::printf("sphere seeding: %zu particles, %.0f expected\n", n, expected);
  EXPECT_NEAR(double(n), expected, 0.02 * expected);
  for (const Vecf<3>& x : p.position) EXPECT_LE((x.cast<double>() - centre).norm(), radius + 1e-6);
}

TEST(GranularSeeding, DenserSeedingScalesTheSpacingMassAndShape) {
  const GridSpec<3> grid(Vec3::Zero(), 0.1, IVec3::Constant(10));
  const std::vector<GranularMaterial> materials{{1600.0, 0.5}};
  SeedOptions options;
  options.particlesPerCell = 27.0;  // a 3 x 3 x 3 lattice in every cell
  GranularParticles p;
  EXPECT_EQ(seedBox(p, grid, Vec3(0.2, 0.1, 0.3), Vec3(0.6, 0.4, 0.5), materials, options), 27u * 4 * 3 * 2);
  const double h = grid.dx / 3.0;
  EXPECT_DOUBLE_EQ(particleSpacing(grid.dx, 27.0), h);
  EXPECT_DOUBLE_EQ(particleRadius(grid.dx, 27.0), h / 2);
  EXPECT_DOUBLE_EQ(particleRadius(grid.dx), grid.dx / 4);  // the seed's r at 8 per cell
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_FLOAT_EQ(p.mass[i], float(1600.0 * h * h * h));
    EXPECT_TRUE(shapeMatrix(p.shape[i]).isApprox(h * h / 4 * Eigen::Matrix3d::Identity(), 1e-6));
  }
  // A density whose lattice does not fit the cells still seeds k per cell and rho_max V on average.
  GranularParticles q;
  options.particlesPerCell = 12.0;
  const std::size_t n = seedBox(q, grid, Vec3::Zero(), Vec3::Ones(), materials, options);
  double mass = 0.0;
  for (float m : q.mass) mass += m;
  std::printf("12 per cell over 1000 cells: %zu particles, mass %.2f kg of %.2f\n", n, mass, 1600.0);
  EXPECT_NEAR(double(n), 12000.0, 120.0);
  EXPECT_NEAR(mass, 1600.0, 16.0);
}

TEST(GranularSeeding, RejectsBadOptions) {
  const GridSpec<3> grid(Vec3::Zero(), 0.1, IVec3::Constant(4));
  const std::vector<GranularMaterial> materials{{1600.0, 0.5}};
  GranularParticles p;
  SeedOptions options;
  for (double phi : {0.0, 1.5, kNaN}) {
    options.fillFraction = phi;
    EXPECT_THROW(seedBox(p, grid, Vec3::Zero(), Vec3::Ones(), materials, options), std::invalid_argument);
  }
  options = {};
  options.material = 1;
  EXPECT_THROW(seedBox(p, grid, Vec3::Zero(), Vec3::Ones(), materials, options), std::invalid_argument);
  options = {};
  options.velocity = Vec3(kNaN, 0, 0);
  EXPECT_THROW(seedBox(p, grid, Vec3::Zero(), Vec3::Ones(), materials, options), std::invalid_argument);
  for (double k : {0.5, 126.0, kNaN}) {
    options = {};
    options.particlesPerCell = k;
    EXPECT_THROW(seedBox(p, grid, Vec3::Zero(), Vec3::Ones(), materials, options), std::invalid_argument);
  }
  const std::vector<GranularMaterial> bad{{-1.0, 0.5}};
  EXPECT_THROW(seedBox(p, grid, Vec3::Zero(), Vec3::Ones(), bad), std::invalid_argument);
  EXPECT_TRUE(p.empty());
}

}  // namespace
}  // namespace msim::granular
