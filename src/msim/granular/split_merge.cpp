#include "msim/granular/split_merge.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Eigenvalues>

#include "msim/core/parallel.hpp"

namespace msim::granular {

namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

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

}  // namespace

bool isValidShape(const Eigen::Matrix3d& a, double radius) {
  const Vec3 l = squaredSemiAxes(a);
  const double r2 = radius * radius;
  return l[0] >= 0.5 * r2 && l[2] <= 2.0 * r2;
}

MergedParticle mergeParticles(const Vec3& xi, const Vec3& vi, double mi, const Eigen::Matrix3d& ai, const Vec3& xj,
                              const Vec3& vj, double mj, const Eigen::Matrix3d& aj) {
  MergedParticle k;
  k.mass = mi + mj;
  k.position = (mi * xi + mj * xj) / k.mass;
  k.velocity = (mi * vi + mj * vj) / k.mass;
  const Vec3 di = xi - k.position, dj = xj - k.position;
  k.shape = (mi * (ai + di * di.transpose()) + mj * (aj + dj * dj.transpose())) / k.mass;
  return k;
}

SplitMerge::SplitMerge(double radius, int maxSplitDepth) : radius_(radius), maxSplitDepth_(maxSplitDepth) {
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw std::invalid_argument("split/merge: particle radius must be a finite number > 0, got " + std::to_string(radius));
  if (maxSplitDepth < 1 || maxSplitDepth > 3)
    throw std::invalid_argument("split/merge: split depth must lie in [1, 3], got " + std::to_string(maxSplitDepth));
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
    // Most particles are well inside the valid band (squared semi-axes in [r^2 / 2, 2 r^2]).
    if (eigenvaluesWithin(a, 0.5 * r2 * (1.0 + 1e-6), 2.0 * r2 * (1.0 - 1e-6))) {
      depth_[i] = 0;
      plan_[i] = Plan::Keep;
      return;
    }
    const Vec3 l = squaredSemiAxes(a);
    int depth = l[2] > 2.0 * r2 ? splitDepth(a) : 0;
    if (depth > 0 && std::ldexp(static_cast<double>(particles.mass[i]), -depth) < minimumChildMass_) depth = 0;
    depth_[i] = static_cast<std::uint8_t>(depth);
    plan_[i] = depth > 0 ? Plan::Split : (l[0] < 0.5 * r2 ? Plan::MergeCandidate : Plan::Keep);
  });
  candidates_.clear();
  for (std::size_t i = 0; i < n; ++i)
    if (plan_[i] == Plan::MergeCandidate) candidates_.push_back(static_cast<std::uint32_t>(i));
}

void SplitMerge::proposeMerges(const GranularParticles& particles) {
  proposal_.resize(candidates_.size());
  if (candidates_.empty()) return;
  // Two equal particles at distance d merge into one of semi-axis at least d/2 along their
  // separation, so no valid merge partner is farther than 2 sqrt2 r.
  const double reach = 2.0 * std::sqrt(2.0) * radius_;
  cells_.build(particles.position, reach);
  parallelFor(0, candidates_.size(), [&](std::size_t c) {
    const std::uint32_t i = candidates_[c];
    const Vec3 xi = particles.position[i].cast<double>();
    std::uint32_t best = kNone;
    double bestDistance2 = reach * reach;
    cells_.forEachNearWithin(xi, [&] { return bestDistance2; }, [&](std::uint32_t j) {
      if (j == i || particles.material[j] != particles.material[i] || plan_[j] == Plan::Split) return;
      const double d2 = (particles.position[j].cast<double>() - xi).squaredNorm();
      if (d2 < bestDistance2 || (d2 == bestDistance2 && j < best)) {
        bestDistance2 = d2;
        best = j;
      }
    });
    if (best != kNone) {
      const MergedParticle k = mergeParticles(
          xi, particles.velocity[i].cast<double>(), particles.mass[i], shapeMatrix(particles.shape[i]),
          particles.position[best].cast<double>(), particles.velocity[best].cast<double>(), particles.mass[best],
          shapeMatrix(particles.shape[best]));
      if (!isValidShape(k.shape, radius_)) best = kNone;
    }
    proposal_[c] = best;
  }, 64);
}

std::size_t SplitMerge::acceptMerges() {
  // Serial, in candidate order, so that the pairing is deterministic: a proposal is accepted when
  // neither particle is already in a pair; the others wait for the next pass.
  partnerOf_.resize(plan_.size());
  std::size_t merges = 0;
  for (std::size_t c = 0; c < candidates_.size(); ++c) {
    const std::uint32_t i = candidates_[c], j = proposal_[c];
    if (j == kNone) continue;
    const auto taken = [&](std::uint32_t p) { return plan_[p] == Plan::MergeOwner || plan_[p] == Plan::MergedAway; };
    if (taken(i) || taken(j)) continue;
    const std::uint32_t owner = std::min(i, j), other = std::max(i, j);
    plan_[owner] = Plan::MergeOwner;
    plan_[other] = Plan::MergedAway;
    partnerOf_[owner] = other;
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
      case Plan::MergeOwner: {
        const std::uint32_t j = partnerOf_[i];
        const MergedParticle k = mergeParticles(
            in.position[i].cast<double>(), in.velocity[i].cast<double>(), in.mass[i], shapeMatrix(in.shape[i]),
            in.position[j].cast<double>(), in.velocity[j].cast<double>(), in.mass[j], shapeMatrix(in.shape[j]));
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
    }
    successors_[i] = {next, count};
    next += count;
  }
  for (std::size_t i = 0; i < n; ++i)
    if (plan_[i] == Plan::MergeOwner) successors_[partnerOf_[i]] = {successors_[i].begin, 1};

  if (stats.splits == 0 && stats.merges == 0) return stats;
  out_.resize(next);
  emit(particles, out_);
  std::swap(particles, out_);
  return stats;
}

}  // namespace msim::granular
