#pragma once
// Split and merge of granular simulation particles (Narain 2011 ch. 5.4.1, seed lines 1393-1407).
//
// A particle is valid when every semi-axis of its ellipsoid (square roots of the eigenvalues of A)
// lies in [r/sqrt2, sqrt2 r]. Invalid particles are split (too long) or merged with their nearest
// neighbour of the same material (too small), and an operation is performed only when every
// resulting particle is valid. Both conserve mass, momentum and centre of mass.
//
// Split (one level): along the longest semi-axis a (unit direction e) into two identical children
// of half the mass with the semi-axis along e halved, A_c = A - (3/4) a^2 e e^T, placed at
// x +- (sqrt3/2) a e. The offset is the one for which eq. 5.43 gives the parent back when the two
// children are merged: A_c + d^2 e e^T = A requires d^2 = (3/4) a^2 (the seed states both the
// halved axis and this round trip; an offset of a/2 would give back a parent of semi-axis a/sqrt2
// along e). Children of a split have the parent's eigenvectors, so a particle grown in several
// directions (e.g. isotropic expansion past sqrt2 r) cannot become valid with one split: the split
// is repeated on the children, each time along the longest remaining axis, up to maxSplitDepth
// levels (2^depth children), and performed only if the final children are valid.
//
// Merge (eq. 5.43): particles i and j become k at their centre of mass with their total mass and
// momentum and m_k A_k = m_i (A_i + dx_i dx_i^T) + m_j (A_j + dx_j dx_j^T), dx = x - x_k. Only
// particles of the same material merge (seed ch. 5.5, multiple materials).
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "msim/granular/granular_particles.hpp"
#include "msim/granular/particle_cell_hash.hpp"

namespace msim::granular {

bool isValidShape(const Eigen::Matrix3d& a, double radius);

struct MergedParticle {
  Vec3 position, velocity;
  double mass;
  Eigen::Matrix3d shape;
};
// Eq. 5.43 (computed in double).
MergedParticle mergeParticles(const Vec3& xi, const Vec3& vi, double mi, const Eigen::Matrix3d& ai, const Vec3& xj,
                              const Vec3& vj, double mj, const Eigen::Matrix3d& aj);

struct SplitMergeStats {
  std::size_t splits = 0;    // particles split
  std::size_t children = 0;  // particles created by those splits
  std::size_t merges = 0;    // pairs merged
};

// One pass over the particles. Keeps its buffers between calls: no allocation once warm.
// Deterministic whatever the thread count; not thread-safe.
class SplitMerge {
 public:
  // std::invalid_argument for radius <= 0 or a depth outside [1, 3].
  explicit SplitMerge(double radius, int maxSplitDepth = 3);

  double radius() const { return radius_; }
  // Splits whose children would be lighter than this are not performed (0: no limit). Not in the
  // seed: in a shear layer that persists (a spinning paddle wheel's blades) every step stretches
  // the same particles again, and splitting them every time halves their mass without end
  // (granular_paddles: children of 3e-14 kg, 2^-36 of a seeded particle, 8k of them in one cell,
  // whose merge searches took 93% of the run). Such a particle stays too long (invalid), like
  // those of the known shear limitation below; it still carries its mass and momentum.
  void setMinimumChildMass(double mass) { minimumChildMass_ = mass; }

  // Splits, then merges, the invalid particles in place. Output order: the survivors and children
  // in the order of their originals (a merged pair sits at the slot of its lower index).
  SplitMergeStats apply(GranularParticles& particles);

  // After apply: old particle i became the particles [begin, begin + count) of the new set (count
  // 2^depth when split, 1 otherwise; both members of a merged pair map to the merged particle).
  struct Successors {
    std::uint32_t begin, count;
  };
  std::span<const Successors> successors() const { return successors_; }

 private:
  enum class Plan : std::uint8_t { Keep, Split, MergeCandidate, MergeOwner, MergedAway };

  void classify(const GranularParticles& particles);
  void proposeMerges(const GranularParticles& particles);
  std::size_t acceptMerges();
  void emit(const GranularParticles& in, GranularParticles& out) const;
  int splitDepth(const Eigen::Matrix3d& a) const;  // levels that make the children valid, or 0

  double radius_;
  double minimumChildMass_ = 0.0;
  int maxSplitDepth_;
  std::vector<Plan> plan_;
  std::vector<std::uint8_t> depth_;          // split levels per particle
  std::vector<std::uint32_t> candidates_;    // merge candidates, ascending
  std::vector<std::uint32_t> proposal_;      // per candidate: partner or kNone
  std::vector<std::uint32_t> partnerOf_;     // per merge owner: the particle merged into it
  std::vector<Successors> successors_;
  ParticleCellHash cells_;
  GranularParticles out_;  // the new set, swapped with the caller's
};

}  // namespace msim::granular
