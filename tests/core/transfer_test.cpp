// Particle <-> grid transfer: conservation, linear exactness, adjointness, kernel weights and
// bitwise determinism across thread counts.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>

#include <tbb/global_control.h>

#include "msim/core/rng.hpp"
#include "msim/core/transfer.hpp"

using namespace msim;

namespace {

constexpr TransferKernel kKernels[] = {TransferKernel::Linear, TransferKernel::QuadraticBSpline};

template <int D>
GridSpec<D> testSpec(int base) {
  IVec<D> res;
  for (int a = 0; a < D; ++a) res[a] = base + 3 * a;
  return GridSpec<D>(Vec<D>::Constant(-0.5), 0.125, res);
}

// Positions over the grid box grown by `margin` cells on every side (so some lie outside).
template <int D>
std::vector<Vecf<D>> randomPositions(const GridSpec<D>& spec, std::size_t n, double margin, Rng& rng) {
  std::vector<Vecf<D>> p(n);
  for (auto& x : p)
    for (int a = 0; a < D; ++a)
      x[a] = float(rng.uniform(spec.origin[a] - margin * spec.dx, spec.upper()[a] + margin * spec.dx));
  return p;
}


template <int D>
double sumOf(const Grid<float, D>& g) {
  double s = 0.0;
  for (float v : g.data()) s += v;
  return s;
}

// Reference 1D kernels, written from their textbook definitions (r in samples).
double tent(double r) { return std::max(0.0, 1.0 - std::abs(r)); }
double quadraticBSpline(double r) {
  r = std::abs(r);
  if (r < 0.5) return 0.75 - r * r;
  if (r < 1.5) return 0.5 * (1.5 - r) * (1.5 - r);
  return 0.0;
}

template <int D>
void expectSplatConservesMass(int base, std::size_t n) {
  Rng rng(21);
  const GridSpec<D> spec = testSpec<D>(base);
  // 1.5 cells beyond the border: many particles have taps outside that must be folded back.
  const auto positions = randomPositions(spec, n, 1.5, rng);
  std::vector<float> values(n);
  double expected = 0.0;
  for (float& v : values) {
    v = float(rng.uniform(0.1, 2.0));
    expected += v;
  }
  Splatter<D> splatter;
  for (TransferKernel kernel : kKernels) {
    Grid<float, D> cells(spec);
    splatter.splat(positions, values, cells, kernel);
    EXPECT_NEAR(sumOf(cells), expected, 1e-6 * expected);
    MacGrid<D> faces(spec);
    for (int a = 0; a < D; ++a) {
      splat<D>(positions, values, faces.component(a), kernel);
      EXPECT_NEAR(sumOf(faces.component(a)), expected, 1e-6 * expected);
    }
    // Sum adds onto what is there.
    splatter.splat(positions, values, cells, kernel);
    EXPECT_NEAR(sumOf(cells), 2.0 * expected, 2e-6 * expected);
  }
}

template <int D>
double linearTransferField(const Vec<D>& x) {
  double f = 0.25;
  for (int a = 0; a < D; ++a) f += (0.6 - 0.35 * a) * x[a];
  return f;
}

// Positions whose every tap is inside g for the quadratic kernel: sample coords in [0.5, n-1.5].
template <int D>
std::vector<Vecf<D>> interiorPositions(const Grid<float, D>& g, std::size_t n, Rng& rng) {
  std::vector<Vecf<D>> p(n);
  for (auto& x : p) {
    Vec<D> s;
    for (int a = 0; a < D; ++a) s[a] = rng.uniform(0.5, g.size()[a] - 1.5);
    x = (g.spec().origin + (s + g.offset()) * g.spec().dx).template cast<float>();
  }
  return p;
}

template <int D>
void expectGatherExactOnLinearFields() {
  Rng rng(4);
  const GridSpec<D> spec = testSpec<D>(10);
  MacGrid<D> mac(spec);
  std::vector<Grid<float, D>> grids{Grid<float, D>(spec)};
  for (int a = 0; a < D; ++a) grids.push_back(mac.component(a));
  for (Grid<float, D>& g : grids) {
    for (std::size_t i = 0; i < g.count(); ++i) g[i] = float(linearTransferField<D>(g.position(g.coord(i))));
    const auto positions = interiorPositions(g, 3000, rng);
    for (TransferKernel kernel : kKernels) {
      const std::vector<float> got = gather<D>(g, positions, kernel);
      for (std::size_t p = 0; p < positions.size(); ++p)
        ASSERT_NEAR(got[p], linearTransferField<D>(positions[p].template cast<double>()), 1e-6);
    }
  }
}

}  // namespace

TEST(Transfer, SplatConservesMass2D) { expectSplatConservesMass<2>(24, 20000); }
TEST(Transfer, SplatConservesMass3D) { expectSplatConservesMass<3>(12, 50000); }

TEST(Transfer, GatherIsExactOnLinearFields2D) { expectGatherExactOnLinearFields<2>(); }
TEST(Transfer, GatherIsExactOnLinearFields3D) { expectGatherExactOnLinearFields<3>(); }

TEST(Transfer, MacGatherIsExactOnLinearFlow) {
  Rng rng(6);
  const GridSpec<3> spec = testSpec<3>(10);
  MacGrid<3> u(spec);
  Eigen::Matrix3d gradient;
  gradient << 0.5, -1.0, 0.25, 1.5, 0.0, -0.75, 0.2, 0.3, -0.5;
  for (int a = 0; a < 3; ++a) {
    auto& face = u.component(a);
    for (std::size_t i = 0; i < face.count(); ++i) face[i] = float((gradient * face.position(face.coord(i)))[a]);
  }
  // One cell in from the walls every component's quadratic stencil is inside its face grid.
  std::vector<Vecf<3>> positions(2000);
  for (auto& x : positions)
    for (int a = 0; a < 3; ++a) x[a] = float(rng.uniform(spec.origin[a] + spec.dx, spec.upper()[a] - spec.dx));
  std::vector<Vecf<3>> got(positions.size());
  for (TransferKernel kernel : kKernels) {
    gather<3>(u, positions, kernel, got);
    for (std::size_t p = 0; p < positions.size(); ++p) {
      const Vec3 expected = gradient * positions[p].cast<double>();
      for (int a = 0; a < 3; ++a) ASSERT_NEAR(got[p][a], expected[a], 1e-6);
    }
  }
}

TEST(Transfer, SingleParticleGetsTheTextbookKernelWeights) {
  const GridSpec<2> spec(Vec2::Zero(), 0.5, IVec2(8, 7));
  MacGrid<2> mac(spec);
  const std::vector<Vecf<2>> position{Vecf<2>(1.83f, 1.27f)};
  const std::vector<float> value{2.0f};
  for (TransferKernel kernel : kKernels) {
    double (*reference)(double) = kernel == TransferKernel::Linear ? tent : quadraticBSpline;
    for (Grid<float, 2> g : {Grid<float, 2>(spec), mac.component(0), mac.component(1)}) {
      splat<2>(position, value, g, kernel);
      const Vec2 s = g.toSampleSpace(position[0].cast<double>());
      for (std::size_t i = 0; i < g.count(); ++i) {
        const IVec2 c = g.coord(i);
        const double w = reference(c[0] - s[0]) * reference(c[1] - s[1]);
        ASSERT_NEAR(g[i], 2.0 * w, 1e-6) << "sample " << c.transpose();
      }
    }
  }
}

TEST(Transfer, GatherIsTheTransposeOfSplat) {
  Rng rng(12);
  const GridSpec<3> spec = testSpec<3>(9);
  const auto positions = randomPositions(spec, 5000, 2.0, rng);
  std::vector<float> values(positions.size());
  for (float& v : values) v = float(rng.normal());
  Grid<float, 3> field(spec);
  for (float& v : field.data()) v = float(rng.normal());
  for (TransferKernel kernel : kKernels) {
    Grid<float, 3> splatted(spec);
    splat<3>(positions, values, splatted, kernel);
    const std::vector<float> gathered = gather<3>(field, positions, kernel);
    double gridSide = 0.0, particleSide = 0.0;
    for (std::size_t i = 0; i < field.count(); ++i) gridSide += double(splatted[i]) * field[i];
    for (std::size_t p = 0; p < positions.size(); ++p) particleSide += double(values[p]) * gathered[p];
    EXPECT_NEAR(gridSide, particleSide, 1e-5 * std::abs(particleSide) + 1e-3);
  }
}

TEST(Transfer, NormalizedSplatAveragesAndLeavesEmptySamplesAtTheDefault) {
  Rng rng(13);
  const GridSpec<3> spec = testSpec<3>(12);
  // Particles only in the lower half along x.
  std::vector<Vecf<3>> positions = randomPositions(spec, 20000, 0.0, rng);
  for (auto& x : positions) x[0] = float(spec.origin[0] + 0.4 * (x[0] - spec.origin[0]));
  const std::vector<Vecf<3>> velocities(positions.size(), Vecf<3>(1.5f, -2.0f, 0.25f));
  for (TransferKernel kernel : kKernels) {
    MacGrid<3> u(spec, 123.0f);
    Splatter<3>().splat(positions, velocities, u, kernel, SplatMode::Normalized, -7.0f);
    for (int a = 0; a < 3; ++a) {
      const Grid<float, 3>& face = u.component(a);
      int filled = 0, empty = 0;
      for (std::size_t i = 0; i < face.count(); ++i) {
        if (face.position(face.coord(i))[0] < spec.origin[0] + 0.3 * spec.extent()[0]) {
          ASSERT_NEAR(face[i], velocities[0][a], 1e-6);
          ++filled;
        } else if (face.position(face.coord(i))[0] > spec.origin[0] + 0.6 * spec.extent()[0]) {
          ASSERT_EQ(face[i], -7.0f);
          ++empty;
        }
      }
      EXPECT_GT(filled, 0);
      EXPECT_GT(empty, 0);
    }
  }
}

TEST(Transfer, SplatIsBitwiseIdenticalAcrossThreadCounts) {
  Rng rng(99);
  const GridSpec<3> spec = testSpec<3>(32);
  const auto positions = randomPositions(spec, 300000, 1.0, rng);
  std::vector<float> values(positions.size());
  std::vector<Vecf<3>> vectors(positions.size());
  for (std::size_t p = 0; p < positions.size(); ++p) {
    values[p] = float(rng.uniform(-1.0, 1.0));
    vectors[p] = Vecf<3>(float(rng.normal()), float(rng.normal()), float(rng.normal()));
  }
  auto run = [&](int threads, TransferKernel kernel) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    Splatter<3> splatter;
    std::vector<float> out;
    Grid<float, 3> sum(spec);
    splatter.splat(positions, values, sum, kernel, SplatMode::Sum);
    out = sum.data();
    MacGrid<3> average(spec);
    splatter.splat(positions, vectors, average, kernel, SplatMode::Normalized);
    for (int a = 0; a < 3; ++a)
      out.insert(out.end(), average.component(a).data().begin(), average.component(a).data().end());
    return out;
  };
  for (TransferKernel kernel : kKernels) {
    const std::vector<float> serial = run(1, kernel), parallel = run(4, kernel);
    ASSERT_EQ(serial.size(), parallel.size());
    EXPECT_EQ(std::memcmp(serial.data(), parallel.data(), serial.size() * sizeof(float)), 0);
  }
}

// A fused splat of several quantities must be exactly what separate splats give, for every
// kernel, on cells and on each face layout (the granular transfer relies on it).
TEST(Transfer, FusedSumsEqualSeparateSplatsBitwise) {
  Rng rng(7);
  const GridSpec<3> spec = testSpec<3>(12);
  const auto positions = randomPositions(spec, 20000, 1.5, rng);
  std::array<std::vector<float>, 3> values;
  for (auto& v : values) {
    v.resize(positions.size());
    for (float& x : v) x = float(rng.uniform(-2.0, 3.0));
  }
  for (TransferKernel kernel : kKernels) {
    MacGrid<3> faces(spec);
    std::vector<Grid<float, 3>> layouts{Grid<float, 3>(spec)};
    for (int a = 0; a < 3; ++a) layouts.push_back(faces.component(a));
    for (const Grid<float, 3>& layout : layouts) {
      Splatter<3> splatter;
      std::array<Grid<float, 3>, 3> separate{layout, layout, layout}, fused{layout, layout, layout};
      for (int q = 0; q < 3; ++q) {
        separate[q].fill(0.5f);  // Sum adds onto what is there
        fused[q].fill(0.5f);
        splatter.splat(positions, values[q], separate[q], kernel);
      }
      splatter.splatSums<3>(positions, {values[0], values[1], values[2]}, {&fused[0], &fused[1], &fused[2]}, kernel);
      for (int q = 0; q < 3; ++q) {
        ASSERT_EQ(separate[q].count(), fused[q].count());
        EXPECT_EQ(std::memcmp(separate[q].data().data(), fused[q].data().data(), fused[q].count() * sizeof(float)), 0)
            << "quantity " << q;
        EXPECT_GT(std::abs(sumOf(fused[q]) - 0.5 * fused[q].count()), 1.0);  // something was splatted
      }
    }
  }
}

TEST(Transfer, FusedMacGatherEqualsSeparateGathersBitwise) {
  Rng rng(8);
  const GridSpec<3> spec = testSpec<3>(10);
  const auto positions = randomPositions(spec, 5000, 1.5, rng);
  MacGrid<3> u(spec), v(spec);
  for (MacGrid<3>* g : {&u, &v})
    for (int a = 0; a < 3; ++a)
      for (float& x : g->component(a).data()) x = float(rng.uniform(-1.0, 1.0));
  for (TransferKernel kernel : kKernels) {
    std::vector<Vecf<3>> su(positions.size()), sv(positions.size()), fu(positions.size()), fv(positions.size());
    gather<3>(u, positions, kernel, su);
    gather<3>(v, positions, kernel, sv);
    gather<3, 2>({&u, &v}, positions, kernel, {fu, fv});
    EXPECT_EQ(std::memcmp(su.data(), fu.data(), su.size() * sizeof(Vecf<3>)), 0);
    EXPECT_EQ(std::memcmp(sv.data(), fv.data(), sv.size() * sizeof(Vecf<3>)), 0);
    EXPECT_NE(std::memcmp(fu.data(), fv.data(), fu.size() * sizeof(Vecf<3>)), 0);
  }
  MacGrid<3> other(testSpec<3>(11));
  std::vector<Vecf<3>> a(positions.size()), b(positions.size());
  EXPECT_THROW((gather<3, 2>({&u, &other}, positions, TransferKernel::Linear, {a, b})), std::invalid_argument);
}

TEST(Transfer, FusedSumsRejectDifferentLayouts) {
  const GridSpec<3> spec = testSpec<3>(6);
  MacGrid<3> faces(spec);
  Grid<float, 3> cells(spec);
  const std::vector<Vecf<3>> positions(3, Vecf<3>::Zero());
  const std::vector<float> values(3, 1.0f), short_(2, 1.0f);
  Splatter<3> splatter;
  EXPECT_THROW(splatter.splatSums<2>(positions, {values, values}, {&cells, &faces.component(0)}, TransferKernel::Linear),
               std::invalid_argument);
  Grid<float, 3> other(spec);
  EXPECT_THROW(splatter.splatSums<2>(positions, {values, short_}, {&cells, &other}, TransferKernel::Linear),
               std::invalid_argument);
}

TEST(Transfer, RejectsMismatchedSizes) {
  const GridSpec<2> spec = testSpec<2>(8);
  Grid<float, 2> g(spec);
  const std::vector<Vecf<2>> positions(3, Vecf<2>::Zero());
  EXPECT_THROW(splat<2>(positions, std::vector<float>(2), g, TransferKernel::Linear), std::invalid_argument);
  std::vector<float> out(4);
  EXPECT_THROW(gather<2>(g, positions, TransferKernel::Linear, out), std::invalid_argument);
}
