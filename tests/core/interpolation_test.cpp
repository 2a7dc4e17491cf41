// Point interpolation against analytic fields: exact on linear data, bounded at steps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "msim/core/interpolation.hpp"
#include "msim/core/rng.hpp"

using namespace msim;

namespace {

template <int D>
Vec<D> slope() {
  Vec<D> a;
  for (int k = 0; k < D; ++k) a[k] = 0.7 - 0.45 * k;
  return a;
}

template <int D>
double linearField(const Vec<D>& x) {
  return 0.3 + slope<D>().dot(x);
}

template <int D>
void fillWith(Grid<float, D>& g, double (*f)(const Vec<D>&)) {
  for (std::size_t i = 0; i < g.count(); ++i) g[i] = static_cast<float>(f(g.position(g.coord(i))));
}

// World box spanned by the samples of g (where interpolation is not clamped).
template <int D>
Vec<D> randomPointInSampleRange(const Grid<float, D>& g, Rng& rng) {
  const Vec<D> lo = g.position(IVec<D>::Zero());
  const Vec<D> hi = g.position(g.size() - IVec<D>::Ones());
  Vec<D> x;
  for (int a = 0; a < D; ++a) x[a] = rng.uniform(lo[a], hi[a]);
  return x;
}

// Cell-centred grid and each MAC face grid of a small non-cubic domain.
template <int D>
std::vector<Grid<float, D>> testGrids() {
  IVec<D> res;
  for (int a = 0; a < D; ++a) res[a] = 7 + 3 * a;
  const GridSpec<D> spec(Vec<D>::Constant(-0.4), 0.25, res);
  std::vector<Grid<float, D>> grids{Grid<float, D>(spec)};
  MacGrid<D> mac(spec);
  for (int a = 0; a < D; ++a) grids.push_back(mac.component(a));
  return grids;
}

template <int D>
void expectExactOnLinearData() {
  Rng rng(7);
  for (Grid<float, D>& g : testGrids<D>()) {
    fillWith<D>(g, linearField<D>);
    for (int n = 0; n < 2000; ++n) {
      const Vec<D> x = randomPointInSampleRange(g, rng);
      EXPECT_NEAR(sampleLinear<D>(g, x), linearField<D>(x), 1e-6);
      EXPECT_NEAR(sampleMonotoneCubic<D>(g, x), linearField<D>(x), 1e-6);
    }
  }
}

}  // namespace

TEST(Interpolation, ExactOnLinearData2D) { expectExactOnLinearData<2>(); }
TEST(Interpolation, ExactOnLinearData3D) { expectExactOnLinearData<3>(); }

TEST(Interpolation, HitsSamplesExactly) {
  Rng rng(3);
  Grid<float, 3> g(GridSpec<3>(Vec3(1, 2, 3), 0.5, IVec3(5, 6, 7)));
  for (float& v : g.data()) v = static_cast<float>(rng.normal());
  for (std::size_t i = 0; i < g.count(); ++i) {
    const Vec3 x = g.position(g.coord(i));
    EXPECT_FLOAT_EQ(sampleLinear<3>(g, x), g[i]);
    EXPECT_FLOAT_EQ(sampleMonotoneCubic<3>(g, x), g[i]);
  }
}

TEST(Interpolation, ClampsOutsideToTheBorderValue) {
  Grid<float, 2> g(GridSpec<2>(Vec2::Zero(), 1.0, IVec2(4, 4)));
  fillWith<2>(g, linearField<2>);
  // Far left of column x = 0.5 (sample 0), at y of sample 2: zero-gradient extension.
  const Vec2 outside(-10.0, 2.5);
  EXPECT_FLOAT_EQ(sampleLinear<2>(g, outside), g(IVec2(0, 2)));
  EXPECT_FLOAT_EQ(sampleMonotoneCubic<2>(g, outside), g(IVec2(0, 2)));
  const Vec2 corner(100.0, 100.0);
  EXPECT_FLOAT_EQ(sampleLinear<2>(g, corner), g(IVec2(3, 3)));
  EXPECT_FLOAT_EQ(sampleMonotoneCubic<2>(g, corner), g(IVec2(3, 3)));
}

TEST(Interpolation, MonotoneCubicDoesNotOvershootSteps) {
  Rng rng(11);
  Grid<float, 3> step(GridSpec<3>(Vec3::Zero(), 1.0, IVec3(12, 12, 12)));
  for (std::size_t i = 0; i < step.count(); ++i) step[i] = step.coord(i)[0] < 6 ? 0.0f : 1.0f;
  Grid<float, 3> noise(step.spec());
  for (float& v : noise.data()) v = rng.uniform() < 0.5 ? 0.0f : 1.0f;
  for (const Grid<float, 3>* g : {&step, &noise}) {
    for (int n = 0; n < 20000; ++n) {
      const Vec3 x = randomPointInSampleRange(*g, rng);
      // Range of the 2^3 surrounding samples.
      const Vec3 s = g->toSampleSpace(x);
      float lo = 1e30f, hi = -1e30f;
      for (int corner = 0; corner < 8; ++corner) {
        IVec3 c;
        for (int a = 0; a < 3; ++a) c[a] = std::min(int(s[a]) + ((corner >> a) & 1), g->size()[a] - 1);
        lo = std::min(lo, (*g)(c));
        hi = std::max(hi, (*g)(c));
      }
      const float v = sampleMonotoneCubic<3>(*g, x);
      ASSERT_GE(v, lo - 1e-6f) << "at " << x.transpose();
      ASSERT_LE(v, hi + 1e-6f) << "at " << x.transpose();
    }
  }
  // Along the step the profile is monotone.
  float previous = -1.0f;
  for (double x = 0.0; x <= 12.0; x += 0.01) {
    const float v = sampleMonotoneCubic<3>(step, Vec3(x, 4.3, 7.9));
    EXPECT_GE(v, previous);
    previous = v;
  }
}

TEST(Interpolation, MonotoneCubicBeatsLinearOnSmoothData) {
  // A smooth monotone field: the cubic must be much more accurate than the linear interpolant,
  // which shows the slope limiter does not flatten smooth data.
  auto smooth = [](const Vec<2>& x) { return std::exp(0.4 * x[0]) + std::tanh(0.3 * x[1]); };
  Grid<float, 2> g(GridSpec<2>(Vec2::Zero(), 0.5, IVec2(20, 20)));
  for (std::size_t i = 0; i < g.count(); ++i) g[i] = static_cast<float>(smooth(g.position(g.coord(i))));
  Rng rng(5);
  double linearError = 0.0, cubicError = 0.0;
  for (int n = 0; n < 5000; ++n) {
    const Vec2 x = randomPointInSampleRange(g, rng);
    linearError = std::max(linearError, std::abs(sampleLinear<2>(g, x) - smooth(x)));
    cubicError = std::max(cubicError, std::abs(sampleMonotoneCubic<2>(g, x) - smooth(x)));
  }
  EXPECT_LT(cubicError, 0.15 * linearError) << "linear " << linearError << " cubic " << cubicError;
}

TEST(Interpolation, MacVelocityIsExactOnLinearFlow) {
  const GridSpec<3> spec(Vec3(0.1, -0.2, 0.3), 0.1, IVec3(8, 9, 10));
  MacGrid<3> u(spec);
  Eigen::Matrix3d gradient;
  gradient << 0.5, -1.0, 0.25, 1.5, 0.0, -0.75, 0.2, 0.3, -0.5;
  const Vec3 u0(0.1, -0.3, 0.6);
  for (int a = 0; a < 3; ++a) {
    Grid<float, 3>& face = u.component(a);
    for (std::size_t i = 0; i < face.count(); ++i) face[i] = float((u0 + gradient * face.position(face.coord(i)))[a]);
  }
  Rng rng(9);
  for (int n = 0; n < 2000; ++n) {
    // Inside the cell-centre box every component is within its own sample range.
    Vec3 x;
    for (int a = 0; a < 3; ++a) x[a] = rng.uniform(spec.origin[a] + 0.5 * spec.dx, spec.upper()[a] - 0.5 * spec.dx);
    const Vec3 expected = u0 + gradient * x;
    const Vec3 got = sampleLinear<3>(u, x);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(got[a], expected[a], 1e-6);
  }
}
