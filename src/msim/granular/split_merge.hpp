#pragma once
// Split and merge of granular simulation particles (Narain 2011 ch. 5.4.1, seed lines 1393-1407).
//
// A particle is valid when every semi-axis of its ellipsoid (square roots of the eigenvalues of A)
// lies in [r/sqrt2, sqrt2 r]. Invalid particles are split (too long) or merged with a near
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
// Merge (eq. 5.43): a too-small particle merges with the nearest of its kMergePartners nearest
// neighbours within 2 sqrt2 r (the same material, not being split) for which the merged particle
// is valid; the seed merges "with an adjacent particle" without saying which. If no pair is valid,
// it merges with its nearest 2, 3, ... partners together, the fewest that give a valid particle
// (eq. 5.43 summed over the group): the mirror of the cascaded split, for particles squashed along
// more than one axis. Particles i and j become k at their centre of mass with their total mass and
// momentum and m_k A_k = m_i (A_i + dx_i dx_i^T) + m_j (A_j + dx_j dx_j^T), dx = x - x_k. Only
// particles of the same material merge (seed ch. 5.5, multiple materials).
//
// Regularize (not in the seed): an invalid particle that neither a split nor a merge can make valid
// gets the nearest valid shape, its eigenvalues clamped into the band (mass, momentum and position
// unchanged). Sustained shear stretches a particle along one axis while it thins along another, so
// it becomes too long and too thin at once: its split children would be too thin and no merge
// shortens it. Such particles stayed invalid and searched for merge partners every step (77% of
// the particles of the landed cloud in granular_explosion, most of the particle stage). The
// shape enters only these decisions and the render points, not the transfers.
#include <array>
#include <cstdint>
#include <span>
#include <utility>
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
// Eq. 5.43 for any number of particles, m_k A_k = sum m_i (A_i + dx_i dx_i^T) with dx_i = x_i - x_k:
// the mass, momentum and second moment summed about `origin` (a member's position, so the sums stay
// well conditioned), in double.
class MergeAccumulator {
 public:
  explicit MergeAccumulator(const Vec3& origin) : origin_(origin) {}
  void add(const Vec3& x, const Vec3& v, double m, const Eigen::Matrix3d& a);
  MergedParticle result() const;

 private:
  Vec3 origin_;
  double mass_ = 0.0;
  Vec3 first_ = Vec3::Zero(), momentum_ = Vec3::Zero();  // sum m (x - origin), sum m v
  Eigen::Matrix3d second_ = Eigen::Matrix3d::Zero();     // sum m (A + (x - origin)(x - origin)^T)
};

// Eq. 5.43 for a pair (computed in double).
MergedParticle mergeParticles(const Vec3& xi, const Vec3& vi, double mi, const Eigen::Matrix3d& ai, const Vec3& xj,
                              const Vec3& vj, double mj, const Eigen::Matrix3d& aj);

// Merge partners considered per too-small particle, nearest first, alone and then together. With
// only the nearest tried, 77% of the particles of the landed cloud in granular_explosion were too
// small without a valid merge, and searched again every step.
inline constexpr int kMergePartners = 8;

struct SplitMergeStats {
  std::size_t splits = 0;    // particles split
  std::size_t children = 0;  // particles created by those splits
  std::size_t merges = 0;      // merges performed (pairs or groups)
  std::size_t mergedAway = 0;  // particles those merges removed (1 per pair)
  std::size_t regularized = 0; // invalid particles no split or merge could fix, brought into the band
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
  // whose merge searches took 93% of the run). Such a particle is regularized instead (above).
  void setMinimumChildMass(double mass) { minimumChildMass_ = mass; }
  // Merges whose result would be heavier than maximumMass[material] are not performed (empty: no
  // limit). Not in the seed: merges undo the splits of a dispersing cloud once it is compressed
  // again, and without a limit the group merges went on coarsening packed material; a landed
  // explosion ended with 1.7 particles per packed cell instead of 8, some 35 times a seeded one.
  // A too-small particle already at the limit is regularized without a search.
  void setMaximumMergedMass(std::vector<double> maximumMass) { maximumMergedMass_ = std::move(maximumMass); }

  // Splits, merges and regularizes the invalid particles in place. Output order: the survivors and
  // children in the order of their originals (a merged group sits at the slot of its lowest index).
  SplitMergeStats apply(GranularParticles& particles);

  // After apply: old particle i became the particles [begin, begin + count) of the new set (count
  // 2^depth when split, 1 otherwise; every member of a merged group maps to the merged particle).
  struct Successors {
    std::uint32_t begin, count;
  };
  std::span<const Successors> successors() const { return successors_; }

 private:
  enum class Plan : std::uint8_t { Keep, Split, MergeCandidate, MergeOwner, MergedAway, Regularize };

  void classify(const GranularParticles& particles);
  void proposeMerges(const GranularParticles& particles);
  std::size_t acceptMerges();
  void emit(const GranularParticles& in, GranularParticles& out) const;
  int splitDepth(const Eigen::Matrix3d& a) const;  // levels that make the children valid, or 0
  // Valid by Sylvester's test on a band narrowed by a relative 1e-6 (a shape it accepts, the
  // eigenvalues accept too; false near the band's edges, where the eigenvalues decide).
  bool surelyValid(const Eigen::Matrix3d& a) const;
  bool valid(const Eigen::Matrix3d& a) const;  // isValidShape, with cheap accepts and rejects first
  Eigen::Matrix3d regularized(const Eigen::Matrix3d& a) const;
  double maximumMergedMass(std::uint16_t material) const;

  double radius_;
  double minimumChildMass_ = 0.0;
  std::vector<double> maximumMergedMass_;  // per material; empty: no limit
  int maxSplitDepth_;
  std::vector<Plan> plan_;
  std::vector<std::uint8_t> depth_;          // split levels per particle
  std::vector<std::uint32_t> candidates_;    // merge candidates, ascending
  struct MergeGroup {
    std::array<std::uint32_t, kMergePartners> members;  // the partners, nearest first
    std::uint8_t size = 0;                              // 0: no valid merge found
  };
  std::vector<MergeGroup> groups_;        // per candidate: the partners it proposes to merge with
  std::vector<std::uint32_t> groupOf_;    // per merge owner: the candidate whose group it owns
  std::vector<Successors> successors_;
  ParticleCellHash cells_;
  GranularParticles out_;  // the new set, swapped with the caller's
};

}  // namespace msim::granular
