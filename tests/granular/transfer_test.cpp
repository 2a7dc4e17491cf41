// Particle <-> grid transfers of the granular FLIP scheme against conservation and exactness facts.
#include "msim/granular/particle_grid_transfer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "granular_test_support.hpp"
#include "msim/core/rng.hpp"

namespace msim::granular {
namespace {

const GridSpec<3> kGrid(Vec3(-0.5, 0.0, 0.2), 0.1, IVec3(12, 10, 8));

double gridSum(const Grid<float, 3>& g) {
  double s = 0.0;
  for (float v : g.data()) s += v;
  return s;
}

// Random particles over the whole domain and a band outside it (folded onto the border).
GranularParticles randomCloud(std::size_t n, std::uint64_t seed) {
  Rng rng(seed);
  GranularParticles p;
  const Vec3 lo = kGrid.origin.array() - 0.05, hi = kGrid.upper().array() + 0.05;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 x(rng.uniform(lo[0], hi[0]), rng.uniform(lo[1], hi[1]), rng.uniform(lo[2], hi[2]));
    p.append(x.cast<float>(), Vecf<3>::Zero(), float(rng.uniform(0.5, 2.0)), toShape(Eigen::Matrix3d::Identity()),
             std::uint16_t(i % 2));
  }
  test::randomVelocities(p, seed + 1);
  return p;
}

const std::vector<GranularMaterial> kMaterials{{1500.0, 0.4}, {2600.0, 1.2}};

TEST(GranularTransfer, SplatConservesMassMomentumAndVolume) {
  const GranularParticles p = randomCloud(20000, 1);
  ParticleGridFields fields(kGrid);
  ParticleGridTransfer transfer;
  transfer.toGrid(p, kMaterials, fields);
  const test::Totals t = test::totals(p);
  double volume = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) volume += double(p.mass[i]) / kMaterials[p.material[i]].density;

  const double massError = std::abs(gridSum(fields.mass) - t.mass) / t.mass;
  double worst = massError;
  EXPECT_LE(massError, 1e-6);
  EXPECT_LE(std::abs(gridSum(fields.volume) - volume) / volume, 1e-6);
  for (int a = 0; a < 3; ++a) {
    const double faceMassError = std::abs(gridSum(fields.faceMass.component(a)) - t.mass) / t.mass;
    const double momentumError =
        std::abs(gridSum(fields.momentum.component(a)) - t.momentum[a]) / (t.mass * 1.0 /* |v| <= 1 */);
    EXPECT_LE(faceMassError, 1e-6);
    EXPECT_LE(momentumError, 1e-6);
    EXPECT_LE(std::abs(gridSum(fields.faceVolume.component(a)) - volume) / volume, 1e-6);
    worst = std::max({worst, faceMassError, momentumError});
  }
  std::printf("P2G: worst relative error of total mass / momentum %.2g\n", worst);
  // A second transfer into the same fields gives the same result (fields are reset, not added to).
  ParticleGridFields again(kGrid);
  transfer.toGrid(p, kMaterials, again);
  transfer.toGrid(p, kMaterials, again);
  EXPECT_EQ(again.mass.data(), fields.mass.data());
  EXPECT_EQ(again.velocity.component(1).data(), fields.velocity.component(1).data());
}

TEST(GranularTransfer, FaceVelocityOfAUniformFlowIsThatVelocity) {
  GranularParticles p = randomCloud(5000, 2);
  for (auto& v : p.velocity) v = Vecf<3>(0.5f, -1.25f, 2.0f);
  ParticleGridFields fields(kGrid);
  ParticleGridTransfer().toGrid(p, kMaterials, fields);
  for (int a = 0; a < 3; ++a) {
    const Grid<float, 3>& u = fields.velocity.component(a);
    const Grid<float, 3>& m = fields.faceMass.component(a);
    for (std::size_t f = 0; f < u.count(); ++f) {
      if (m[f] > 0.0f) {
        EXPECT_NEAR(u[f], p.velocity[0][a], 1e-5);
      } else {
        EXPECT_EQ(u[f], 0.0f);
      }
    }
  }
}

TEST(GranularTransfer, VolumeFractionAndFrictionOfASeededBlock) {
  // Two materials side by side, seeded at phi = 0.6: inside either block the cell volume is
  // phi * cellVolume on average and the friction is that material's alpha.
  ParticleGridFields fields(kGrid);
  GranularParticles p;
  SeedOptions left, right;
  left.fillFraction = right.fillFraction = 0.6;
  right.material = 1;
  right.seed = 9;
  seedBox(p, kGrid, kGrid.origin, Vec3(0.1, 1.0, 1.0), kMaterials, left);
  seedBox(p, kGrid, Vec3(0.1, 0.0, 0.2), kGrid.upper(), kMaterials, right);
  ParticleGridTransfer().toGrid(p, kMaterials, fields);
  double phiSum = 0.0;
  int cells = 0;
  for (std::size_t c = 0; c < fields.volume.count(); ++c) {
    const IVec3 q = fields.volume.coord(c);
    if ((q.array() < 1).any() || (q.array() >= kGrid.res.array() - 1).any()) continue;  // border cells get folded weight
    if (q[0] == 5 || q[0] == 6) continue;                                                // the interface
    phiSum += fields.volume[c] / kGrid.cellVolume();
    ++cells;
    EXPECT_NEAR(fields.friction[c], q[0] < 6 ? 0.4 : 1.2, 1e-5);
  }
  std::printf("seeded block: mean phi %.4f over %d interior cells (0.6 seeded)\n", phiSum / cells, cells);
  EXPECT_NEAR(phiSum / cells, 0.6, 0.01);
  // At the interface the friction is a volume-weighted mean, between the two.
  const float mixed = fields.friction(IVec3(5, 4, 4));
  EXPECT_GT(mixed, 0.4f);
  EXPECT_LT(mixed, 1.2f);
}

TEST(GranularTransfer, GatherOfALinearFieldIsExact) {
  Eigen::Matrix3d g;
  g << 0.3, -1.0, 0.5, 0.7, 0.2, -0.4, -0.6, 0.9, 0.1;
  const Vec3 b(0.25, -0.5, 1.0);
  MacGrid<3> velocity(kGrid);
  test::fillLinear(velocity, g, b);
  GranularParticles p = randomCloud(5000, 3);
  // Keep the particles where every trilinear tap is inside the face grids.
  const Vec3 lo = kGrid.origin.array() + 0.05, hi = kGrid.upper().array() - 0.05;
  for (auto& x : p.position) x = Vec3(x.cast<double>().cwiseMax(lo).cwiseMin(hi)).cast<float>();
  const MacGrid<3> unchanged = velocity;
  ParticleGridTransfer transfer;
  transfer.toParticles(unchanged, velocity, p, 0.0);  // pure PIC: v = I(v_grid)
  double worst = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3 exact = g * p.position[i].cast<double>() + b;
    worst = std::max(worst, (p.velocity[i].cast<double>() - exact).cwiseAbs().maxCoeff());
  }
  std::printf("G2P of a linear field: max error %.2g m/s\n", worst);
  EXPECT_LE(worst, 1e-5);
}

TEST(GranularTransfer, FlipWithAnUnchangedGridKeepsVelocities) {
  GranularParticles p = randomCloud(5000, 4);
  const std::vector<Vecf<3>> before = p.velocity;
  MacGrid<3> velocity(kGrid);
  Rng rng(5);
  for (int a = 0; a < 3; ++a)
    for (float& u : velocity.component(a).data()) u = float(rng.uniform(-1, 1));
  ParticleGridTransfer transfer;
  transfer.toParticles(velocity, velocity, p, 1.0);
  EXPECT_EQ(p.velocity, before);  // exactly
}

TEST(GranularTransfer, FlipRatioBlendsFlipAndPic) {
  // A uniform grid change dv: FLIP adds dv, PIC takes the new grid velocity; ratio 0.95 is 95/5.
  GranularParticles p = randomCloud(1000, 6);
  const std::vector<Vecf<3>> before = p.velocity;
  MacGrid<3> oldVelocity(kGrid, 1.0f), newVelocity(kGrid, 3.0f);
  ParticleGridTransfer().toParticles(oldVelocity, newVelocity, p);
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(p.velocity[i][a], 0.95 * (before[i][a] + 2.0) + 0.05 * 3.0, 1e-5);
  EXPECT_THROW(ParticleGridTransfer().toParticles(oldVelocity, newVelocity, p, 1.5), std::invalid_argument);
}

TEST(GranularTransfer, RejectsUnknownMaterial) {
  GranularParticles p = randomCloud(10, 7);
  p.material[3] = 2;
  ParticleGridFields fields(kGrid);
  EXPECT_THROW(ParticleGridTransfer().toGrid(p, kMaterials, fields), std::invalid_argument);
}

}  // namespace
}  // namespace msim::granular
