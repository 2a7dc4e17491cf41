#pragma once
// Shared helpers of the granular particle tests: analytic velocity fields on MAC grids, a
// reference matrix exponential, the Mahalanobis distance and conserved totals accumulated in
// double.
#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "msim/core/mac_grid.hpp"
#include "msim/core/rng.hpp"
#include "msim/granular/granular_particles.hpp"

namespace msim::granular::test {

// (d^T A^{-1} d)^(1/2) = |L^{-1} d| with A = L L^T: 1 on the surface of the ellipsoid of A
// centred at the origin.
inline double mahalanobisDistance(const Eigen::Matrix3d& a, const Vec3& d) {
  return Eigen::LLT<Eigen::Matrix3d>(a).matrixL().solve(d).norm();
}

// Face samples of v(x) = G x + b.
inline void fillLinear(MacGrid<3>& grid, const Eigen::Matrix3d& g, const Vec3& b = Vec3::Zero()) {
  for (int a = 0; a < 3; ++a) {
    Grid<float, 3>& face = grid.component(a);
    for (std::size_t i = 0; i < face.count(); ++i) {
      const Vec3 x = face.position(face.coord(i));
      face[i] = static_cast<float>(g.row(a).dot(x) + b[a]);
    }
  }
}

// exp(M) by its Taylor series (for the small matrices of the tests).
inline Eigen::Matrix3d expm(const Eigen::Matrix3d& m) {
  Eigen::Matrix3d sum = Eigen::Matrix3d::Identity(), term = Eigen::Matrix3d::Identity();
  for (int k = 1; k < 40; ++k) {
    term = term * m / k;
    sum += term;
  }
  return sum;
}

struct Totals {
  double mass = 0.0;
  Vec3 momentum = Vec3::Zero(), firstMoment = Vec3::Zero();  // sum m v, sum m x
  Vec3 centreOfMass() const { return firstMoment / mass; }
};

inline Totals totals(const GranularParticles& p) {
  Totals t;
  for (std::size_t i = 0; i < p.size(); ++i) {
    t.mass += p.mass[i];
    t.momentum += double(p.mass[i]) * p.velocity[i].cast<double>();
    t.firstMoment += double(p.mass[i]) * p.position[i].cast<double>();
  }
  return t;
}

// Random velocities in [-1, 1)^3 m/s, so that momentum checks are not trivially zero.
inline void randomVelocities(GranularParticles& p, std::uint64_t seed) {
  Rng rng(seed);
  for (auto& v : p.velocity) v = Vecf<3>(float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)));
}

}  // namespace msim::granular::test
