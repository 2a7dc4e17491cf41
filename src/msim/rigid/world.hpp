#pragma once
// A set of rigid bodies in a domain of planes, with hinges. One step(dt):
//   1. integrateVelocity (gravity, external force/torque)          -- symplectic Euler kick
//   2. contacts: every dynamic body vs every plane, body pairs from the broad phase
//   3. solveConstraints (hinges + contacts with friction, restitution, Baumgarte)
//   4. integratePosition (x += dt v, L-conserving midpoint rotation), clears force/torque
// A granular or fluid coupling (Narain 2011 eq. 5.23) adds its impulse dt*F with
// RigidBody::applyImpulse between steps, or sets force/torque before step().
#include <map>
#include <utility>
#include <vector>

#include "msim/rigid/collision.hpp"
#include "msim/rigid/constraint_solver.hpp"
#include "msim/rigid/hinge.hpp"
#include "msim/rigid/rigid_body.hpp"

namespace msim::rigid {

struct WorldSettings {
  Vec3 gravity{0.0, 0.0, -9.81};
  double contactMargin = 1e-6;  // [m] gap within which speculative contacts are kept
  SolverSettings solver;
};

class World {
 public:
  explicit World(WorldSettings settings = {}) : settings_(std::move(settings)) {}

  int addBody(RigidBody body);  // returns its index
  void addPlane(const Plane& plane);
  // Six inward walls of [lo, hi] (InputError unless lo < hi componentwise).
  void addDomainBox(const Vec3& lo, const Vec3& hi, const Material& material = {});
  int addHinge(int body, const Vec3& pivot, const Vec3& axis);
  // Friction of the pair (a, b); b = kWorld sets it for a against every plane.
  void setPairFriction(int a, int b, double mu);

  // Advances by dt (InputError for dt <= 0).
  void step(double dt);

  std::vector<RigidBody>& bodies() { return bodies_; }
  const std::vector<RigidBody>& bodies() const { return bodies_; }
  RigidBody& body(int i) { return bodies_.at(i); }
  const std::vector<Plane>& planes() const { return planes_; }
  const std::vector<Contact>& lastContacts() const { return contacts_; }
  WorldSettings& settings() { return settings_; }

 private:
  void findContacts();
  void setMaterial(Contact& c, const Material& ma, const Material& mb) const;

  WorldSettings settings_;
  std::vector<RigidBody> bodies_;
  std::vector<Plane> planes_;
  std::vector<Hinge> hinges_;
  std::map<std::pair<int, int>, double> pairFriction_;
  std::vector<Contact> contacts_;
};

}  // namespace msim::rigid
