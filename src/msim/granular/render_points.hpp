#pragma once
// Render points of a granular material (Narain 2011 ch. 5.6, seed lines 1518-1520): every
// simulation particle owns points sampled uniformly inside its ellipsoid; they are carried
// passively with the flow (the grid motion expanded to first order about their particle, the
// map that also deforms its ellipsoid), handed to a child or the merged particle on split/merge, and
// resampled inside their particle's ellipsoid when they leave it. Everything is O(points), parallel
// and deterministic (each point draws from its own stream of core/rng.hpp).
//
// The points are not rebalanced: a particle keeps the points it is given, so after a split its
// children share the parent's points and a merged particle holds both sets; the total stays
// perParticle times the number of particles sampled.
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "msim/core/mac_grid.hpp"
#include "msim/core/rng.hpp"
#include "msim/granular/granular_particles.hpp"
#include "msim/granular/particle_advection.hpp"
#include "msim/granular/split_merge.hpp"

namespace msim::granular {

// Uniform in the ellipsoid d^T A^{-1} d <= 1 (A = L L^T maps the unit ball onto it with constant
// Jacobian). Draws four numbers.
Vec3 sampleInEllipsoid(const Eigen::Matrix3d& a, Rng& rng);

// A point is outside its particle when its Mahalanobis distance exceeds 1 by more than this; the
// margin keeps the float rounding of a freshly sampled point from counting as an escape.
inline constexpr double kEscapeMargin = 1e-3;

class RenderPoints {
 public:
  // std::invalid_argument for perParticle == 0.
  explicit RenderPoints(std::size_t perParticle = 16, std::uint64_t seed = 0);

  // Replaces every point: perParticle of them inside each particle.
  void sample(const GranularParticles& particles);
  // One particle step for every point, in one pass: moved with its particle's motion of the step
  // (carriedPosition of particle_advection.hpp; `motion` from advectParticles, one per particle
  // before split/merge), handed to the successor of its particle whose ellipsoid holds it best
  // (smallest Mahalanobis distance; `successors` from SplitMerge::apply, empty when the step had
  // none), and resampled inside that particle if it lies farther than 1 + kEscapeMargin.
  // `particles` are those after the step. Returns how many were resampled.
  std::size_t carry(std::span<const ParticleMotion> motion, double dt, const GridSpec<3>& domain,
                    const GranularParticles& particles, std::span<const SplitMerge::Successors> successors);

  std::size_t size() const { return positions_.size(); }
  std::span<const Vecf<3>> positions() const { return positions_; }
  std::span<const std::uint32_t> parents() const { return parents_; }

 private:
  Rng streamFor(std::size_t point) const;

  std::size_t perParticle_;
  Rng rng_;
  std::uint64_t generation_ = 0;  // counts sample/resample calls so that each draws fresh numbers
  std::vector<Vecf<3>> positions_;
  std::vector<std::uint32_t> parents_;
  std::vector<Eigen::Matrix3f> inverseFactor_;  // per particle after the step: L^-1 with A = L L^T
  // Per particle before the step: carriedPosition as x + shift + gradient (x - start), in single
  // precision like the points (their rounding, ~1e-7 relative, is far below the step's motion).
  struct CarriedMap {
    Eigen::Matrix3f gradient;  // dt J
    Vecf<3> start, shift;      // x_p before the step; its displacement plus dt v
  };
  std::vector<CarriedMap> carried_;
};

}  // namespace msim::granular
