#include "msim/solids/self_collision.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "msim/core/parallel.hpp"
#include "msim/solids/collision/ccd.hpp"
#include "msim/solids/collision/impact_zone.hpp"
#include "msim/solids/collision/proximity.hpp"
#include "msim/solids/contact_stencil.hpp"
#include "msim/solids/mass_spring.hpp"

namespace msim::solids {

namespace {

template <typename Positions>
std::array<Vec3, 4> gatherPositions(const std::array<int, 4>& nodes, const Positions& x) {
  return {x[static_cast<std::size_t>(nodes[0])], x[static_cast<std::size_t>(nodes[1])], x[static_cast<std::size_t>(nodes[2])],
          x[static_cast<std::size_t>(nodes[3])]};
}

}  // namespace

std::array<int, 4> SelfCollisionResolver::particles(const CollisionPairs& pairs, const Crossing& c) const {
  if (c.pointTriangle) {
    const auto& t = pairs.triangles()[static_cast<std::size_t>(c.second)];
    return {c.first, t[0], t[1], t[2]};
  }
  const auto& e = pairs.edges()[static_cast<std::size_t>(c.first)];
  const auto& f = pairs.edges()[static_cast<std::size_t>(c.second)];
  return {e[0], e[1], f[0], f[1]};
}

void SelfCollisionResolver::detect(const CollisionPairs& pairs, const std::vector<Vec3>& x0, const std::vector<Vec3>& x1) {
  const std::size_t nPoint = candidatesPointTriangle_.size(), n = nPoint + candidatesEdgeEdge_.size();
  // Candidate k: the point-triangle pairs, then the edge-edge pairs.
  const auto candidate = [&](std::size_t k) {
    return k < nPoint ? Crossing{true, candidatesPointTriangle_[k].point, candidatesPointTriangle_[k].triangle}
                      : Crossing{false, candidatesEdgeEdge_[k - nPoint].first, candidatesEdgeEdge_[k - nPoint].second};
  };
  // One flag per candidate, filled in parallel, then read in order: deterministic. With a split,
  // each process tests the candidates of its own points and of the edges whose first vertex it
  // owns, and the crossings found are joined.
  const auto tests = [&](std::size_t k) {
    if (split_ == nullptr) return true;
    return k < nPoint ? CollisionPairs::isOwnPair(*split_, candidatesPointTriangle_[k])
                      : pairs.isOwnPair(*split_, candidatesEdgeEdge_[k - nPoint]);
  };
  hit_.assign(n, 0);
  parallelFor(
      0, n,
      [&](std::size_t k) {
        if (!tests(k)) return;
        const Crossing c = candidate(k);
        const std::array<int, 4> nodes = particles(pairs, c);
        const auto a0 = gatherPositions(nodes, x0), a1 = gatherPositions(nodes, x1);
        const auto t = c.pointTriangle ? pointTriangleCollisionTime(a0, a1, settings_.tolerance)
                                       : edgeEdgeCollisionTime(a0, a1, settings_.tolerance);
        hit_[k] = t.has_value() ? 1 : 0;
      },
      64);
  if (split_) {
    std::vector<double> found;
    for (std::size_t k = 0; k < n; ++k)
      if (hit_[k]) found.push_back(static_cast<double>(k));
    split_->gatherRows(found, 1);
    for (const double k : found) hit_[static_cast<std::size_t>(k)] = 1;
  }
  crossings_.clear();
  for (std::size_t k = 0; k < n; ++k)
    if (hit_[k]) crossings_.push_back(candidate(k));
}

bool SelfCollisionResolver::respond(const CollisionPairs& pairs, const Crossing& c, const std::vector<Vec3>& x0,
                                    std::vector<Vec3>& x1, double T, double innerDt, const RepulsionSettings& repulsion) {
  const std::array<int, 4> nodes = particles(pairs, c);
  const auto a0 = gatherPositions(nodes, x0), a1 = gatherPositions(nodes, x1);
  const auto when = c.pointTriangle ? pointTriangleCollisionTime(a0, a1, settings_.tolerance)
                                    : edgeEdgeCollisionTime(a0, a1, settings_.tolerance);
  if (!when) return false;
  std::array<Vec3, 4> at;
  for (int i = 0; i < 4; ++i) at[static_cast<std::size_t>(i)] = a0[static_cast<std::size_t>(i)] + *when * (a1[static_cast<std::size_t>(i)] - a0[static_cast<std::size_t>(i)]);
  // The pair's stencil and normal where they meet; the normal faces the side the pair started on.
  ContactStencil stencil;
  Vec3 normal;
  if (c.pointTriangle) {
    const PointTriangleProximity prox = pointTriangleProximity(at[0], at[1], at[2], at[3]);
    const auto& t = pairs.triangles()[static_cast<std::size_t>(c.second)];
    stencil = ContactStencil::pointTriangle(c.first, t, prox.weights);
    normal = prox.normal;
  } else {
    const EdgeEdgeProximity prox = edgeEdgeProximity(at[0], at[1], at[2], at[3]);
    stencil = ContactStencil::edgeEdge(pairs.edges()[static_cast<std::size_t>(c.first)],
                                       pairs.edges()[static_cast<std::size_t>(c.second)], prox.s, prox.t);
    normal = prox.normal;
  }
  const Vec3 start = stencil.relative(x0);
  if (start.dot(normal) < 0.0) normal = -normal;
  for (const int p : nodes) velocity_[static_cast<std::size_t>(p)] = (x1[static_cast<std::size_t>(p)] - x0[static_cast<std::size_t>(p)]) / T;
  const double im = stencil.inverseMass(inverseMass_);
  if (!(im > 0.0)) return true;  // all pinned: nothing can move (the scripted motion collides)
  double vN = stencil.relative(velocity_).dot(normal);
  if (vN < 0.0) {
    stencil.changeRelative(-vN * normal, inverseMass_, velocity_);
    vN = 0.0;
  }
  // Eq. 6.1 with the average inner step where the pair would end within the thickness.
  const double gap = start.dot(normal) + T * vN;
  const double d = repulsion.thickness - gap;
  if (d > 0.0) {
    const double cap = 0.1 * d / innerDt - vN;
    if (cap > 0.0) stencil.changeRelative(std::min(innerDt * repulsion.stiffness * d * im, cap) * normal, inverseMass_, velocity_);
  }
  for (const int p : nodes) {
    const auto q = static_cast<std::size_t>(p);
    if (inverseMass_[q] == 0.0) continue;
    x1[q] = x0[q] + T * velocity_[q];
    moved_[q] = 1;
  }
  return true;
}

SelfCollisionStats SelfCollisionResolver::resolve(CollisionPairs& pairs, const std::vector<Vec3>& x0, std::vector<Vec3>& x1,
                                                  const std::vector<double>& mass, const std::vector<char>& pinned, double T,
                                                  double innerDt, const RepulsionSettings& repulsion,
                                                  const BodyContact* bodies) {
  const std::size_t n = x0.size();
  inverseMasses(mass, pinned, inverseMass_);
  velocity_.assign(n, Vec3::Zero());
  SelfCollisionStats stats;
  movedThisPass_.assign(n, 1);
  ImpactZones zones(static_cast<int>(n));
  const int totalPasses = settings_.gaussSeidelPasses + settings_.impactZonePasses;
  for (int pass = 0; pass < totalPasses; ++pass) {
    pairs.find(x0, x1, settings_.tolerance, candidatesPointTriangle_, candidatesEdgeEdge_, pass == 0 ? nullptr : &movedThisPass_,
               split_);
    detect(pairs, x0, x1);
    ++stats.passes;
    stats.unresolved = static_cast<int>(crossings_.size());
    if (crossings_.empty()) break;
    stats.collisions += static_cast<int>(crossings_.size());
    moved_.assign(n, 0);
    if (pass < settings_.gaussSeidelPasses) {
      for (const Crossing& c : crossings_) respond(pairs, c, x0, x1, T, innerDt, repulsion);
      if (bodies)
        for (std::size_t p = 0; p < n; ++p)
          if (moved_[p]) bodies->pushOut(x1[p]);
    } else {
      for (const Crossing& c : crossings_) zones.addCollision(particles(pairs, c));
      const std::vector<std::vector<int>> all = zones.zones();
      stats.impactZones = static_cast<int>(all.size());
      stats.zoneParticles = 0;
      for (const auto& zone : all) {
        applyRigidImpactZone(zone, mass, pinned, x0, x1, T);
        stats.zoneParticles += static_cast<int>(zone.size());
        for (const int p : zone) moved_[static_cast<std::size_t>(p)] = 1;
      }
    }
    movedThisPass_ = moved_;
  }
  if (stats.unresolved > 0 && stats.passes == totalPasses) {
    // The last pass changed positions after its detection: look once more.
    pairs.find(x0, x1, settings_.tolerance, candidatesPointTriangle_, candidatesEdgeEdge_, &movedThisPass_, split_);
    detect(pairs, x0, x1);
    stats.unresolved = static_cast<int>(crossings_.size());
  }
  return stats;
}

}  // namespace msim::solids
