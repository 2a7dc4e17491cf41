#include "msim/solids/mass_spring.hpp"

#include <stdexcept>

#include "msim/solids/altitude_spring.hpp"

namespace msim::solids {

void inverseMasses(const std::vector<double>& mass, const std::vector<char>& pinned, std::vector<double>& out) {
  out.resize(mass.size());
  for (std::size_t p = 0; p < mass.size(); ++p) out[p] = pinned[p] ? 0.0 : 1.0 / mass[p];
}

int MassSpringSystem::addParticle(const Vec3& position, double particleMass, const Vec3& velocity) {
  if (!(particleMass > 0.0)) throw std::invalid_argument("mass-spring system: a particle's mass must be > 0");
  x.push_back(position);
  v.push_back(velocity);
  mass.push_back(particleMass);
  pinned.push_back(0);
  return static_cast<int>(x.size()) - 1;
}

void MassSpringSystem::addSpring(int a, int b, double stiffness, double damping) {
  const int n = static_cast<int>(x.size());
  if (a < 0 || b < 0 || a >= n || b >= n || a == b)
    throw std::invalid_argument("mass-spring system: a spring needs two different particles");
  if (!(stiffness >= 0.0) || !(damping >= 0.0))
    throw std::invalid_argument("mass-spring system: stiffness and damping must be >= 0");
  const double length = (x[b] - x[a]).norm();
  if (!(length > 0.0)) throw std::invalid_argument("mass-spring system: a spring between coincident particles");
  springs.push_back({a, b, length, stiffness, damping});
}

void MassSpringSystem::addTetrahedron(const std::array<int, 4>& v, double stiffness, double damping) {
  const int n = static_cast<int>(x.size());
  for (int i = 0; i < 4; ++i) {
    if (v[i] < 0 || v[i] >= n) throw std::invalid_argument("mass-spring system: a tetrahedron's vertex is out of range");
    for (int j = 0; j < i; ++j)
      if (v[i] == v[j]) throw std::invalid_argument("mass-spring system: a tetrahedron repeats a vertex");
  }
  if (!(stiffness >= 0.0) || !(damping >= 0.0))
    throw std::invalid_argument("mass-spring system: stiffness and damping must be >= 0");
  const std::array<Vec3, 4> rest = {x[v[0]], x[v[1]], x[v[2]], x[v[3]]};
  TetrahedronSpring t{v, {}, stiffness, damping};
  for (int c = 0; c < 7; ++c) {
    t.restAltitude[static_cast<std::size_t>(c)] = candidateAltitude(rest, c);
    if (!(t.restAltitude[static_cast<std::size_t>(c)] > 0.0))
      throw std::invalid_argument("mass-spring system: a tetrahedron is inverted or flat in its rest shape");
  }
  tetrahedra.push_back(t);
}

void MassSpringSystem::explicitForces(const std::vector<Vec3>& at, std::vector<Vec3>& force) const {
  force.resize(at.size());
  for (std::size_t p = 0; p < at.size(); ++p) force[p] = mass[p] * gravity + (external.empty() ? Vec3(Vec3::Zero()) : external[p]);
  for (const Spring& s : springs) {
    const Vec3 d = at[s.b] - at[s.a];
    const double length = d.norm();
    if (!(length > 0.0)) continue;  // coincident: no direction to pull along
    const Vec3 f = s.stiffness * (length / s.restLength - 1.0) * (d / length);
    force[s.a] += f;
    force[s.b] -= f;
  }
  for (const TetrahedronSpring& t : tetrahedra) {
    const AltitudeChoice a = chooseAltitude({at[t.v[0]], at[t.v[1]], at[t.v[2]], at[t.v[3]]});
    if (a.candidate < 0) continue;
    const double strainNow = a.altitude / t.restAltitude[static_cast<std::size_t>(a.candidate)] - 1.0;
    for (int i = 0; i < 4; ++i) force[t.v[i]] -= a.weights[static_cast<std::size_t>(i)] * t.stiffness * strainNow * a.normal;
  }
}

Vec3 MassSpringSystem::meanVelocity() const { return meanVelocity(v); }

Vec3 MassSpringSystem::meanVelocity(const std::vector<Vec3>& velocities) const {
  Vec3 momentum = Vec3::Zero();
  double total = 0.0;
  for (std::size_t p = 0; p < size(); ++p) {
    momentum += mass[p] * velocities[p];
    total += mass[p];
  }
  return total > 0.0 ? Vec3(momentum / total) : Vec3(Vec3::Zero());
}

double MassSpringSystem::kineticEnergy() const {
  double e = 0.0;
  for (std::size_t p = 0; p < x.size(); ++p) e += 0.5 * mass[p] * v[p].squaredNorm();
  return e;
}

double MassSpringSystem::potentialEnergy() const {
  double e = 0.0;
  for (std::size_t s = 0; s < springs.size(); ++s) {
    const double strainNow = strain(s);
    e += 0.5 * springs[s].stiffness * springs[s].restLength * strainNow * strainNow;
  }
  for (const TetrahedronSpring& t : tetrahedra) {
    const AltitudeChoice a = chooseAltitude({x[t.v[0]], x[t.v[1]], x[t.v[2]], x[t.v[3]]});
    if (a.candidate < 0) continue;
    const double l0 = t.restAltitude[static_cast<std::size_t>(a.candidate)], s = a.altitude / l0 - 1.0;
    e += 0.5 * t.stiffness * l0 * s * s;
  }
  for (std::size_t p = 0; p < x.size(); ++p) e -= mass[p] * gravity.dot(x[p]);
  return e;
}

double MassSpringSystem::strain(std::size_t s) const {
  const Spring& spring = springs[s];
  return (x[spring.b] - x[spring.a]).norm() / spring.restLength - 1.0;
}

}  // namespace msim::solids
