#include "msim/fluid/vortex/velocity_gradient.hpp"

#include <algorithm>
#include <cmath>

namespace msim::fluid {

namespace {

// Component a of the velocity at the centre of cell c: the mean of its two a-faces.
template <int D>
double centreVelocity(const MacGrid<D>& velocity, const IVec<D>& c, int a) {
  const auto& face = velocity.component(a);
  const std::size_t lower = face.index(c);
  return 0.5 * (double(face[lower]) + double(face[lower + face.stride(a)]));
}

}  // namespace

template <int D>
Eigen::Matrix<double, D, D> cellVelocityGradient(const MacGrid<D>& velocity, const IVec<D>& c) {
  const GridSpec<D>& spec = velocity.spec();
  const double dx = spec.dx;
  Eigen::Matrix<double, D, D> g;
  for (int b = 0; b < D; ++b) {
    // Neighbours along b for the central difference, one-sided at the border.
    IVec<D> lo = c, hi = c;
    if (c[b] > 0) lo[b] -= 1;
    if (c[b] + 1 < spec.res[b]) hi[b] += 1;
    const double span = (hi[b] - lo[b]) * dx;
    for (int a = 0; a < D; ++a) {
      if (a == b) {
        const auto& face = velocity.component(a);
        const std::size_t lower = face.index(c);
        g(a, a) = (double(face[lower + face.stride(a)]) - double(face[lower])) / dx;
      } else {
        g(a, b) = span > 0.0 ? (centreVelocity<D>(velocity, hi, a) - centreVelocity<D>(velocity, lo, a)) / span : 0.0;
      }
    }
  }
  return g;
}

template <int D>
Eigen::Matrix<double, D, D> velocityGradientAt(const MacGrid<D>& velocity, const Vec<D>& position) {
  const GridSpec<D>& spec = velocity.spec();
  // Cell-centre sample coordinates, clamped to the centres (as sampleLinear clamps).
  IVec<D> base;
  Vec<D> t;
  for (int a = 0; a < D; ++a) {
    const double s = std::clamp((position[a] - spec.origin[a]) / spec.dx - 0.5, 0.0, double(spec.res[a] - 1));
    base[a] = spec.res[a] > 1 ? std::min(static_cast<int>(s), spec.res[a] - 2) : 0;
    t[a] = s - base[a];
  }
  Eigen::Matrix<double, D, D> g = Eigen::Matrix<double, D, D>::Zero();
  for (int corner = 0; corner < (1 << D); ++corner) {
    IVec<D> c = base;
    double w = 1.0;
    for (int a = 0; a < D; ++a) {
      const int upper = (corner >> a) & 1;
      w *= upper ? t[a] : 1.0 - t[a];
      c[a] = std::min(c[a] + upper, spec.res[a] - 1);
    }
    if (w != 0.0) g += w * cellVelocityGradient<D>(velocity, c);
  }
  return g;
}

template Eigen::Matrix<double, 2, 2> cellVelocityGradient<2>(const MacGrid<2>&, const IVec<2>&);
template Eigen::Matrix<double, 3, 3> cellVelocityGradient<3>(const MacGrid<3>&, const IVec<3>&);
template Eigen::Matrix<double, 2, 2> velocityGradientAt<2>(const MacGrid<2>&, const Vec<2>&);
template Eigen::Matrix<double, 3, 3> velocityGradientAt<3>(const MacGrid<3>&, const Vec<3>&);

}  // namespace msim::fluid
