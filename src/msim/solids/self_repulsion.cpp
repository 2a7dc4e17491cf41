#include "msim/solids/self_repulsion.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "msim/solids/collision/proximity.hpp"
#include "msim/solids/contact_stencil.hpp"

namespace msim::solids {

namespace {

// A pair's state at the current positions: the stencil of its relative position, the remembered
// normal and the gap along it (negative once crossed).
struct Contact {
  ContactStencil stencil;
  Vec3 normal;
  double gap = 0.0;
};

}  // namespace

void SelfRepulsion::findPairs(CollisionPairs& pairs, const std::vector<Vec3>& x, const std::vector<Vec3>& predicted) {
  mesh_ = &pairs;
  pairs.find(x, predicted, settings_.thickness, foundPointTriangle_, foundEdgeEdge_);
  pointTriangle_.clear();
  for (const PointTrianglePair& p : foundPointTriangle_) {
    const auto& t = pairs.triangles()[static_cast<std::size_t>(p.triangle)];
    const Vec3& a = x[static_cast<std::size_t>(t[0])];
    const double side = (x[static_cast<std::size_t>(t[1])] - a).cross(x[static_cast<std::size_t>(t[2])] - a).dot(x[static_cast<std::size_t>(p.point)] - a);
    pointTriangle_.push_back({p, side < 0.0});
  }
  edgeEdge_.clear();
  for (const EdgeEdgePair& p : foundEdgeEdge_) {
    const auto& e = pairs.edges()[static_cast<std::size_t>(p.first)];
    const auto& f = pairs.edges()[static_cast<std::size_t>(p.second)];
    const EdgeEdgeProximity prox = edgeEdgeProximity(x[static_cast<std::size_t>(e[0])], x[static_cast<std::size_t>(e[1])],
                                                     x[static_cast<std::size_t>(f[0])], x[static_cast<std::size_t>(f[1])]);
    edgeEdge_.push_back({p, prox.normal});
  }
}

int SelfRepulsion::repelPositionVelocity(const std::vector<Vec3>& x, std::vector<Vec3>& v,
                                         const std::vector<double>& inverseMass, double dt) const {
  apply(Pass::Inelastic, x, v, inverseMass, dt);
  return apply(Pass::Elastic, x, v, inverseMass, dt);
}

int SelfRepulsion::repelEndVelocity(const std::vector<Vec3>& x, std::vector<Vec3>& v,
                                    const std::vector<double>& inverseMass) const {
  return apply(Pass::EndOfStep, x, v, inverseMass, 0.0);
}

int SelfRepulsion::apply(Pass pass, const std::vector<Vec3>& x, std::vector<Vec3>& v,
                         const std::vector<double>& inverseMass, double dt) const {
  if (mesh_ == nullptr) return 0;
  const double h = settings_.thickness;
  int active = 0;
  const auto respond = [&](const Contact& c) {
    if (!(c.gap < h) || !(c.gap > -2.0 * h)) return;  // apart, or crossed deeper than repulsion can mend
    ++active;
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
  };
  for (const PointTriangleHistory& p : pointTriangle_) {
    const auto& t = mesh_->triangles()[static_cast<std::size_t>(p.pair.triangle)];
    const Vec3& xp = x[static_cast<std::size_t>(p.pair.point)];
    const Vec3 &a = x[static_cast<std::size_t>(t[0])], &b = x[static_cast<std::size_t>(t[1])], &c = x[static_cast<std::size_t>(t[2])];
    const PointTriangleProximity prox = pointTriangleProximity(xp, a, b, c);
    // Only where the point lies over the face: near an edge or a corner the edge pairs act.
    if (!(prox.weights.minCoeff() > 0.0)) continue;
    Vec3 normal = (b - a).cross(c - a);
    const double length = normal.norm();
    if (!(length > 0.0)) continue;
    normal /= p.flipped ? -length : length;
    const ContactStencil stencil = ContactStencil::pointTriangle(p.pair.point, t, prox.weights);
    respond({stencil, normal, stencil.relative(x).dot(normal)});
  }
  for (const EdgeEdgeHistory& p : edgeEdge_) {
    const auto& e = mesh_->edges()[static_cast<std::size_t>(p.pair.first)];
    const auto& f = mesh_->edges()[static_cast<std::size_t>(p.pair.second)];
    const EdgeEdgeProximity prox = edgeEdgeProximity(x[static_cast<std::size_t>(e[0])], x[static_cast<std::size_t>(e[1])],
                                                     x[static_cast<std::size_t>(f[0])], x[static_cast<std::size_t>(f[1])]);
    if (!(prox.s > 0.0 && prox.s < 1.0 && prox.t > 0.0 && prox.t < 1.0)) continue;  // end points: the point pairs act
    const bool crossed = p.side.dot(prox.normal) < settings_.edgeFlipEpsilon;
    respond({ContactStencil::edgeEdge(e, f, prox.s, prox.t), crossed ? Vec3(-prox.normal) : prox.normal,
             crossed ? -prox.distance : prox.distance});
  }
  return active;
}

}  // namespace msim::solids
