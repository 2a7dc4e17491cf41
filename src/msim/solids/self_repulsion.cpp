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
  gatheredValid_ = false;  // new pairs: the next gathering examines them all
  pairs.find(x, predicted, settings_.thickness, foundPointTriangle_, foundEdgeEdge_, nullptr, split_);
  // Each pair's side in the collision-free state (eq. 6.2's history), on all cores; with a split,
  // of the pairs this process examines.
  pointTriangle_.resize(foundPointTriangle_.size());
  edgeEdge_.resize(foundEdgeEdge_.size());
  for (std::size_t i = 0; i < foundPointTriangle_.size(); ++i) pointTriangle_[i].pair = foundPointTriangle_[i];
  for (std::size_t i = 0; i < foundEdgeEdge_.size(); ++i) edgeEdge_[i].pair = foundEdgeEdge_[i];
  parallelFor(0, foundPointTriangle_.size(), [&](std::size_t i) {
    if (!examines(i)) return;
    const PointTrianglePair& p = foundPointTriangle_[i];
    const auto& t = pairs.triangles()[static_cast<std::size_t>(p.triangle)];
    const Vec3& a = x[static_cast<std::size_t>(t[0])];
    const double side = (x[static_cast<std::size_t>(t[1])] - a).cross(x[static_cast<std::size_t>(t[2])] - a).dot(x[static_cast<std::size_t>(p.point)] - a);
    pointTriangle_[i].flipped = side < 0.0;
  });
  parallelFor(0, foundEdgeEdge_.size(), [&](std::size_t i) {
    if (!examines(foundPointTriangle_.size() + i)) return;
    const EdgeEdgePair& p = foundEdgeEdge_[i];
    const auto& e = pairs.edges()[static_cast<std::size_t>(p.first)];
    const auto& f = pairs.edges()[static_cast<std::size_t>(p.second)];
    const EdgeEdgeProximity prox = edgeEdgeProximity(x[static_cast<std::size_t>(e[0])], x[static_cast<std::size_t>(e[1])],
                                                     x[static_cast<std::size_t>(f[0])], x[static_cast<std::size_t>(f[1])]);
    edgeEdge_[i].side = prox.normal;
  });
}

bool SelfRepulsion::examines(std::size_t pair) const {
  if (split_ == nullptr) return true;
  if (pair < pointTriangle_.size()) return CollisionPairs::isOwnPair(*split_, pointTriangle_[pair].pair);
  return mesh_->isOwnPair(*split_, edgeEdge_[pair - pointTriangle_.size()].pair);
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
// Consecutive gatherings over the same pairs (the end of one inner step, B.8, and the start of the
// next, B.2) mostly see the same positions: only strain limiting and the bodies' push-out move
// particles in between. A pair none of whose particles moved keeps what the last gathering found
// for it (its face's or edges' frame depends on its particles alone), so only the others are
// examined again: the result is the same as examining all.
void SelfRepulsion::gatherContacts(const std::vector<Vec3>& x) {
  if (mesh_ == nullptr) {
    contacts_.clear();
    contactParticles_.clear();
    return;
  }
  bool incremental = gatheredValid_ && gatheredAt_.size() == x.size();
  if (incremental) {
    moved_.resize(x.size());
    parallelFor(0, x.size(), [&](std::size_t v) { moved_[v] = x[v] != gatheredAt_[v]; });
    const auto movedCount = static_cast<std::size_t>(std::count(moved_.begin(), moved_.end(), char{1}));
    if (movedCount == 0) return;
    incremental = 2 * movedCount < x.size();  // most moved: examining all is cheaper than sorting them out
  }
  gatheredAt_ = x;
  gatheredValid_ = true;
  const auto moved = [&](int v) { return !incremental || moved_[static_cast<std::size_t>(v)] != 0; };
  const double h = settings_.thickness;
  // Closer than h, and crossed by less than 2h (deeper than repulsion can mend: collisions act).
  const auto within = [h](double gap) { return gap < h && gap > -2.0 * h; };
  const auto& triangles = mesh_->triangles();
  const auto& edges = mesh_->edges();
  faces_.resize(triangles.size());
  parallelFor(0, triangles.size(), [&](std::size_t i) {
    const auto& t = triangles[i];
    const Vec3 &a = x[static_cast<std::size_t>(t[0])], &b = x[static_cast<std::size_t>(t[1])], &c = x[static_cast<std::size_t>(t[2])];
    const Vec3 normal = (b - a).cross(c - a);
    const double length = normal.norm();
    const Vec3 centroid = (a + b + c) / 3.0;
    faces_[i] = {length > 0.0 ? Vec3(normal / length) : Vec3::Zero(), centroid,
                 std::max({(a - centroid).squaredNorm(), (b - centroid).squaredNorm(), (c - centroid).squaredNorm()})};
  });
  edgeSpheres_.resize(edges.size());
  parallelFor(0, edges.size(), [&](std::size_t i) {
    const Vec3 &p0 = x[static_cast<std::size_t>(edges[i][0])], &p1 = x[static_cast<std::size_t>(edges[i][1])];
    edgeSpheres_[i] = {0.5 * (p0 + p1), 0.5 * (p1 - p0).norm()};
  });
  // The contact of point-triangle pair i, if any, into `found` (pairs are numbered points first,
  // then edges).
  const auto examinePointTriangle = [&](std::size_t i, std::vector<Contact>& found) {
    const PointTriangleHistory& p = pointTriangle_[i];
    const auto triangle = static_cast<std::size_t>(p.pair.triangle);
    const auto& t = triangles[triangle];
    const Vec3& xp = x[static_cast<std::size_t>(p.pair.point)];
    const Vec3& a = x[static_cast<std::size_t>(t[0])];
    const FaceFrame& face = faces_[triangle];
    if (face.normal.squaredNorm() == 0.0) return;  // no area
    const Vec3 normal = p.flipped ? Vec3(-face.normal) : face.normal;
    const double gap = (xp - a).dot(normal);  // the distance from the face along the remembered side
    if (!within(gap)) return;
    // Only where the point lies over the face: near an edge or a corner the edge pairs act.
    // The face lies within its farthest corner's distance of its centroid, so a point whose
    // foot on the face's plane lies farther is not over it (most candidates of a flat cloth:
    // neighbours beside the face).
    if ((xp - face.centroid).squaredNorm() - gap * gap > face.radius2) return;
    const std::optional<Vec3> weights =
        faceProjectionWeights(xp, a, x[static_cast<std::size_t>(t[1])], x[static_cast<std::size_t>(t[2])]);
    if (!weights || !(weights->minCoeff() > 0.0)) return;
    found.push_back({ContactStencil::pointTriangle(p.pair.point, t, *weights), normal, gap, static_cast<int>(i)});
  };
  const auto examineEdgeEdge = [&](std::size_t i, std::vector<Contact>& found) {
    const EdgeEdgeHistory& p = edgeEdge_[i];
    const auto first = static_cast<std::size_t>(p.pair.first), second = static_cast<std::size_t>(p.pair.second);
    // Most candidate pairs are far apart: every point of an edge lies within half its length of
    // its midpoint, so the midpoints' distance less both half lengths bounds the gap from below.
    const EdgeSphere &one = edgeSpheres_[first], &other = edgeSpheres_[second];
    const double reach = 2.0 * h + one.halfLength + other.halfLength;
    if ((one.midpoint - other.midpoint).squaredNorm() >= reach * reach) return;
    const auto& e = edges[first];
    const auto& f = edges[second];
    const std::optional<EdgeEdgeProximity> interior =
        edgeEdgeInteriorProximity(x[static_cast<std::size_t>(e[0])], x[static_cast<std::size_t>(e[1])],
                                  x[static_cast<std::size_t>(f[0])], x[static_cast<std::size_t>(f[1])], 2.0 * h);
    if (!interior) return;  // closest at an end point (the point-face pairs act), or beyond any gap within()
    const EdgeEdgeProximity& prox = *interior;
    const bool crossed = p.side.dot(prox.normal) < settings_.edgeFlipEpsilon;
    const double gap = crossed ? -prox.distance : prox.distance;
    if (!within(gap)) return;
    found.push_back({ContactStencil::edgeEdge(e, f, prox.s, prox.t), crossed ? Vec3(-prox.normal) : prox.normal, gap,
                     static_cast<int>(pointTriangle_.size() + i)});
  };
  const auto pairMoved = [&](std::size_t i) {
    if (i < pointTriangle_.size()) {
      const PointTrianglePair& p = pointTriangle_[i].pair;
      const auto& t = triangles[static_cast<std::size_t>(p.triangle)];
      return moved(p.point) || moved(t[0]) || moved(t[1]) || moved(t[2]);
    }
    const EdgeEdgePair& p = edgeEdge_[i - pointTriangle_.size()].pair;
    const auto &e = edges[static_cast<std::size_t>(p.first)], &f = edges[static_cast<std::size_t>(p.second)];
    return moved(e[0]) || moved(e[1]) || moved(f[0]) || moved(f[1]);
  };
  // With a split, the contacts each process examined are joined below.
  constexpr std::size_t kBlock = 2048;
  const std::size_t pairs = pointTriangle_.size() + edgeEdge_.size();
  const std::size_t blocks = (pairs + kBlock - 1) / kBlock;
  blockContacts_.resize(std::max(blockContacts_.size(), blocks));
  parallelFor(0, blocks, [&](std::size_t block) {
    std::vector<Contact>& found = blockContacts_[block];
    found.clear();
    const std::size_t first = block * kBlock, end = std::min(pairs, first + kBlock);
    // The last gathering's contacts in this block (they are in the pairs' order).
    auto kept = std::lower_bound(contacts_.begin(), contacts_.end(), static_cast<int>(first),
                                 [](const Contact& c, int pair) { return c.pair < pair; });
    for (std::size_t i = first; i < end; ++i) {
      if (!examines(i)) continue;
      if (incremental && !pairMoved(i)) {
        while (kept != contacts_.end() && kept->pair < static_cast<int>(i)) ++kept;
        if (kept != contacts_.end() && kept->pair == static_cast<int>(i)) found.push_back(*kept);
      } else if (i < pointTriangle_.size()) {
        examinePointTriangle(i, found);
      } else {
        examineEdgeEdge(i - pointTriangle_.size(), found);
      }
    }
  }, 1);
  contacts_.clear();
  for (std::size_t block = 0; block < blocks; ++block)
    contacts_.insert(contacts_.end(), blockContacts_[block].begin(), blockContacts_[block].end());
  if (split_) joinContacts();
}

// Every process's contacts as rows of 13 doubles (particles, weights, normal, gap, pair), joined on
// every process and put in the pairs' order: the contacts one process alone finds.
void SelfRepulsion::joinContacts() {
  constexpr int kWidth = 13;
  std::vector<double>& rows = contactRows_;
  rows.clear();
  for (const Contact& c : contacts_) {
    for (int k = 0; k < 4; ++k) rows.push_back(c.stencil.node[static_cast<std::size_t>(k)]);
    rows.insert(rows.end(), c.stencil.weight.begin(), c.stencil.weight.end());
    rows.insert(rows.end(), {c.normal[0], c.normal[1], c.normal[2], c.gap, double(c.pair)});
  }
  split_->gatherRows(rows, kWidth);
  contacts_.resize(rows.size() / kWidth);
  for (std::size_t i = 0; i < contacts_.size(); ++i) {
    const double* row = rows.data() + kWidth * i;
    Contact& c = contacts_[i];
    for (std::size_t k = 0; k < 4; ++k) {
      c.stencil.node[k] = static_cast<int>(row[k]);
      c.stencil.weight[k] = row[4 + k];
    }
    c.normal = Vec3(row[8], row[9], row[10]);
    c.gap = row[11];
    c.pair = static_cast<int>(row[12]);
  }
  std::sort(contacts_.begin(), contacts_.end(), [](const Contact& a, const Contact& b) { return a.pair < b.pair; });
  contactParticles_.resize(contacts_.size());
  for (std::size_t i = 0; i < contacts_.size(); ++i) contactParticles_[i] = contacts_[i].stencil.node;
}

int SelfRepulsion::respond(Pass pass, std::vector<Vec3>& v, const std::vector<double>& inverseMass, double dt) const {
  if (split_) {
    split_->gaussSeidel(contactParticles_, v, [&](std::size_t i) { respond(pass, contacts_[i], v, inverseMass, dt); });
  } else {
    for (const Contact& c : contacts_) respond(pass, c, v, inverseMass, dt);
  }
  return static_cast<int>(contacts_.size());
}

void SelfRepulsion::respond(Pass pass, const Contact& c, std::vector<Vec3>& v, const std::vector<double>& inverseMass,
                            double dt) const {
  const double h = settings_.thickness;
  const double im = c.stencil.inverseMass(inverseMass);
  if (!(im > 0.0)) return;
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

}  // namespace msim::solids
