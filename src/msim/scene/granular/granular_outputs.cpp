#include "msim/scene/granular/granular_outputs.hpp"

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/io/ply.hpp"
#include "msim/io/vdb.hpp"
#include "msim/scene/granular/granular_bodies.hpp"
#include "msim/scene/phenomenon_support.hpp"

namespace msim::scene {
namespace {

namespace fs = std::filesystem;
using granular::GranularParticles;

constexpr const char* kParticles = "particles";
constexpr const char* kBodies = "bodies";
constexpr const char* kShape[6] = {"a_xx", "a_yy", "a_zz", "a_xy", "a_xz", "a_yz"};

template <class Value>
io::PointAttribute attribute(const char* name, std::size_t n, Value value) {
  io::PointAttribute a{name, std::vector<float>(n)};
  for (std::size_t i = 0; i < n; ++i) a.values[i] = static_cast<float>(value(i));
  return a;
}

// Positions, velocity, mass and material; with `shapes` also the ellipsoid (what resume needs).
io::PointCloud particleCloud(const GranularParticles& p, bool shapes) {
  io::PointCloud c;
  c.positions = p.position;
  const std::size_t n = p.size();
  for (int a = 0; a < 3; ++a) {
    const char* name[3] = {"vx", "vy", "vz"};
    c.attributes.push_back(attribute(name[a], n, [&](std::size_t i) { return p.velocity[i][a]; }));
  }
  c.attributes.push_back(attribute("mass", n, [&](std::size_t i) { return p.mass[i]; }));
  c.attributes.push_back(attribute("material", n, [&](std::size_t i) { return p.material[i]; }));
  if (shapes)
    for (int k = 0; k < 6; ++k) c.attributes.push_back(attribute(kShape[k], n, [&](std::size_t i) { return p.shape[i][k]; }));
  return c;
}

}  // namespace

void writeParticlePly(const fs::path& file, const GranularParticles& particles) {
  io::writePlyPoints(file, particleCloud(particles, false));
}

void writeRenderPointPly(const fs::path& file, const granular::RenderPoints& points, const GranularParticles& particles) {
  io::PointCloud c;
  c.positions.assign(points.positions().begin(), points.positions().end());
  const auto parents = points.parents();
  c.attributes.push_back(attribute("material", c.positions.size(), [&](std::size_t i) {
    return parents[i] < particles.size() ? particles.material[parents[i]] : 0;
  }));
  io::writePlyPoints(file, c);
}

void writeBodyPly(const fs::path& file, const rigid::World& world, const std::vector<int>& bodies) {
  TriangleMesh all;
  io::PointAttribute id{"body", {}};
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    const TriangleMesh m = bodyMesh(world.bodies()[bodies[k]]);
    const int base = static_cast<int>(all.vertices.size());
    all.vertices.insert(all.vertices.end(), m.vertices.begin(), m.vertices.end());
    for (const auto& t : m.triangles) all.triangles.push_back({base + t[0], base + t[1], base + t[2]});
    id.values.resize(all.vertices.size(), static_cast<float>(k));
  }
  io::writePlyMesh(file, all, std::span<const io::PointAttribute>(&id, 1));
}

void addGranularFrame(io::VdbWriter& writer, const granular::GranularSimulation& sim, const std::vector<int>& bodies) {
  const GridSpec<3>& spec = sim.settings().grid;
  auto cellGrid = [&](const std::vector<double>& values) {
    Grid<float, 3> g(spec);
    if (values.size() == g.count())
      for (std::size_t i = 0; i < values.size(); ++i) g[i] = static_cast<float>(values[i]);
    return g;
  };
  writer.addFogVolume("phi", cellGrid(sim.gridState().phi));
  writer.addFloatGrid("pressure", cellGrid(sim.stress().pressure()));
  writer.addVectorGrid("velocity", sim.gridVelocity());
  // Points are bucketed into voxels of the cell size: 8 particles per cell when packed.
  writer.addPoints(kParticles, particleCloud(sim.particles(), true), spec.dx);
  io::PointCloud state;
  for (int index : bodies) {
    const rigid::RigidBody& b = sim.world().bodies()[index];
    state.positions.push_back(b.position.cast<float>());
  }
  const auto& all = sim.world().bodies();
  auto bodyAttribute = [&](const char* name, auto value) {
    state.attributes.push_back(attribute(name, bodies.size(), [&](std::size_t k) { return value(all[bodies[k]]); }));
  };
  bodyAttribute("qw", [](const rigid::RigidBody& b) { return b.orientation.w(); });
  bodyAttribute("qx", [](const rigid::RigidBody& b) { return b.orientation.x(); });
  bodyAttribute("qy", [](const rigid::RigidBody& b) { return b.orientation.y(); });
  bodyAttribute("qz", [](const rigid::RigidBody& b) { return b.orientation.z(); });
  bodyAttribute("vx", [](const rigid::RigidBody& b) { return b.velocity.x(); });
  bodyAttribute("vy", [](const rigid::RigidBody& b) { return b.velocity.y(); });
  bodyAttribute("vz", [](const rigid::RigidBody& b) { return b.velocity.z(); });
  bodyAttribute("wx", [](const rigid::RigidBody& b) { return b.angularVelocity.x(); });
  bodyAttribute("wy", [](const rigid::RigidBody& b) { return b.angularVelocity.y(); });
  bodyAttribute("wz", [](const rigid::RigidBody& b) { return b.angularVelocity.z(); });
  if (!bodies.empty()) writer.addPoints(kBodies, state, spec.dx);
}

void restoreGranularVdb(const fs::path& file, granular::GranularSimulation& sim, const std::vector<int>& bodies,
                        const std::string& source) {
  const io::VdbFile saved(file, io::VdbProvenance::MsimRun);
  const io::PointCloud points = saved.points(kParticles);
  const io::PointCloud state = bodies.empty() ? io::PointCloud{} : saved.points(kBodies);
  auto values = [&](const io::PointCloud& cloud, const std::string& name) -> const std::vector<float>& {
    return savedPointAttribute(cloud, name, file, source);
  };
  if (state.positions.size() != bodies.size())
    throw InputError(fmt::format("{}: cannot resume from {}: it holds {} bodies, the scene has {}", source,
                                 file.string(), state.positions.size(), bodies.size()));
  GranularParticles& p = sim.particles();
  const std::size_t n = points.positions.size();
  p.resize(n);
  const auto &vx = values(points, "vx"), &vy = values(points, "vy"), &vz = values(points, "vz");
  const auto &mass = values(points, "mass"), &material = values(points, "material");
  for (std::size_t i = 0; i < n; ++i) {
    p.position[i] = points.positions[i];
    p.velocity[i] = Vecf<3>(vx[i], vy[i], vz[i]);
    p.mass[i] = mass[i];
    p.material[i] = static_cast<std::uint16_t>(material[i]);
  }
  for (int k = 0; k < 6; ++k) {
    const auto& a = values(points, kShape[k]);
    for (std::size_t i = 0; i < n; ++i) p.shape[i][k] = a[i];
  }
  const auto &qw = values(state, "qw"), &qx = values(state, "qx"), &qy = values(state, "qy"), &qz = values(state, "qz");
  const auto &bvx = values(state, "vx"), &bvy = values(state, "vy"), &bvz = values(state, "vz");
  const auto &wx = values(state, "wx"), &wy = values(state, "wy"), &wz = values(state, "wz");
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    rigid::RigidBody& b = sim.world().body(bodies[k]);
    b.position = state.positions[k].cast<double>();
    b.orientation = Eigen::Quaterniond(qw[k], qx[k], qy[k], qz[k]).normalized();
    b.velocity = Vec3(bvx[k], bvy[k], bvz[k]);
    b.angularVelocity = Vec3(wx[k], wy[k], wz[k]);
  }
}

}  // namespace msim::scene
