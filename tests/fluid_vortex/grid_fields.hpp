#pragma once
// Independent grid operators for the vortex-particle tests: exact sampling of an analytic velocity
// onto MAC faces, the discrete divergence of a face field, and the curl at cell centres (centre
// averages, central differences; written here so the tests do not check the module with itself).
#include <array>
#include <cmath>

#include <Eigen/Geometry>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"

namespace vortex_test {

using namespace msim;

// Face velocities of u(x) sampled exactly at each face centre.
template <int D, typename F>
MacGrid<D> sampledVelocity(const GridSpec<D>& spec, F field) {
  MacGrid<D> u(spec);
  for (int a = 0; a < D; ++a) {
    auto& g = u.component(a);
    for (std::size_t i = 0; i < g.count(); ++i) g[i] = static_cast<float>(field(g.position(g.coord(i)))[a]);
  }
  return u;
}

// sum_a (u_a(upper face) - u_a(lower face)) / dx at each cell centre (the projection's divergence).
inline Grid<double, 3> faceDivergence(const MacGrid<3>& u) {
  const GridSpec<3>& spec = u.spec();
  Grid<double, 3> div(spec);
  for (std::size_t i = 0; i < div.count(); ++i) {
    const IVec3 c = div.coord(i);
    double s = 0.0;
    for (int a = 0; a < 3; ++a) {
      IVec3 up = c;
      up[a] += 1;
      s += (double(u.component(a)(up)) - double(u.component(a)(c))) / spec.dx;
    }
    div[i] = s;
  }
  return div;
}

// curl u at cell centres (interior cells; the border layer is left zero).
inline Grid<Eigen::Vector3d, 3> cellCurl(const MacGrid<3>& u) {
  const GridSpec<3>& spec = u.spec();
  Grid<Eigen::Vector3d, 3> centre(spec), curl(spec);
  for (std::size_t i = 0; i < centre.count(); ++i) {
    const IVec3 c = centre.coord(i);
    for (int a = 0; a < 3; ++a) {
      IVec3 up = c;
      up[a] += 1;
      centre[i][a] = 0.5 * (double(u.component(a)(c)) + double(u.component(a)(up)));
    }
  }
  for (std::size_t i = 0; i < curl.count(); ++i) {
    const IVec3 c = curl.coord(i);
    bool border = false;
    for (int a = 0; a < 3; ++a) border = border || c[a] == 0 || c[a] == spec.res[a] - 1;
    if (border) continue;
    auto d = [&](int component, int axis) {
      IVec3 lo = c, hi = c;
      lo[axis] -= 1;
      hi[axis] += 1;
      return (centre(hi)[component] - centre(lo)[component]) / (2.0 * spec.dx);
    };
    curl[i] = Eigen::Vector3d(d(2, 1) - d(1, 2), d(0, 2) - d(2, 0), d(1, 0) - d(0, 1));
  }
  return curl;
}

// Trilinear interpolation of a cell-centred vector grid at x (inside the centres' range).
inline Eigen::Vector3d trilinear(const Grid<Eigen::Vector3d, 3>& g, const Vec3& x) {
  const Vec3 s = g.toSampleSpace(x);
  const IVec3 base(static_cast<int>(std::floor(s[0])), static_cast<int>(std::floor(s[1])),
                   static_cast<int>(std::floor(s[2])));
  const Vec3 t = s - base.cast<double>();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  for (int corner = 0; corner < 8; ++corner) {
    IVec3 c = base;
    double w = 1.0;
    for (int a = 0; a < 3; ++a) {
      const int bit = (corner >> a) & 1;
      c[a] += bit;
      w *= bit ? t[a] : 1.0 - t[a];
    }
    v += w * g(c);
  }
  return v;
}

}  // namespace vortex_test
