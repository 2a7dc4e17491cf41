#include "msim/granular/render_points.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Cholesky>

#include "msim/core/parallel.hpp"
#include "msim/granular/particle_advection.hpp"

namespace msim::granular {

double mahalanobisDistance(const Eigen::Matrix3d& a, const Vec3& d) {
  // |L^{-1} d| with A = L L^T.
  return Eigen::LLT<Eigen::Matrix3d>(a).matrixL().solve(d).norm();
}

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

void RenderPoints::advect(std::span<const ParticleMotion> motion, double dt, const GridSpec<3>& domain) {
  parallelFor(0, size(), [&](std::size_t p) {
    positions_[p] = carriedPosition(motion[parents_[p]], positions_[p].cast<double>(), dt, domain).cast<float>();
  }, 4096);
}

void RenderPoints::reassign(const GranularParticles& particles, std::span<const SplitMerge::Successors> successors) {
  parallelFor(0, size(), [&](std::size_t p) {
    const SplitMerge::Successors s = successors[parents_[p]];
    std::uint32_t best = s.begin;
    if (s.count > 1) {
      const Vec3 x = positions_[p].cast<double>();
      double bestDistance = std::numeric_limits<double>::infinity();
      for (std::uint32_t k = s.begin; k < s.begin + s.count; ++k) {
        const double d = mahalanobisDistance(shapeMatrix(particles.shape[k]), x - particles.position[k].cast<double>());
        if (d < bestDistance) {
          bestDistance = d;
          best = k;
        }
      }
    }
    parents_[p] = best;
  });
}

std::size_t RenderPoints::resampleEscaped(const GranularParticles& particles) {
  ++generation_;
  escaped_.resize(size());
  // Each particle's factor once, not once per point (tens of points per particle).
  inverseFactor_.resize(particles.size());
  // The test in single precision (the positions are floats; its relative error, ~1e-6, is far
  // below kEscapeMargin).
  parallelFor(0, particles.size(), [&](std::size_t i) {
    inverseFactor_[i] = Eigen::LLT<Eigen::Matrix3d>(shapeMatrix(particles.shape[i]))
                            .matrixL()
                            .solve(Eigen::Matrix3d::Identity())
                            .cast<float>();
  });
  constexpr float kLimit2 = static_cast<float>((1.0 + kEscapeMargin) * (1.0 + kEscapeMargin));
  parallelFor(0, size(), [&](std::size_t p) {
    const std::uint32_t i = parents_[p];
    escaped_[p] = (inverseFactor_[i] * (positions_[p] - particles.position[i])).squaredNorm() > kLimit2;
    if (escaped_[p]) {
      Rng rng = streamFor(p);
      positions_[p] =
          (particles.position[i].cast<double>() + sampleInEllipsoid(shapeMatrix(particles.shape[i]), rng)).cast<float>();
    }
  }, 4096);
  return static_cast<std::size_t>(parallelSum(size(), [&](std::size_t p) { return escaped_[p]; }));
}

}  // namespace msim::granular
