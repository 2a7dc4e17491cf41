#include "msim/scene/granular/granular_bodies.hpp"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/io/obj.hpp"
#include "msim/rigid/mass_properties.hpp"
#include "msim/rigid/polyhedron.hpp"
#include "msim/scene/keys/json_vectors.hpp"
#include "msim/scene/scene_file.hpp"

namespace msim::scene {
namespace {

using nlohmann::json;

Schema bodyShapeSchema() {
  Schema sphere = Schema::object("ball");
  sphere.number("radius", "m", "radius").min(0.0, Bound::Exclusive);
  Schema box = Schema::object("box, axis-aligned in the body frame");
  box.vector("size", "m", 3, "side lengths").min(0.0, Bound::Exclusive);
  Schema mesh = Schema::object("closed convex triangle mesh (treated as its convex hull in contacts)");
  mesh.string("file", "OBJ or PLY file, relative to the scene file");
  mesh.number("scale", "", 1.0, "uniform scale of the vertices").min(0.0, Bound::Exclusive);
  Schema wheel = Schema::object("paddle wheel about the body-frame z axis: a square hub and flat blades");
  wheel.number("radius", "m", "from the axis to the blade tips").min(0.0, Bound::Exclusive);
  wheel.number("width", "m", "extent along the axis").min(0.0, Bound::Exclusive);
  wheel.integer("blades", 4, "number of blades, evenly spaced").min(1).max(64);
  wheel.number("thickness", "", 0.1, "blade thickness as a fraction of the radius").min(0.0, Bound::Exclusive).max(1.0);
  Schema shape = Schema::variant("the body's shape, centred on 'position'");
  shape.alternative("sphere", std::move(sphere))
      .alternative("box", std::move(box))
      .alternative("mesh", std::move(mesh))
      .alternative("paddle_wheel", std::move(wheel));
  return shape;
}

rigid::Shape paddleWheel(const json& s) {
  const double r = s.at("radius").get<double>(), width = s.at("width").get<double>();
  const int blades = s.at("blades").get<int>();
  const double thickness = s.at("thickness").get<double>() * r;
  std::vector<rigid::CompoundPart> parts;
  // The hub is as thick as two blades so that the blades' inner ends are buried in it.
  const double hub = std::max(thickness, 0.15 * r);
  parts.push_back({rigid::Box{Vec3(hub, hub, 0.5 * width)}, Vec3::Zero(), Eigen::Quaterniond::Identity()});
  for (int k = 0; k < blades; ++k) {
    const double angle = 2.0 * std::numbers::pi * k / blades;
    const Eigen::Quaterniond q(Eigen::AngleAxisd(angle, Vec3::UnitZ()));
    parts.push_back({rigid::Box{Vec3(0.5 * r, 0.5 * thickness, 0.5 * width)}, q * Vec3(0.5 * r, 0.0, 0.0), q});
  }
  return rigid::makeCompound(std::move(parts));
}

rigid::Shape bodyShape(const Scene& scene, const json& s) {
  const std::string type = s.at("type").get<std::string>();
  if (type == "sphere") return rigid::Sphere{s.at("radius").get<double>()};
  if (type == "box") return rigid::Box{0.5 * paddedVec3(s.at("size"))};
  if (type == "paddle_wheel") return paddleWheel(s);
  const std::filesystem::path file = scene.directory() / s.at("file").get<std::string>();
  if (!std::filesystem::is_regular_file(file)) throw InputError("mesh file '" + file.string() + "' not found");
  TriangleMesh mesh = io::readObj(file);
  for (Vec3& v : mesh.vertices) v *= s.at("scale").get<double>();
  return rigid::makeConvexMesh(mesh);
}

void appendBox(TriangleMesh& out, const Vec3& half, const Eigen::Quaterniond& q, const Vec3& offset) {
  const int base = static_cast<int>(out.vertices.size());
  for (int k = 0; k < 8; ++k) {
    const Vec3 corner((k & 1 ? 1 : -1) * half.x(), (k & 2 ? 1 : -1) * half.y(), (k & 4 ? 1 : -1) * half.z());
    out.vertices.push_back(q * corner + offset);
  }
  // Outward-wound quads of the corner numbering above (bit 0: x, bit 1: y, bit 2: z).
  static constexpr int kQuads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : kQuads) {
    out.triangles.push_back({base + f[0], base + f[1], base + f[2]});
    out.triangles.push_back({base + f[0], base + f[2], base + f[3]});
  }
}

void appendSphere(TriangleMesh& out, double radius, const Vec3& offset) {
  constexpr int kSlices = 12, kStacks = 8;
  const int base = static_cast<int>(out.vertices.size());
  for (int i = 0; i <= kStacks; ++i) {
    const double theta = std::numbers::pi * i / kStacks;
    for (int j = 0; j < kSlices; ++j) {
      const double phi = 2.0 * std::numbers::pi * j / kSlices;
      out.vertices.push_back(offset + radius * Vec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                                    std::sin(theta) * std::sin(phi)));
    }
  }
  for (int i = 0; i < kStacks; ++i)
    for (int j = 0; j < kSlices; ++j) {
      const int a = base + i * kSlices + j, b = base + i * kSlices + (j + 1) % kSlices;
      out.triangles.push_back({a, b, b + kSlices});
      out.triangles.push_back({a, b + kSlices, a + kSlices});
    }
}

void appendPart(TriangleMesh& out, const rigid::PartShape& shape, const Eigen::Quaterniond& q, const Vec3& offset) {
  if (const auto* s = std::get_if<rigid::Sphere>(&shape)) {
    appendSphere(out, s->radius, offset);
  } else if (const auto* b = std::get_if<rigid::Box>(&shape)) {
    appendBox(out, b->halfExtents, q, offset);
  } else {
    const auto& m = std::get<rigid::ConvexMesh>(shape);
    const int base = static_cast<int>(out.vertices.size());
    for (const Vec3& v : m.vertices) out.vertices.push_back(q * v + offset);
    for (const auto& t : m.triangles) out.triangles.push_back({base + t[0], base + t[1], base + t[2]});
  }
}

}  // namespace

Schema granularBodySchema() {
  Schema b = Schema::object("a rigid body coupled with the material both ways (ch. 5.3.4)");
  b.field("shape", bodyShapeSchema().required());
  b.number("density", "kg/m^3", 0.0, "mass per volume; 0 = give 'mass' instead").min(0.0);
  b.number("mass", "kg", 0.0, "total mass (inertia from the shape at uniform density); 0 = use 'density'").min(0.0);
  b.vector("position", "m", 3, "centre of mass at t = 0").required();
  Schema orientation = Schema::object("rotation at t = 0 from the body frame to the world");
  orientation.vector("axis", "", {0.0, 0.0, 1.0}, "rotation axis");
  orientation.number("angle", "deg", 0.0, "rotation angle about the axis");
  b.field("orientation", orientation);
  b.vector("velocity", "m/s", {0.0, 0.0, 0.0}, "velocity at t = 0");
  b.vector("angular_velocity", "rad/s", {0.0, 0.0, 0.0}, "angular velocity at t = 0 (world frame)");
  Schema hinge = Schema::object("a fixed axle: the body only turns about 'axis' through 'pivot'");
  hinge.vector("axis", "", {0.0, 0.0, 0.0}, "world direction of the axle; zero = no hinge");
  hinge.vector("pivot", "m", {0.0, 0.0, 0.0}, "world point on the axle, within the body's reach");
  b.field("hinge", hinge);
  b.number("friction", "", 0.5, "contact friction coefficient against walls and other bodies").min(0.0);
  b.number("restitution", "", 0.0, "bounciness of its contacts").min(0.0).max(1.0);
  return b;
}

std::vector<int> addSceneBodies(const Scene& scene, rigid::World& world) {
  const json& list = scene.resolved.at("bodies");
  const std::string source = scene.file.string();
  const Vec3 lo = scene.origin, hi = scene.origin + scene.dx * scene.resolution.cast<double>();
  std::vector<int> indices;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const json& b = list[k];
    const std::string key = fmt::format("bodies[{}]", k);
    auto fail = [&](const std::string& field, const std::string& what) -> void {
      throw InputError(fmt::format("{}: '{}.{}' {}", source, key, field, what));
    };
    rigid::Shape shape;
    try {
      shape = bodyShape(scene, b.at("shape"));
    } catch (const std::exception& e) {
      fail("shape", fmt::format("is not a valid body shape: {}", e.what()));
    }
    const double density = b.at("density").get<double>(), mass = b.at("mass").get<double>();
    if (density > 0.0 && mass > 0.0) fail("mass", "and 'density' are both given; give one of them");
    if (!(density > 0.0) && !(mass > 0.0))
      fail("mass", "must be > 0 (or give a 'density' > 0): a body without mass cannot be simulated");
    rigid::RigidBody body = density > 0.0 ? rigid::RigidBody::fromDensity(shape, density) : rigid::RigidBody::fromMass(shape, mass);
    body.position = paddedVec3(b.at("position"));
    if ((body.position.array() <= lo.array()).any() || (body.position.array() >= hi.array()).any())
      fail("position", fmt::format("= ({:.3g}, {:.3g}, {:.3g}) lies outside the domain", body.position.x(),
                                   body.position.y(), body.position.z()));
    const Vec3 axis = paddedVec3(b.at("orientation").at("axis"));
    const double angle = b.at("orientation").at("angle").get<double>() * std::numbers::pi / 180.0;
    if (angle != 0.0 && !(axis.norm() > 0.0)) fail("orientation.axis", "must be non-zero for a non-zero angle");
    if (angle != 0.0) body.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis.normalized()));
    body.velocity = paddedVec3(b.at("velocity"));
    body.angularVelocity = paddedVec3(b.at("angular_velocity"));
    body.material.friction = b.at("friction").get<double>();
    body.material.restitution = b.at("restitution").get<double>();
    const Vec3 hingeAxis = paddedVec3(b.at("hinge").at("axis"));
    const Vec3 pivot = paddedVec3(b.at("hinge").at("pivot"));
    const double reach = rigid::boundingRadius(body.shape());
    const int index = world.addBody(std::move(body));
    if (hingeAxis.norm() > 0.0) {
      // A forgotten pivot defaults to the origin; an axle outside the body is almost surely that.
      if ((pivot - world.bodies()[index].position).norm() > reach)
        fail("hinge.pivot", fmt::format("lies {:.3g} m from the body's centre, outside its reach of {:.3g} m",
                                        (pivot - world.bodies()[index].position).norm(), reach));
      world.addHinge(index, pivot, hingeAxis.normalized());
    }
    indices.push_back(index);
  }
  return indices;
}

TriangleMesh bodyMesh(const rigid::RigidBody& body) {
  TriangleMesh local;
  const Eigen::Quaterniond identity = Eigen::Quaterniond::Identity();
  if (const auto* c = std::get_if<rigid::Compound>(&body.shape())) {
    for (const rigid::CompoundPart& p : c->parts) appendPart(local, p.shape, p.rotation, p.offset);
  } else {
    std::visit(
        [&](const auto& s) {
          if constexpr (!std::is_same_v<std::decay_t<decltype(s)>, rigid::Compound>) appendPart(local, s, identity, Vec3::Zero());
        },
        body.shape());
  }
  for (Vec3& v : local.vertices) v = body.toWorld(v);
  return local;
}

}  // namespace msim::scene
