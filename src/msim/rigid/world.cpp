#include "msim/rigid/world.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "msim/core/error.hpp"
#include "msim/rigid/broad_phase.hpp"
#include "msim/rigid/integrator.hpp"

namespace msim::rigid {

int World::addBody(RigidBody body) {
  bodies_.push_back(std::move(body));
  return static_cast<int>(bodies_.size()) - 1;
}

void World::addPlane(const Plane& plane) {
  if (!(plane.normal.norm() > 0.0) || !plane.normal.allFinite() || !std::isfinite(plane.offset))
    throw InputError("rigid plane: normal must be a finite non-zero vector");
  Plane p = plane;
  const double len = p.normal.norm();
  p.normal /= len;
  p.offset /= len;
  planes_.push_back(p);
}

void World::addDomainBox(const Vec3& lo, const Vec3& hi, const Material& material) {
  if (!(lo.array() < hi.array()).all())
    throw InputError("rigid domain box: lo must be below hi on every axis");
  for (const Plane& p : domainWalls(lo, hi, material)) addPlane(p);
}

int World::addHinge(int body, const Vec3& pivot, const Vec3& axis) {
  hinges_.push_back(makeHinge(bodies_.at(body), body, pivot, axis));
  return static_cast<int>(hinges_.size()) - 1;
}

void World::setPairFriction(int a, int b, double mu) {
  if (!(mu >= 0.0) || !std::isfinite(mu))
    throw InputError("rigid friction coefficient must be >= 0, got " + std::to_string(mu));
  pairFriction_[{std::min(a, b), std::max(a, b)}] = mu;
}

void World::setMaterial(Contact& c, const Material& ma, const Material& mb) const {
  const auto it = pairFriction_.find({std::min(c.a, c.b), std::max(c.a, c.b)});
  c.friction = it != pairFriction_.end() ? it->second : std::sqrt(ma.friction * mb.friction);
  c.restitution = std::max(ma.restitution, mb.restitution);
}

void World::findContacts() {
  contacts_.clear();
  const int n = static_cast<int>(bodies_.size());
  const double margin = settings_.contactMargin;
  for (int i = 0; i < n; ++i) {
    if (bodies_[i].isStatic()) continue;
    for (const Plane& plane : planes_) {
      const std::size_t first = contacts_.size();
      collidePlane(bodies_[i], i, plane, margin, contacts_);
      for (std::size_t k = first; k < contacts_.size(); ++k)
        setMaterial(contacts_[k], bodies_[i].material, plane.material);
    }
  }
  std::vector<Vec3> centres(n);
  std::vector<double> radii(n);
  std::vector<char> skip(n);
  for (int i = 0; i < n; ++i) {
    centres[i] = bodies_[i].position;
    radii[i] = boundingRadius(bodies_[i].shape());
    skip[i] = bodies_[i].isStatic();
  }
  for (const auto& [i, j] : overlappingPairs(centres, radii, skip, margin)) {
    const std::size_t first = contacts_.size();
    collidePair(bodies_[i], i, bodies_[j], j, margin, contacts_);
    for (std::size_t k = first; k < contacts_.size(); ++k)
      setMaterial(contacts_[k], bodies_[contacts_[k].a].material, bodies_[contacts_[k].b].material);
  }
}

void World::step(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw InputError("rigid world: time step must be positive, got " + std::to_string(dt));
  for (RigidBody& b : bodies_) integrateVelocity(b, settings_.gravity, dt);
  findContacts();
  solveConstraints(bodies_, contacts_, hinges_, settings_.solver, dt);
  for (RigidBody& b : bodies_) integratePosition(b, dt);
}

}  // namespace msim::rigid
