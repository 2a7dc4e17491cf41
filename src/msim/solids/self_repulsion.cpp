#include "msim/solids/self_repulsion.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include <Eigen/Geometry>

#include "msim/core/parallel.hpp"
#include "msim/solids/collision/proximity.hpp"

namespace msim::solids {

void SelfRepulsion::findPairs(CollisionPairs& pairs, const std::vector<Vec3>& x, const std::vector<Vec3>& predicted) {
  mesh_ = &pairs;
  pairs.find(x, predicted, settings_.thickness, foundPointTriangle_, foundEdgeEdge_);
  // Each pair's side in the collision-free state (eq. 6.2's history), on all cores.
  pointTriangle_.resize(foundPointTriangle_.size());
  parallelFor(0, foundPointTriangle_.size(), [&](std::size_t i) {
    const PointTrianglePair& p = foundPointTriangle_[i];
    const auto& t = pairs.triangles()[static_cast<std::size_t>(p.triangle)];
    const Vec3& a = x[static_cast<std::size_t>(t[0])];
    const double side = (x[static_cast<std::size_t>(t[1])] - a).cross(x[static_cast<std::size_t>(t[2])] - a).dot(x[static_cast<std::size_t>(p.point)] - a);
    pointTriangle_[i] = {p, side < 0.0};
  });
  edgeEdge_.resize(foundEdgeEdge_.size());
  parallelFor(0, foundEdgeEdge_.size(), [&](std::size_t i) {
    const EdgeEdgePair& p = foundEdgeEdge_[i];
    const auto& e = pairs.edges()[static_cast<std::size_t>(p.first)];
    const auto& f = pairs.edges()[static_cast<std::size_t>(p.second)];
    const EdgeEdgeProximity prox = edgeEdgeProximity(x[static_cast<std::size_t>(e[0])], x[static_cast<std::size_t>(e[1])],
                                                     x[static_cast<std::size_t>(f[0])], x[static_cast<std::size_t>(f[1])]);
    edgeEdge_[i] = {p, prox.normal};
  });
}

int SelfRepulsion::repelPositionVelocity(const std::vector<Vec3>& x, std::vector<Vec3>& v,
                                         const std::vector<double>& inverseMass, double dt) {
  gatherContacts(x);
  respond(Pass::Inelastic, v, inverseMass, dt);
  return respond(Pass::Elastic, v, inverseMass, dt);
}

int SelfRepulsion::repelEndVelocity(const std::vector<Vec3>& x, std::vector<Vec3>& v,
                                    const std::vector<double>& inverseMass) {
  gatherContacts(x);
  return respond(Pass::EndOfStep, v, inverseMass, 0.0);
}

// The geometry depends on the positions alone, which a pass leaves alone, so it is found for all
// pairs at once on all cores, block by block, and the blocks joined in the pairs' order (the
// Gauss-Seidel passes then see the contacts in the same order whatever the thread count).
void SelfRepulsion::gatherContacts(const std::vector<Vec3>& x) {
  contacts_.clear();
  if (mesh_ == nullptr) return;
  const double h = settings_.thickness;
  // Closer than h, and crossed by less than 2h (deeper than repulsion can mend: collisions act).
  const auto within = [h](double gap) { return gap < h && gap > -2.0 * h; };
  const auto& triangles = mesh_->triangles();
  const auto& edges = mesh_->edges();
  faceNormals_.resize(triangles.size());
  faceCentroids_.resize(triangles.size());
  faceRadii2_.resize(triangles.size());
  parallelFor(0, triangles.size(), [&](std::size_t i) {
    const auto& t = triangles[i];
    const Vec3 &a = x[static_cast<std::size_t>(t[0])], &b = x[static_cast<std::size_t>(t[1])], &c = x[static_cast<std::size_t>(t[2])];
    const Vec3 normal = (b - a).cross(c - a);
    const double length = normal.norm();
    faceNormals_[i] = length > 0.0 ? Vec3(normal / length) : Vec3::Zero();
    const Vec3 centroid = (a + b + c) / 3.0;
    faceCentroids_[i] = centroid;
    faceRadii2_[i] = std::max({(a - centroid).squaredNorm(), (b - centroid).squaredNorm(), (c - centroid).squaredNorm()});
  });
  edgeMidpoints_.resize(edges.size());
  edgeHalfLengths_.resize(edges.size());
  parallelFor(0, edges.size(), [&](std::size_t i) {
    const Vec3 &p0 = x[static_cast<std::size_t>(edges[i][0])], &p1 = x[static_cast<std::size_t>(edges[i][1])];
    edgeMidpoints_[i] = 0.5 * (p0 + p1);
    edgeHalfLengths_[i] = 0.5 * (p1 - p0).norm();
  });
  constexpr std::size_t kBlock = 2048;
  const std::size_t pointBlocks = (pointTriangle_.size() + kBlock - 1) / kBlock;
  const std::size_t edgeBlocks = (edgeEdge_.size() + kBlock - 1) / kBlock;
  blockContacts_.resize(std::max(blockContacts_.size(), pointBlocks + edgeBlocks));
  parallelFor(0, pointBlocks + edgeBlocks, [&](std::size_t block) {
    std::vector<Contact>& found = blockContacts_[block];
    found.clear();
    if (block < pointBlocks) {
      const std::size_t end = std::min(pointTriangle_.size(), (block + 1) * kBlock);
      for (std::size_t i = block * kBlock; i < end; ++i) {
        const PointTriangleHistory& p = pointTriangle_[i];
        const auto triangle = static_cast<std::size_t>(p.pair.triangle);
        const auto& t = triangles[triangle];
        const Vec3& xp = x[static_cast<std::size_t>(p.pair.point)];
        const Vec3& a = x[static_cast<std::size_t>(t[0])];
        if (faceNormals_[triangle].squaredNorm() == 0.0) continue;  // no area
        const Vec3 normal = p.flipped ? Vec3(-faceNormals_[triangle]) : faceNormals_[triangle];
        const double gap = (xp - a).dot(normal);  // the distance from the face along the remembered side
        if (!within(gap)) continue;
        // Only where the point lies over the face: near an edge or a corner the edge pairs act.
        // The face lies within its farthest corner's distance of its centroid, so a point whose
        // foot on the face's plane lies farther is not over it (most candidates of a flat cloth:
        // neighbours beside the face).
        if ((xp - faceCentroids_[triangle]).squaredNorm() - gap * gap > faceRadii2_[triangle]) continue;
        const std::optional<Vec3> weights =
            faceProjectionWeights(xp, a, x[static_cast<std::size_t>(t[1])], x[static_cast<std::size_t>(t[2])]);
        if (!weights || !(weights->minCoeff() > 0.0)) continue;
        found.push_back({ContactStencil::pointTriangle(p.pair.point, t, *weights), normal, gap});
      }
    } else {
      const std::size_t first = (block - pointBlocks) * kBlock;
      const std::size_t end = std::min(edgeEdge_.size(), first + kBlock);
      for (std::size_t i = first; i < end; ++i) {
        const EdgeEdgeHistory& p = edgeEdge_[i];
        const auto first = static_cast<std::size_t>(p.pair.first), second = static_cast<std::size_t>(p.pair.second);
        // Most candidate pairs are far apart: every point of an edge lies within half its length of
        // its midpoint, so the midpoints' distance less both half lengths bounds the gap from below.
        const double reach = 2.0 * h + edgeHalfLengths_[first] + edgeHalfLengths_[second];
        if ((edgeMidpoints_[first] - edgeMidpoints_[second]).squaredNorm() >= reach * reach) continue;
        const auto& e = edges[first];
        const auto& f = edges[second];
        const std::optional<EdgeEdgeProximity> interior =
            edgeEdgeInteriorProximity(x[static_cast<std::size_t>(e[0])], x[static_cast<std::size_t>(e[1])],
                                      x[static_cast<std::size_t>(f[0])], x[static_cast<std::size_t>(f[1])]);
        if (!interior) continue;  // closest at an end point: the point-face pairs act
        const EdgeEdgeProximity& prox = *interior;
        const bool crossed = p.side.dot(prox.normal) < settings_.edgeFlipEpsilon;
        const double gap = crossed ? -prox.distance : prox.distance;
        if (!within(gap)) continue;
        found.push_back({ContactStencil::edgeEdge(e, f, prox.s, prox.t), crossed ? Vec3(-prox.normal) : prox.normal, gap});
      }
    }
  }, 1);
  for (std::size_t block = 0; block < pointBlocks + edgeBlocks; ++block)
    contacts_.insert(contacts_.end(), blockContacts_[block].begin(), blockContacts_[block].end());
}

int SelfRepulsion::respond(Pass pass, std::vector<Vec3>& v, const std::vector<double>& inverseMass, double dt) const {
  const double h = settings_.thickness;
  for (const Contact& c : contacts_) {
    const double im = c.stencil.inverseMass(inverseMass);
    if (!(im > 0.0)) continue;
    const Vec3 rel = c.stencil.relative(v);
    const double vN = rel.dot(c.normal);
    switch (pass) {
      case Pass::Inelastic:
        if (vN < 0.0) c.stencil.changeRelative(-vN * c.normal, inverseMass, v);
        break;
      case Pass::Elastic: {
        const double d = h - c.gap;                     // eq. 6.2's overlap
        const double cap = 0.1 * d / dt - vN;           // eq. 6.1's bound, as a velocity change
        if (cap > 0.0) c.stencil.changeRelative(std::min(dt * settings_.stiffness * d * im, cap) * c.normal, inverseMass, v);
        break;
      }
      case Pass::EndOfStep: {
        if (!(vN < 0.0)) break;
        const Vec3 tangential = rel - vN * c.normal;
        const double speed = tangential.norm();
        Vec3 change = -vN * c.normal;
        if (speed > 0.0) change -= std::min(settings_.friction * -vN / speed, 1.0) * tangential;
        c.stencil.changeRelative(change, inverseMass, v);
        break;
      }
    }
  }
  return static_cast<int>(contacts_.size());
}

}  // namespace msim::solids
