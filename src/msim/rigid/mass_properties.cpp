#include "msim/rigid/mass_properties.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "msim/core/error.hpp"
#include "msim/rigid/polyhedron.hpp"

namespace msim::rigid {
namespace {

void requirePositive(double value, const char* what) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw InputError(std::string("rigid body: ") + what + " must be positive and finite, got " +
                     std::to_string(value));
}

// Eberly 2002, "Subexpressions": polynomial terms of one triangle's surface integrals.
void subexpressions(double w0, double w1, double w2, double& f1, double& f2, double& f3,
                    double& g0, double& g1, double& g2) {
  const double temp0 = w0 + w1;
  f1 = temp0 + w2;
  const double temp1 = w0 * w0;
  const double temp2 = temp1 + w1 * temp0;
  f2 = temp2 + w2 * f1;
  f3 = w0 * temp1 + w1 * temp2 + w2 * f2;
  g0 = f2 + w0 * (f1 + w0);
  g1 = f2 + w1 * (f1 + w1);
  g2 = f2 + w2 * (f1 + w2);
}

void validateTopology(const TriangleMesh& mesh) {
  if (mesh.vertices.size() < 4 || mesh.triangles.size() < 4)
    throw InputError("rigid body mesh: need at least 4 vertices and 4 triangles, got " +
                     std::to_string(mesh.vertices.size()) + " and " +
                     std::to_string(mesh.triangles.size()));
  const int n = static_cast<int>(mesh.vertices.size());
  std::map<std::pair<int, int>, int> directed;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      if (tri[k] < 0 || tri[k] >= n)
        throw InputError("rigid body mesh: triangle " + std::to_string(t) + " has vertex index " +
                         std::to_string(tri[k]) + " outside [0, " + std::to_string(n) + ")");
      if (!mesh.vertices[tri[k]].allFinite())
        throw InputError("rigid body mesh: vertex " + std::to_string(tri[k]) + " is not finite");
    }
    for (int k = 0; k < 3; ++k) ++directed[{tri[k], tri[(k + 1) % 3]}];
  }
  for (const auto& [edge, count] : directed) {
    const auto reverse = directed.find({edge.second, edge.first});
    if (count != 1 || reverse == directed.end() || reverse->second != 1)
      throw InputError("rigid body mesh: not closed and consistently wound at edge (" +
                       std::to_string(edge.first) + ", " + std::to_string(edge.second) +
                       "): each edge must appear once in each direction");
  }
}

}  // namespace

MassProperties sphereMassProperties(const Sphere& sphere, double density) {
  requirePositive(density, "density");
  requirePositive(sphere.radius, "sphere radius");
  const double r = sphere.radius;
  MassProperties p;
  p.mass = density * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  p.inertia = Eigen::Matrix3d::Identity() * (0.4 * p.mass * r * r);
  return p;
}

MassProperties boxMassProperties(const Box& box, double density) {
  requirePositive(density, "density");
  for (int k = 0; k < 3; ++k) requirePositive(box.halfExtents[k], "box half extent");
  const Vec3 e = 2.0 * box.halfExtents;  // full side lengths
  MassProperties p;
  p.mass = density * e.prod();
  p.inertia.diagonal() << p.mass / 12.0 * (e.y() * e.y() + e.z() * e.z()),
      p.mass / 12.0 * (e.x() * e.x() + e.z() * e.z()),
      p.mass / 12.0 * (e.x() * e.x() + e.y() * e.y());
  return p;
}

MassProperties meshMassProperties(const TriangleMesh& mesh, double density) {
  requirePositive(density, "density");
  validateTopology(mesh);
  // integral = {1, x, y, z, x^2, y^2, z^2, xy, yz, zx} over the volume (Eberly 2002).
  double in[10] = {};
  for (const auto& tri : mesh.triangles) {
    const Vec3& p0 = mesh.vertices[tri[0]];
    const Vec3& p1 = mesh.vertices[tri[1]];
    const Vec3& p2 = mesh.vertices[tri[2]];
    const Vec3 d = (p1 - p0).cross(p2 - p0);
    double f1x, f2x, f3x, g0x, g1x, g2x, f1y, f2y, f3y, g0y, g1y, g2y, f1z, f2z, f3z, g0z, g1z, g2z;
    subexpressions(p0.x(), p1.x(), p2.x(), f1x, f2x, f3x, g0x, g1x, g2x);
    subexpressions(p0.y(), p1.y(), p2.y(), f1y, f2y, f3y, g0y, g1y, g2y);
    subexpressions(p0.z(), p1.z(), p2.z(), f1z, f2z, f3z, g0z, g1z, g2z);
    in[0] += d.x() * f1x;
    in[1] += d.x() * f2x;
    in[2] += d.y() * f2y;
    in[3] += d.z() * f2z;
    in[4] += d.x() * f3x;
    in[5] += d.y() * f3y;
    in[6] += d.z() * f3z;
    in[7] += d.x() * (p0.y() * g0x + p1.y() * g1x + p2.y() * g2x);
    in[8] += d.y() * (p0.z() * g0y + p1.z() * g1y + p2.z() * g2y);
    in[9] += d.z() * (p0.x() * g0z + p1.x() * g1z + p2.x() * g2z);
  }
  constexpr double kMult[10] = {1.0 / 6,  1.0 / 24, 1.0 / 24,  1.0 / 24,  1.0 / 60,
                                1.0 / 60, 1.0 / 60, 1.0 / 120, 1.0 / 120, 1.0 / 120};
  for (int k = 0; k < 10; ++k) in[k] *= kMult[k];

  const double volume = in[0];
  double extent = 0.0;
  for (const Vec3& v : mesh.vertices) extent = std::max(extent, v.cwiseAbs().maxCoeff());
  if (volume < 0.0)
    throw InputError("rigid body mesh: signed volume " + std::to_string(volume) +
                     " is negative; triangles must be wound counter-clockwise seen from outside");
  // Scale-aware degeneracy test: volume of order 1e-12 of the bounding cube is flat.
  if (!(volume > 1e-12 * std::max(extent * extent * extent, 1e-300)))
    throw InputError("rigid body mesh: degenerate (zero volume)");

  MassProperties p;
  p.mass = density * volume;
  const Vec3 c(in[1] / volume, in[2] / volume, in[3] / volume);
  p.centreOfMass = c;
  // Parallel-axis shift of the second moments from the origin to the centre of mass.
  const double xx = in[4] - volume * c.x() * c.x();
  const double yy = in[5] - volume * c.y() * c.y();
  const double zz = in[6] - volume * c.z() * c.z();
  const double xy = in[7] - volume * c.x() * c.y();
  const double yz = in[8] - volume * c.y() * c.z();
  const double zx = in[9] - volume * c.z() * c.x();
  p.inertia << yy + zz, -xy, -zx, -xy, xx + zz, -yz, -zx, -yz, xx + yy;
  p.inertia *= density;
  return p;
}

Eigen::Matrix3d parallelAxisInertia(double mass, const Vec3& offset) {
  return mass * (offset.squaredNorm() * Eigen::Matrix3d::Identity() - offset * offset.transpose());
}

namespace {

MassProperties massOf(const Sphere& s, double density) { return sphereMassProperties(s, density); }
MassProperties massOf(const Box& b, double density) { return boxMassProperties(b, density); }
MassProperties massOf(const ConvexMesh& m, double density) {
  if (m.faces.empty())
    throw InputError("rigid body mesh: ConvexMesh has no faces; build it with makeConvexMesh");
  return meshMassProperties(TriangleMesh{m.vertices, m.triangles}, density);
}
MassProperties massOf(const Compound& c, double density) {
  if (c.parts.empty()) throw InputError("rigid compound: needs at least one part");
  MassProperties total;
  std::vector<MassProperties> parts;
  for (const CompoundPart& part : c.parts) {
    MassProperties p =
        std::visit([&](const auto& s) { return massOf(s, density); }, part.shape);
    const Eigen::Matrix3d R = part.rotation.normalized().toRotationMatrix();
    p.centreOfMass = R * p.centreOfMass + part.offset;
    p.inertia = R * p.inertia * R.transpose();
    total.mass += p.mass;
    total.centreOfMass += p.mass * p.centreOfMass;
    parts.push_back(p);
  }
  total.centreOfMass /= total.mass;
  for (const MassProperties& p : parts)
    total.inertia += p.inertia + parallelAxisInertia(p.mass, p.centreOfMass - total.centreOfMass);
  return total;
}

}  // namespace

MassProperties shapeMassProperties(const Shape& shape, double density) {
  return std::visit([&](const auto& s) { return massOf(s, density); }, shape);
}

ConvexMesh makeConvexMesh(const TriangleMesh& mesh) {
  const MassProperties p = meshMassProperties(mesh, 1.0);
  ConvexMesh out{mesh.vertices, mesh.triangles, {}, {}, {}};
  for (Vec3& v : out.vertices) v -= p.centreOfMass;
  buildConvexFeatures(out);
  return out;
}

Compound makeCompound(std::vector<CompoundPart> parts) {
  for (std::size_t k = 0; k < parts.size(); ++k) {
    CompoundPart& part = parts[k];
    const std::string name = "rigid compound part " + std::to_string(k) + ": ";
    if (!part.offset.allFinite()) throw InputError(name + "offset is not finite");
    if (!part.rotation.coeffs().allFinite() || !(part.rotation.norm() > 0.0))
      throw InputError(name + "rotation must be a finite non-zero quaternion");
    part.rotation.normalize();
    try {
      std::visit([](const auto& s) { massOf(s, 1.0); }, part.shape);
    } catch (const InputError& e) {
      throw InputError(name + e.what());
    }
  }
  Compound out{std::move(parts)};
  const Vec3 c = massOf(out, 1.0).centreOfMass;
  for (CompoundPart& part : out.parts) part.offset -= c;
  return out;
}

}  // namespace msim::rigid
