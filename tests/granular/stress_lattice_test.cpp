// The finite differences of stress_lattice.hpp against identities they must satisfy whatever their
// implementation: addDivergence (D_c) and divergenceTranspose (D_c^T) are adjoint over the open
// faces, and poissonStencil is D_c^T W D_c (the 7-point operator the friction QPs solve), for every
// component on a small grid with closed faces scattered through it.
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Core>

#include "msim/granular/stress_lattice.hpp"
#include "msim/numerics/bound_qp_mic0.hpp"

using namespace msim;
using namespace msim::granular;

namespace {

constexpr double kLatticeDx = 0.05;
const IVec3 kCells(5, 4, 6);

std::vector<StressComponent> allComponents() {
  return {StressComponent::Diagonal(0),       StressComponent::Diagonal(1),       StressComponent::Diagonal(2),
          StressComponent::OffDiagonal(0, 1), StressComponent::OffDiagonal(0, 2), StressComponent::OffDiagonal(1, 2)};
}

// Random values on every face; every fifth face (at random) closed in the mask.
void randomFaces(std::mt19937& rng, FaceField& values, FaceField& mask) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> pick(0, 4);
  values = FaceField(kCells);
  mask = FaceField(kCells, 1.0);
  for (int a = 0; a < 3; ++a)
    for (std::size_t i = 0; i < values.values[a].size(); ++i) {
      values.values[a][i] = u(rng);
      if (pick(rng) == 0) mask.values[a][i] = 0.0;
    }
}

std::vector<double> randomSamples(std::mt19937& rng, const StressComponent& c) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> s(static_cast<std::size_t>(latticeSize(c, kCells).prod()));
  for (double& v : s) v = u(rng);
  return s;
}

}  // namespace

TEST(GranularStressLattice, DivergenceAndItsTransposeAreAdjoint) {
  std::mt19937 rng(7);
  for (const StressComponent& c : allComponents()) {
    FaceField u, mask;
    randomFaces(rng, u, mask);
    const std::vector<double> s = randomSamples(rng, c);
    FaceField ds(kCells);
    addDivergence(c, s, 1.0, kLatticeDx, mask, ds);
    std::vector<double> dtu;
    divergenceTranspose(c, u, kLatticeDx, mask, dtu);
    ASSERT_EQ(dtu.size(), s.size());
    double faces = 0.0, samples = 0.0, scale = 0.0;
    for (int a = 0; a < 3; ++a)
      for (std::size_t i = 0; i < u.values[a].size(); ++i) {
        faces += ds.values[a][i] * u.values[a][i];
        scale += std::abs(ds.values[a][i] * u.values[a][i]);
        if (mask.values[a][i] == 0.0) {
          EXPECT_EQ(ds.values[a][i], 0.0) << "a closed face was written";
        }
      }
    for (std::size_t q = 0; q < s.size(); ++q) samples += s[q] * dtu[q];
    EXPECT_GT(scale, 1.0) << "component (" << c.a << ", " << c.b << ") acts on no face";
    EXPECT_NEAR(faces, samples, 1e-12 * scale) << "component (" << c.a << ", " << c.b << ")";
  }
}

TEST(GranularStressLattice, PoissonStencilIsTheTransposeTimesWeightsTimesTheDivergence) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> positive(0.5, 2.0);
  for (const StressComponent& c : allComponents()) {
    FaceField weight, mask;
    randomFaces(rng, weight, mask);
    for (auto& w : weight.values)
      for (double& v : w) v = positive(rng);
    const IVec3 lattice = latticeSize(c, kCells);
    constexpr double kIsolated = 3.0;
    std::array<std::vector<double>, 3> lower;
    std::vector<double> diagonal;
    poissonStencil(c, weight, kLatticeDx, mask, kIsolated, lower, diagonal);
    const numerics::GridPoissonQpOperator<3> A(lattice, lower, diagonal);

    // D^T W D x, built from the two other passes.
    const std::vector<double> x = randomSamples(rng, c);
    FaceField dx(kCells);
    addDivergence(c, x, 1.0, kLatticeDx, mask, dx);
    for (int a = 0; a < 3; ++a)
      for (std::size_t i = 0; i < dx.values[a].size(); ++i) dx.values[a][i] *= weight.values[a][i];
    std::vector<double> expected;
    divergenceTranspose(c, dx, kLatticeDx, mask, expected);

    Eigen::VectorXd ax(static_cast<Eigen::Index>(x.size()));
    A.apply(Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size())), ax);
    int isolated = 0;
    for (std::size_t q = 0; q < x.size(); ++q) {
      if (diagonal[q] == kIsolated) {  // no open face reaches it: held apart, D^T W D x is 0 there
        ++isolated;
        EXPECT_NEAR(expected[q], 0.0, 1e-9);
        continue;
      }
      EXPECT_NEAR(ax[static_cast<Eigen::Index>(q)], expected[q], 1e-9 * (1.0 + std::abs(expected[q])))
          << "component (" << c.a << ", " << c.b << "), sample " << q;
    }
    EXPECT_LT(isolated, static_cast<int>(x.size()) / 4);
  }
}

// The friction's bookkeeping runs the passes on a box of samples. For values that vanish outside
// the box, the boxed divergence must be exactly the whole one, and it must visit the faces that
// read the box and no others; the boxed transpose must match the whole one inside the box and
// leave the rest of its output alone.
TEST(GranularStressLattice, BoxedPassesMatchTheWholeOnes) {
  std::mt19937 rng(11);
  const LatticeBox boxes[] = {{IVec3(1, 1, 2), IVec3(3, 2, 4)}, {IVec3(0, 0, 0), IVec3(0, 3, 1)}, {}};
  for (const StressComponent& c : allComponents())
    for (const LatticeBox& box : boxes) {
      const IVec3 lattice = latticeSize(c, kCells);
      FaceField u, mask;
      randomFaces(rng, u, mask);
      std::vector<double> s = randomSamples(rng, c);
      for (int z = 0; z < lattice[2]; ++z)
        for (int y = 0; y < lattice[1]; ++y)
          for (int x = 0; x < lattice[0]; ++x) {
            const IVec3 q(x, y, z);
            const bool inside = !box.empty() && (q.array() >= box.first.array()).all() && (q.array() <= box.last.array()).all();
            if (!inside) s[(static_cast<std::size_t>(z) * lattice[1] + y) * lattice[0] + x] = 0.0;
          }
      FaceField whole = u, boxed = u;  // start from nonzero values: both add onto them
      addDivergence(c, s, 1.3, kLatticeDx, mask, whole);
      addDivergence(c, s, 1.3, kLatticeDx, mask, boxed, box);
      for (int a = 0; a < 3; ++a) {
        EXPECT_EQ(whole.values[a], boxed.values[a]) << "axis " << a;
        // Every face the whole pass changed lies in facesReading.
        const LatticeBox faces = facesReading(c, box, kCells, a);
        const IVec3 n = u.size(a);
        for (std::size_t i = 0; i < u.values[a].size(); ++i) {
          if (whole.values[a][i] == u.values[a][i]) continue;
          const IVec3 f(static_cast<int>(i % n[0]), static_cast<int>(i / n[0] % n[1]), static_cast<int>(i / n[0] / n[1]));
          EXPECT_TRUE(!faces.empty() && (f.array() >= faces.first.array()).all() && (f.array() <= faces.last.array()).all())
              << "axis " << a << " face " << i;
        }
      }
      std::vector<double> full, part(s.size(), 7.0);
      divergenceTranspose(c, u, kLatticeDx, mask, full);
      divergenceTranspose(c, u, kLatticeDx, mask, part, box);
      for (int z = 0; z < lattice[2]; ++z)
        for (int y = 0; y < lattice[1]; ++y)
          for (int x = 0; x < lattice[0]; ++x) {
            const IVec3 q(x, y, z);
            const std::size_t i = (static_cast<std::size_t>(z) * lattice[1] + y) * lattice[0] + x;
            const bool inside = !box.empty() && (q.array() >= box.first.array()).all() && (q.array() <= box.last.array()).all();
            EXPECT_EQ(part[i], inside ? full[i] : 7.0) << "sample " << i;
          }
    }
}
