#include "msim/granular/particle_advection.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "msim/core/interpolation.hpp"
#include "msim/core/parallel.hpp"

namespace msim::granular {

VelocitySample sampleVelocityAndJacobian(const MacGrid<3>& velocity, const Vec3& x) {
  using interpolation_detail::LinearAxis;
  VelocitySample out;
  const double inverseDx = 1.0 / velocity.spec().dx;
  for (int a = 0; a < 3; ++a) {
    const Grid<float, 3>& g = velocity.component(a);
    const Vec3 s = g.toSampleSpace(x);
    LinearAxis axis[3];
    bool varies[3];  // whether the interpolant depends on this coordinate at x
    for (int b = 0; b < 3; ++b) {
      const int n = g.size()[b];
      axis[b] = interpolation_detail::linearAxis(s[b], n, g.stride(b));
      varies[b] = n >= 2 && s[b] >= 0.0 && s[b] <= n - 1;
    }
    const float* data = g.data().data();
    double value = 0.0;
    Vec3 gradient = Vec3::Zero();  // per sample-space coordinate
    for (int corner = 0; corner < 8; ++corner) {
      std::ptrdiff_t offset = 0;
      double w[3], sign[3];
      for (int b = 0; b < 3; ++b) {
        const bool high = (corner >> b) & 1;
        offset += high ? axis[b].hi : axis[b].lo;
        w[b] = high ? axis[b].t : 1.0 - axis[b].t;
        sign[b] = high ? 1.0 : -1.0;
      }
      const double f = data[offset];
      value += f * w[0] * w[1] * w[2];
      gradient[0] += f * sign[0] * w[1] * w[2];
      gradient[1] += f * w[0] * sign[1] * w[2];
      gradient[2] += f * w[0] * w[1] * sign[2];
    }
    out.value[a] = value;
    for (int b = 0; b < 3; ++b) out.jacobian(a, b) = varies[b] ? gradient[b] * inverseDx : 0.0;
  }
  return out;
}

Eigen::Matrix3d deformShape(const Eigen::Matrix3d& a, const Eigen::Matrix3d& jacobian, double dt) {
  const Eigen::Matrix3d f = Eigen::Matrix3d::Identity() + dt * jacobian;
  return f * a * f.transpose();
}

void sampleCorrection(const GranularParticles& particles, const MacGrid<3>& displacement, std::vector<Vec3>& out) {
  out.resize(particles.size());
  parallelFor(0, particles.size(), [&](std::size_t i) {
    out[i] = sampleLinear<3>(displacement, particles.position[i].cast<double>());
  });
}

void advectParticles(GranularParticles& particles, const MacGrid<3>& velocity, double dt,
                     std::span<const Vec3> displacement, std::vector<ParticleMotion>* motion) {
  const GridSpec<3>& domain = velocity.spec();
  if (!displacement.empty() && displacement.size() != particles.size())
    throw std::invalid_argument("advectParticles: " + std::to_string(displacement.size()) +
                                " correction displacements for " + std::to_string(particles.size()) + " particles");
  if (motion) motion->resize(particles.size());
  parallelFor(0, particles.size(), [&](std::size_t i) {
    const Vec3 start = particles.position[i].cast<double>();
    const Vec3 x = displacement.empty() ? start : clampIntoDomain(domain, start + displacement[i]);
    const VelocitySample v = sampleVelocityAndJacobian(velocity, x);
    particles.shape[i] = toShape(deformShape(shapeMatrix(particles.shape[i]), v.jacobian, dt));
    particles.position[i] = clampIntoDomain(domain, x + dt * v.value).cast<float>();
    if (motion) (*motion)[i] = ParticleMotion{start, x - start, v.value, v.jacobian};
  });
}

}  // namespace msim::granular
