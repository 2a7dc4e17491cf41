#include "msim/granular/split_merge.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Eigenvalues>

#include "msim/core/parallel.hpp"

namespace msim::granular {

namespace {

// Eigenvalues (squared semi-axes) in ascending order; the closed form is enough to classify.
Vec3 squaredSemiAxes(const Eigen::Matrix3d& a) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(a, Eigen::EigenvaluesOnly);
  return solver.eigenvalues();
}

// Whether every eigenvalue of the symmetric a lies strictly inside (lo, hi), by Sylvester's
// criterion on a - lo I and hi I - a (their leading principal minors positive): a few products
// instead of the closed-form eigenvalues' acos and cos. Callers pass a band shrunk by a relative
// 1e-6, far beyond the rounding of either method, so a shape it accepts is one the eigenvalues
// accept too; shapes near the band's edges go to the eigenvalues.
bool eigenvaluesWithin(const Eigen::Matrix3d& a, double lo, double hi) {
  auto positiveDefinite = [](const Eigen::Matrix3d& m) {
    return m(0, 0) > 0.0 && m(0, 0) * m(1, 1) - m(0, 1) * m(0, 1) > 0.0 && m.determinant() > 0.0;
  };
  const Eigen::Matrix3d identity = Eigen::Matrix3d::Identity();
  return positiveDefinite(a - lo * identity) && positiveDefinite(hi * identity - a);
}

void addParticle(MergeAccumulator& k, const GranularParticles& p, std::uint32_t j) {
  k.add(p.position[j].cast<double>(), p.velocity[j].cast<double>(), p.mass[j], shapeMatrix(p.shape[j]));
}

}  // namespace

bool isValidShape(const Eigen::Matrix3d& a, double radius) {
  const Vec3 l = squaredSemiAxes(a);
  const double r2 = radius * radius;
  return l[0] >= 0.5 * r2 && l[2] <= 2.0 * r2;
}

void MergeAccumulator::add(const Vec3& x, const Vec3& v, double m, const Eigen::Matrix3d& a) {
  const Vec3 y = x - origin_;
  mass_ += m;
  first_ += m * y;
  momentum_ += m * v;
  second_ += m * (a + y * y.transpose());
}

MergedParticle MergeAccumulator::result() const {
  const Vec3 c = first_ / mass_;
  return {origin_ + c, momentum_ / mass_, mass_, second_ / mass_ - c * c.transpose()};
}

MergedParticle mergeParticles(const Vec3& xi, const Vec3& vi, double mi, const Eigen::Matrix3d& ai, const Vec3& xj,
                              const Vec3& vj, double mj, const Eigen::Matrix3d& aj) {
  MergeAccumulator k(xi);
  k.add(xi, vi, mi, ai);
  k.add(xj, vj, mj, aj);
  return k.result();
}

SplitMerge::SplitMerge(double radius, int maxSplitDepth) : radius_(radius), maxSplitDepth_(maxSplitDepth) {
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw std::invalid_argument("split/merge: particle radius must be a finite number > 0, got " + std::to_string(radius));
  if (maxSplitDepth < 1 || maxSplitDepth > 3)
    throw std::invalid_argument("split/merge: split depth must lie in [1, 3], got " + std::to_string(maxSplitDepth));
}

double SplitMerge::maximumMergedMass(std::uint16_t material) const {
  // Widened by a relative 1e-6: masses are stored in float, so two particles of exactly half the
  // limit must not fail it by rounding.
  return material < maximumMergedMass_.size() ? maximumMergedMass_[material] * (1.0 + 1e-6)
                                              : std::numeric_limits<double>::infinity();
}

bool SplitMerge::surelyValid(const Eigen::Matrix3d& a) const {
  // Squared semi-axes in [r^2 / 2, 2 r^2], the band narrowed by a relative 1e-6.
  const double r2 = radius_ * radius_;
  return eigenvaluesWithin(a, 0.5 * r2 * (1.0 + 1e-6), 2.0 * r2 * (1.0 - 1e-6));
}

bool SplitMerge::valid(const Eigen::Matrix3d& a) const {
  // A diagonal entry is a Rayleigh quotient, so one outside the band puts an eigenvalue outside
  // it too: the common rejection (material squashed along a grid axis) without eigenvalues.
  const double r2 = radius_ * radius_;
  const Vec3 d = a.diagonal();
  if (d.minCoeff() < 0.5 * r2 || d.maxCoeff() > 2.0 * r2) return false;
  return surelyValid(a) || isValidShape(a, radius_);
}

Eigen::Matrix3d SplitMerge::regularized(const Eigen::Matrix3d& a) const {
  // The semi-axes clamped into [0.8 r, 1.25 r], the axes kept: well inside the valid band
  // [r / sqrt2, sqrt2 r], so that the next steps' deformation does not make it invalid again at
  // once (clamped to the band's edge, a particle in sustained shear left it again every step and
  // searched for merge partners every step). The accurate solver: near-equal and near-zero
  // eigenvalues are common here.
  const double r2 = radius_ * radius_;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(a);
  const Vec3 l = solver.eigenvalues().cwiseMax(0.64 * r2).cwiseMin(1.5625 * r2);
  return solver.eigenvectors() * l.asDiagonal() * solver.eigenvectors().transpose();
}

int SplitMerge::splitDepth(const Eigen::Matrix3d& a) const {
  // Each level quarters the largest eigenvalue and keeps the eigenvectors (A - 3/4 l e e^T).
  Vec3 l = squaredSemiAxes(a);
  const double r2 = radius_ * radius_;
  for (int depth = 1; depth <= maxSplitDepth_; ++depth) {
    Eigen::Index longest;
    l.maxCoeff(&longest);
    l[longest] *= 0.25;
    if (l.maxCoeff() <= 2.0 * r2) return l.minCoeff() >= 0.5 * r2 ? depth : 0;
  }
  return 0;
}

void SplitMerge::classify(const GranularParticles& particles) {
  const std::size_t n = particles.size();
  plan_.resize(n);
  depth_.resize(n);
  const double r2 = radius_ * radius_;
  parallelFor(0, n, [&](std::size_t i) {
    const Eigen::Matrix3d a = shapeMatrix(particles.shape[i]);
    // Most particles are well inside the valid band.
    if (surelyValid(a)) {
      depth_[i] = 0;
      plan_[i] = Plan::Keep;
      return;
    }
    const Vec3 l = squaredSemiAxes(a);
    int depth = l[2] > 2.0 * r2 ? splitDepth(a) : 0;
    if (depth > 0 && std::ldexp(static_cast<double>(particles.mass[i]), -depth) < minimumChildMass_) depth = 0;
    depth_[i] = static_cast<std::uint8_t>(depth);
    // No valid split (children too thin or too light): a too-small particle below the mass limit
    // looks for a merge (and is regularized if none is valid); any other is regularized at once.
    const bool mayMerge = l[0] < 0.5 * r2 && particles.mass[i] < maximumMergedMass(particles.material[i]);
    plan_[i] = depth > 0 ? Plan::Split : (mayMerge ? Plan::MergeCandidate : Plan::Regularize);
  });
  candidates_.clear();
  for (std::size_t i = 0; i < n; ++i)
    if (plan_[i] == Plan::MergeCandidate) candidates_.push_back(static_cast<std::uint32_t>(i));
}

void SplitMerge::proposeMerges(const GranularParticles& particles) {
  groups_.resize(candidates_.size());
  if (candidates_.empty()) return;
  // Two equal particles at distance d merge into one of semi-axis at least d/2 along their
  // separation, so no valid merge partner is farther than 2 sqrt2 r.
  const double reach = 2.0 * std::sqrt(2.0) * radius_, reach2 = reach * reach;
  cells_.build(particles.position, reach);
  parallelFor(0, candidates_.size(), [&](std::size_t c) {
    const std::uint32_t i = candidates_[c];
    const Vec3 xi = particles.position[i].cast<double>();
    // The kMergePartners nearest partners within reach, ordered by (distance, index): the set
    // does not depend on the order the cells are visited in.
    std::array<std::pair<double, std::uint32_t>, kMergePartners> nearest;
    int found = 0;
    const auto bound2 = [&] { return found < kMergePartners ? reach2 : nearest[kMergePartners - 1].first; };
    cells_.forEachNearWithin(xi, bound2, [&](std::uint32_t j) {
      if (j == i || particles.material[j] != particles.material[i] || plan_[j] == Plan::Split) return;
      const std::pair<double, std::uint32_t> key{(particles.position[j].cast<double>() - xi).squaredNorm(), j};
      if (key.first > reach2 || (found == kMergePartners && !(key < nearest[kMergePartners - 1]))) return;
      int at = found < kMergePartners ? found++ : kMergePartners - 1;
      for (; at > 0 && key < nearest[at - 1]; --at) nearest[at] = nearest[at - 1];
      nearest[at] = key;
    });
    MergeGroup& group = groups_[c];
    group.size = 0;
    const double maximumMass = maximumMergedMass(particles.material[i]), mi = particles.mass[i];
    // A pair first, the nearest partner that makes one valid particle.
    for (int k = 0; k < found; ++k) {
      if (mi + particles.mass[nearest[k].second] > maximumMass) continue;
      MergeAccumulator pair(xi);
      addParticle(pair, particles, i);
      addParticle(pair, particles, nearest[k].second);
      if (valid(pair.result().shape)) {
        group.size = 1;
        group.members[0] = nearest[k].second;
        return;
      }
    }
    // Then the nearest partners together: a particle squashed along more than one axis (a landed
    // cloud) grows by a merge only along the separation, so no pair can make it valid.
    MergeAccumulator all(xi);
    addParticle(all, particles, i);
    double mass = mi;
    for (int k = 0; k < found; ++k) {
      mass += particles.mass[nearest[k].second];
      if (mass > maximumMass) return;
      addParticle(all, particles, nearest[k].second);
      if (k > 0 && valid(all.result().shape)) {
        group.size = static_cast<std::uint8_t>(k + 1);
        for (int m = 0; m <= k; ++m) group.members[m] = nearest[m].second;
        return;
      }
    }
  }, 64);
}

std::size_t SplitMerge::acceptMerges() {
  // Serial, in candidate order, so that the grouping is deterministic: a proposal is accepted when
  // none of its particles is already in a group; the others wait for the next pass. The group
  // goes to its lowest index.
  groupOf_.resize(plan_.size());
  std::size_t merges = 0;
  const auto taken = [&](std::uint32_t p) { return plan_[p] == Plan::MergeOwner || plan_[p] == Plan::MergedAway; };
  for (std::size_t c = 0; c < candidates_.size(); ++c) {
    const MergeGroup& group = groups_[c];
    const std::uint32_t i = candidates_[c];
    if (taken(i)) continue;
    if (group.size == 0) {
      plan_[i] = Plan::Regularize;  // no valid merge exists for it
      continue;
    }
    const auto members = std::span(group.members).first(group.size);
    if (std::any_of(members.begin(), members.end(), taken)) continue;
    const std::uint32_t owner = std::min(i, *std::min_element(members.begin(), members.end()));
    plan_[i] = Plan::MergedAway;
    for (std::uint32_t j : members) plan_[j] = Plan::MergedAway;
    plan_[owner] = Plan::MergeOwner;
    groupOf_[owner] = static_cast<std::uint32_t>(c);
    ++merges;
  }
  return merges;
}

void SplitMerge::emit(const GranularParticles& in, GranularParticles& out) const {
  parallelFor(0, in.size(), [&](std::size_t i) {
    const std::uint32_t at = successors_[i].begin;
    switch (plan_[i]) {
      case Plan::Keep:
      case Plan::MergeCandidate:
        out.copyFrom(in, i, at);
        break;
      case Plan::MergedAway:
        break;
      case Plan::Regularize:
        out.copyFrom(in, i, at);
        out.shape[at] = toShape(regularized(shapeMatrix(in.shape[i])));
        break;
      case Plan::MergeOwner: {
        // The same sums in the same order as the proposal that found the group valid.
        const std::uint32_t c = groupOf_[i], first = candidates_[c];
        MergeAccumulator group(in.position[first].cast<double>());
        addParticle(group, in, first);
        for (std::uint8_t m = 0; m < groups_[c].size; ++m) addParticle(group, in, groups_[c].members[m]);
        const MergedParticle k = group.result();
        out.position[at] = k.position.cast<float>();
        out.velocity[at] = k.velocity.cast<float>();
        out.mass[at] = static_cast<float>(k.mass);
        out.shape[at] = toShape(k.shape);
        out.material[at] = in.material[i];
        break;
      }
      case Plan::Split: {
        // The accurate (iterative) solver for the directions: near-equal axes are common here.
        Eigen::Matrix3d a = shapeMatrix(in.shape[i]);
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(a);
        Vec3 l = solver.eigenvalues();
        Vec3 offset[8] = {Vec3::Zero()};
        int count = 1;
        for (int level = 0; level < depth_[i]; ++level) {
          Eigen::Index longest;
          l.maxCoeff(&longest);
          const Vec3 e = solver.eigenvectors().col(longest);
          const Vec3 d = 0.5 * std::sqrt(3.0 * l[longest]) * e;  // (sqrt3/2) a e
          for (int c = count - 1; c >= 0; --c) {
            offset[2 * c + 1] = offset[c] + d;
            offset[2 * c] = offset[c] - d;
          }
          count *= 2;
          a -= 0.75 * l[longest] * e * e.transpose();
          l[longest] *= 0.25;
        }
        const Vec3 x = in.position[i].cast<double>();
        const float m = in.mass[i] / static_cast<float>(count);  // exact: a power of two
        const ParticleShape child = toShape(a);
        for (int c = 0; c < count; ++c) {
          out.position[at + c] = (x + offset[c]).cast<float>();
          out.velocity[at + c] = in.velocity[i];
          out.mass[at + c] = m;
          out.shape[at + c] = child;
          out.material[at + c] = in.material[i];
        }
        break;
      }
    }
  }, 256);
}

SplitMergeStats SplitMerge::apply(GranularParticles& particles) {
  const std::size_t n = particles.size();
  classify(particles);
  proposeMerges(particles);
  SplitMergeStats stats;
  stats.merges = acceptMerges();

  // Slots of the new set: an exclusive prefix sum of each particle's output count.
  successors_.resize(n);
  std::uint32_t next = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t count = 1;
    if (plan_[i] == Plan::Split) {
      count = 1u << depth_[i];
      ++stats.splits;
      stats.children += count;
    } else if (plan_[i] == Plan::MergedAway) {
      count = 0;
    } else if (plan_[i] == Plan::Regularize) {
      ++stats.regularized;
    }
    successors_[i] = {next, count};
    next += count;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (plan_[i] != Plan::MergeOwner) continue;
    const std::uint32_t c = groupOf_[i];
    const MergeGroup& group = groups_[c];
    successors_[candidates_[c]] = {successors_[i].begin, 1};
    for (std::uint8_t m = 0; m < group.size; ++m) successors_[group.members[m]] = {successors_[i].begin, 1};
    stats.mergedAway += group.size;
  }

  if (stats.splits == 0 && stats.merges == 0 && stats.regularized == 0) return stats;
  out_.resize(next);
  emit(particles, out_);
  std::swap(particles, out_);
  return stats;
}

}  // namespace msim::granular
