// The Advector reuses the semi-Lagrangian feet of the last layout it traced while the velocity
// (by value), dt, trace and solids are unchanged. Every reuse must give exactly what a fresh
// Advector computes.
#include <gtest/gtest.h>

#include <cmath>

#include "msim/numerics/advection/advector.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

const GridSpec<3> kSpec(Vec3::Zero(), 0.05, IVec3(24, 20, 16));

MacGrid<3> swirl(double strength) {
  MacGrid<3> v(kSpec);
  for (int a = 0; a < 3; ++a) {
    auto& g = v.component(a);
    for (std::size_t i = 0; i < g.count(); ++i) {
      const Vec3 p = g.position(g.coord(i)) - Vec3(0.6, 0.5, 0.4);
      g[i] = static_cast<float>(strength * (a == 0 ? -p.y() : (a == 1 ? p.x() : 0.3 + p.x() * p.y())));
    }
  }
  return v;
}

Grid<float, 3> wave(double k) {
  Grid<float, 3> g(kSpec);
  for (std::size_t i = 0; i < g.count(); ++i) {
    const Vec3 p = g.position(g.coord(i));
    g[i] = static_cast<float>(std::sin(k * p.x()) * std::cos(0.7 * k * p.y() + p.z()));
  }
  return g;
}

Grid<float, 3> ballMask() {
  Grid<float, 3> m(kSpec);
  for (std::size_t i = 0; i < m.count(); ++i)
    m[i] = (m.position(m.coord(i)) - Vec3(0.6, 0.5, 0.4)).norm() < 0.15 ? 1.0f : 0.0f;
  return m;
}

Grid<float, 3> fresh(const Grid<float, 3>& phi, const MacGrid<3>& velocity, double dt, bool solid) {
  Advector<float, 3> advector(kSpec, AdvectionSettings{});
  if (solid) advector.setSolid(ballMask());
  Grid<float, 3> out = phi;
  advector.advect(out, velocity, dt);
  return out;
}

void expectSame(const Grid<float, 3>& a, const Grid<float, 3>& b) {
  ASSERT_EQ(a.count(), b.count());
  for (std::size_t i = 0; i < a.count(); ++i) ASSERT_EQ(a[i], b[i]) << "sample " << i;
}

}  // namespace

TEST(FeetCache, ReusedFeetGiveTheSameResultAsAFreshAdvector) {
  for (bool solid : {false, true}) {
    Advector<float, 3> advector(kSpec, AdvectionSettings{});
    if (solid) advector.setSolid(ballMask());
    MacGrid<3> velocity = swirl(1.0);
    const double dt = 0.08;
    Grid<float, 3> a = wave(9.0), b = wave(13.0);
    advector.advect(a, velocity, dt);
    advector.advect(b, velocity, dt);  // same velocity and dt: the feet of `a` are reused
    expectSame(a, fresh(wave(9.0), velocity, dt, solid));
    expectSame(b, fresh(wave(13.0), velocity, dt, solid));

    // The same velocity object with new values, then a new dt: the feet must be traced again.
    velocity = swirl(-0.7);
    Grid<float, 3> c = wave(9.0);
    advector.advect(c, velocity, dt);
    expectSame(c, fresh(wave(9.0), velocity, dt, solid));
    Grid<float, 3> d = wave(9.0);
    advector.advect(d, velocity, 0.5 * dt);
    expectSame(d, fresh(wave(9.0), velocity, 0.5 * dt, solid));
  }
}

TEST(FeetCache, SelfAdvectionOfAMacGridMovesWithTheVelocityOfTimeN) {
  const MacGrid<3> start = swirl(1.0);
  MacGrid<3> self = start, other = start;
  Advector<float, 3> first(kSpec, AdvectionSettings{}), second(kSpec, AdvectionSettings{});
  Grid<float, 3> phi = wave(9.0);
  first.advect(phi, self, 0.08);  // leaves cell-centred feet behind, which must not be reused
  first.advect(self, self, 0.08);
  second.advect(other, start, 0.08);
  for (int a = 0; a < 3; ++a) {
    const auto& x = self.component(a);
    const auto& y = other.component(a);
    for (std::size_t i = 0; i < x.count(); ++i) ASSERT_EQ(x[i], y[i]) << "component " << a << " sample " << i;
  }
}
