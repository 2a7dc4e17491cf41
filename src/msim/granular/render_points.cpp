#include "msim/granular/render_points.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "msim/core/parallel.hpp"
#include "msim/granular/particle_advection.hpp"

namespace msim::granular {

Vec3 sampleInEllipsoid(const Eigen::Matrix3d& a, Rng& rng) {
  // Uniform in the unit ball: a uniform direction (normalised Gaussian) at radius cbrt(u).
  Vec3 direction(rng.normal(), rng.normal(), rng.normal());
  const double norm = direction.norm();
  direction = norm > 0.0 ? Vec3(direction / norm) : Vec3::UnitX();
  const double radius = std::cbrt(rng.uniform());
  return Eigen::LLT<Eigen::Matrix3d>(a).matrixL() * (radius * direction);
}

RenderPoints::RenderPoints(std::size_t perParticle, std::uint64_t seed) : perParticle_(perParticle), rng_(seed) {
  if (perParticle == 0) throw std::invalid_argument("render points: at least one point per particle is needed");
}

Rng RenderPoints::streamFor(std::size_t point) const { return rng_.split(generation_).split(point); }

void RenderPoints::sample(const GranularParticles& particles) {
  ++generation_;
  const std::size_t n = particles.size() * perParticle_;
  positions_.resize(n);
  parents_.resize(n);
  parallelFor(0, n, [&](std::size_t p) {
    const std::size_t i = p / perParticle_;
    Rng rng = streamFor(p);
    parents_[p] = static_cast<std::uint32_t>(i);
    positions_[p] =
        (particles.position[i].cast<double>() + sampleInEllipsoid(shapeMatrix(particles.shape[i]), rng)).cast<float>();
  });
}

std::size_t RenderPoints::carry(std::span<const ParticleMotion> motion, double dt, const GridSpec<3>& domain,
                                const GranularParticles& particles,
                                std::span<const SplitMerge::Successors> successors) {
  if (!successors.empty() && successors.size() != motion.size())
    throw std::invalid_argument("render points: one successor range per particle before the step is needed");
  if (successors.empty() && particles.size() != motion.size())
    throw std::invalid_argument("render points: the particles changed but no successors were given");
  ++generation_;
  // Per particle once, not per point (tens of points per particle): carriedPosition rearranged as
  // x + (dx_p + dt v_p) + dt J_p (x - x_p), and the inverse factor of the new shape.
  carried_.resize(motion.size());
  parallelFor(0, motion.size(), [&](std::size_t i) {
    const ParticleMotion& m = motion[i];
    carried_[i] = CarriedMap{(dt * m.jacobian).cast<float>(), m.start.cast<float>(),
                             (m.displacement + dt * m.velocity).cast<float>()};
  });
  inverseFactor_.resize(particles.size());
  parallelFor(0, particles.size(), [&](std::size_t i) {
    inverseFactor_[i] = Eigen::LLT<Eigen::Matrix3d>(shapeMatrix(particles.shape[i]))
                            .matrixL()
                            .solve(Eigen::Matrix3d::Identity())
                            .cast<float>();
  });
  const double eps = kBoundaryEpsilonCells * domain.dx;  // as clampIntoDomain
  const Vecf<3> lo = (domain.origin.array() + eps).cast<float>(), hi = (domain.upper().array() - eps).cast<float>();
  // The escape test in single precision (its relative error, ~1e-6, is far below kEscapeMargin).
  constexpr float kLimit2 = static_cast<float>((1.0 + kEscapeMargin) * (1.0 + kEscapeMargin));
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, size(), 4096), std::size_t(0),
      [&](const tbb::blocked_range<std::size_t>& r, std::size_t escaped) {
        for (std::size_t p = r.begin(); p != r.end(); ++p) {
          const std::uint32_t before = parents_[p];
          const CarriedMap& c = carried_[before];
          const Vecf<3> x0 = positions_[p];
          const Vecf<3> x = (x0 + c.shift + c.gradient * (x0 - c.start)).cwiseMax(lo).cwiseMin(hi);
          std::uint32_t parent = before;
          if (!successors.empty()) {
            const SplitMerge::Successors s = successors[before];
            parent = s.begin;
            float best = std::numeric_limits<float>::infinity();
            for (std::uint32_t k = s.begin; s.count > 1 && k < s.begin + s.count; ++k) {
              const float d = (inverseFactor_[k] * (x - particles.position[k])).squaredNorm();
              if (d < best) {
                best = d;
                parent = k;
              }
            }
          }
          parents_[p] = parent;
          if ((inverseFactor_[parent] * (x - particles.position[parent])).squaredNorm() > kLimit2) {
            Rng rng = streamFor(p);
            positions_[p] = (particles.position[parent].cast<double>() +
                             sampleInEllipsoid(shapeMatrix(particles.shape[parent]), rng))
                                .cast<float>();
            ++escaped;
          } else {
            positions_[p] = x;
          }
        }
        return escaped;
      },
      [](std::size_t a, std::size_t b) { return a + b; });
}

}  // namespace msim::granular
