#include "msim/scene/solids/mass_spring_phenomenon.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/core/log.hpp"
#include "msim/geometry/rigid_motion.hpp"
#include "msim/geometry/shape_adapters.hpp"
#include "msim/io/obj.hpp"
#include "msim/io/ply.hpp"
#include "msim/io/vdb.hpp"
#include "msim/parallel/mpi_session.hpp"
#include "msim/parallel/split_cloth.hpp"
#include "msim/render/camera.hpp"
#include "msim/render/density_preview.hpp"
#include "msim/render/frame_renderer.hpp"
#include "msim/scene/keys/json_vectors.hpp"
#include "msim/scene/phenomenon_support.hpp"
#include "msim/scene/keys/render_keys.hpp"
#include "msim/scene/scene_file.hpp"
#include "msim/scene/schema/shape_schema.hpp"
#include "msim/scene/keys/turbulent_wind_keys.hpp"
#include "msim/solids/cloth_collision_loop.hpp"
#include "msim/solids/cloth_mesh.hpp"
#include "msim/solids/collision/triangle_intersection.hpp"
#include "msim/solids/newmark.hpp"
#include "msim/solids/strain_limit.hpp"
#include "msim/solids/tet_mesh.hpp"

namespace msim::scene {

namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr double kExplodedStrain = 10.0;  // a spring stretched to 11 times its length: the run failed
// Symmetric Gauss-Seidel sweeps of strain limiting per step: a hanging chain of 10 springs at 49%
// stretch comes to rest at the limit (tests/solids/strain_limit_test.cpp).
constexpr int kStrainLimitSweeps = 50;
// Linearisations per half step of a frame-sized step by default: a hanging cloth swinging at one
// step per frame keeps its energy (docs/solids.md); the collision loop's small inner steps need one.
constexpr int kFrameStepLinearisations = 4;

// The keys cloth and solid share, in their object: gravity, the solver, outputs, pins.
void declareMassSpringKeys(Schema& object, const char* what, double strainLimit) {
  object.vector("gravity", "m/s^2", {0.0, -9.8, 0.0}, "acceleration of gravity").lengths({3});
  object.number("wind_drag", "kg/(m^2 s)", 1.0,
                "c of the wind's drag c A ((u - v) . n) n on each surface triangle, along its normal (linear, as Selle "
                "ch. 6's leaves), from winds[]")
      .min(0.0);
  object.boolean("implicit_springs", true,
                 "springs implicit along themselves (Selle ch. 5.5) and, when stretched, across (their tension): stable "
                 "at one step per frame");
  object.integer("newton_iterations", 0,
                 "most linearisations of the springs per half step; more keep a large step from gaining energy. 0: "
                 "1 (the seed's) in the self-collision loop's inner steps of at most a frame / inner_steps, 4 for "
                 "frame-sized steps")
      .min(0);
  object.number("newton_tolerance", "", 0.03,
                "the linearisations stop once one moves no particle by this fraction of the shortest spring")
      .min(0.0, Bound::Exclusive);
  object.number("strain_limit", "", strainLimit,
                "springs stretched further are shortened to this strain after every step (Provot 1995, Bridson et al. "
                "2003); 0 = off")
      .min(0.0);
  object.vector("initial_velocity", "m/s", {0.0, 0.0, 0.0}, "every free vertex starts with this velocity").lengths({3});
  object.string("contact_method", "crossing_fraction",
                "crossing_fraction: a step that meets a body is cut where it meets it and ends with Gamma of its "
                "velocity (Selle ch. 6.5); projection: the earlier method, moved out along the normal after the whole "
                "step (friction a step late)")
      .choices({"crossing_fraction", "projection"});
  object.number("cg_tolerance", "", 1e-3, "relative residual of the step's solves (Table 6.1)").min(0.0, Bound::Exclusive).max(1.0);
  object.string("preconditioner", "jacobi",
                "of the step's conjugate gradients: jacobi (the matrix's diagonal) or multigrid (smoothed "
                "aggregation: far fewer iterations at large steps on big meshes; slower at the small steps of colliding cloth)")
      .choices({"jacobi", "multigrid"});
  object.string("mesh_format", "ply", fmt::format("the {} surface mesh written per frame (mesh/<name>_NNNN.*): ply, obj, both or none", what))
      .choices({"ply", "obj", "both", "none"});
  Schema pin = Schema::object("vertices inside this shape are scripted: still, or moving rigidly as given below");
  pin.field("shape", shapeSchema());
  pin.vector("velocity", "m/s", {0.0, 0.0, 0.0}, "the pinned vertices translate at this velocity").lengths({3});
  pin.vector("angular_velocity", "rad/s", {0.0, 0.0, 0.0},
             "and turn at this angular velocity (world frame) about `center`, which moves with them")
      .lengths({3});
  pin.vector("center", "m", {0.0, 0.0, 0.0}, "the point the pinned vertices turn about, at t = 0").lengths({3});
  object.array("pins", pin, "pinned vertices");
}

void declareBodiesAndWinds(Schema& root) {
  Schema body = Schema::object("a solid the cloth or solid lands on and slides over");
  body.field("shape", shapeSchema());
  body.number("friction", "", 0.3, "mu of Coulomb friction (Selle ch. 6.5)").min(0.0);
  body.vector("velocity", "m/s", {0.0, 0.0, 0.0}, "the body translates at this velocity from its place at t = 0").lengths({3});
  body.vector("angular_velocity", "rad/s", {0.0, 0.0, 0.0},
              "and turns at this angular velocity (world frame) about `center`, which moves with it")
      .lengths({3});
  body.vector("center", "m", {0.0, 0.0, 0.0}, "the point the body turns about, at t = 0").lengths({3});
  root.array("bodies", body, "solids in contact");
  declareTurbulentWinds(root);
}

void declareCloth(Schema& root) {
  Schema cloth = Schema::object("the cloth: its mesh, material and time step (docs/cloth.md)");
  Schema patch = Schema::object("a rectangular patch: origin + s edge_u + t edge_v, s and t in [0, 1]");
  patch.vector("origin", "m", {0.0, 1.0, 0.0}, "a corner of the patch").lengths({3});
  patch.vector("edge_u", "m", {1.0, 0.0, 0.0}, "the first edge from the origin").lengths({3});
  patch.vector("edge_v", "m", {0.0, 0.0, 1.0}, "the second edge from the origin").lengths({3});
  patch.vector("quads", "", {32.0, 32.0}, "quads along edge_u and edge_v (two triangles each)").lengths({2}).min(1.0);
  cloth.field("patch", patch);
  Schema mesh = Schema::object("a triangle mesh file instead of the patch");
  mesh.string("file", "", "OBJ or PLY, relative to the scene file; '' = use the patch");
  mesh.number("scale", "", 1.0, "uniform scale of the vertices").min(0.0, Bound::Exclusive);
  mesh.vector("translate", "m", {0.0, 0.0, 0.0}, "translation after scaling").lengths({3});
  cloth.field("mesh", mesh);
  cloth.number("density", "kg/m^2", 0.1, "mass per area").min(0.0, Bound::Exclusive);
  cloth.number("edge_stiffness", "N", 20.0, "k of eq. 5.1 for the edge springs: the pull at a strain of 1")
      .min(0.0, Bound::Exclusive);
  cloth.number("edge_damping", "N s/m", 0.01, "damping along the edge springs").min(0.0);
  cloth.number("bend_stiffness", "N", 2.0, "k of the bending springs across each interior edge").min(0.0);
  cloth.number("bend_damping", "N s/m", 0.001, "damping along the bending springs").min(0.0);
  declareMassSpringKeys(cloth, "cloth", 0.1);
  cloth.boolean("self_collisions", true,
                "the outer collision loop of Selle ch. 6: history-based self-repulsion, continuous collision detection "
                "and rigid impact zones keep the cloth from passing through itself");
  cloth.number("thickness", "m", 0.01, "h of eqs. 6.1-6.2: the distance self-repulsion keeps (Table 6.1)")
      .min(0.0, Bound::Exclusive);
  cloth.number("repulsion_stiffness", "N/m", 0.0, "k of eq. 6.1; 0 = the edge springs' k / l0 (mean over the mesh)").min(0.0);
  cloth.number("self_friction", "", 0.3, "mu of cloth sliding on itself").min(0.0);
  cloth.integer("inner_steps", 16, "k_i: inner steps per outer collision step (Selle ch. 6.3: 4-16)").min(1).max(64);
  root.field("cloth", cloth);
  declareBodiesAndWinds(root);
}

void declareSolid(Schema& root) {
  Schema solid = Schema::object("the solid: its shape, tetrahedra, material and time step (docs/solids.md)");
  solid.field("shape", shapeSchema());
  solid.number("spacing", "m", 0.05, "the BCC lattice's cube side: tetrahedra of spacing^3 / 12").min(0.0, Bound::Exclusive);
  solid.number("density", "kg/m^3", 1000.0, "mass per volume").min(0.0, Bound::Exclusive);
  solid.number("edge_stiffness", "N", 100.0, "k of eq. 5.1 for the edge springs").min(0.0, Bound::Exclusive);
  solid.number("edge_damping", "N s/m", 0.1, "damping along the edge springs").min(0.0);
  solid.number("altitude_stiffness", "N", 100.0, "k of each tetrahedron's altitude spring (ch. 5.3.4); 0 = edge springs only")
      .min(0.0);
  solid.number("altitude_damping", "N s/m", 0.1, "damping along the altitude springs").min(0.0);
  solid.vector("initial_scale", "", {1.0, 1.0, 1.0},
               "the solid starts scaled by these factors about its centre (crushed: [1, 0.05, 1]) and springs back")
      .lengths({3})
      .min(0.0);
  declareMassSpringKeys(solid, "solid's", 0.0);
  root.field("solid", solid);
  declareBodiesAndWinds(root);
}

double massSpringBytesPerCell(int, const json&) { return 8.0; }  // the preview's grids


class MassSpringPhenomenon final : public Phenomenon {
 public:
  // kind: "cloth" or "solid", the phenomenon and its key.
  MassSpringPhenomenon(const Scene& scene, StageTimers& timers, std::string kind)
      : kind_(std::move(kind)),
        vertices_(kind_ + "_vertices"),
        source_(scene.file.string()),
        name_(scene.resolved.at("name").get<std::string>()),
        timers_(timers),
        spec_(scene.gridSpec<3>()),
        cfl_(scene.resolved.at("time").at("cfl").get<double>()) {
    if (scene.dimensions != 3)
      throw InputError(fmt::format("{}: 'domain': a {} scene is 3D (give domain.min and domain.max 3 numbers)", source_, kind_));
    const json& c = scene.resolved.at(kind_);
    meshFormat_ = c.at("mesh_format").get<std::string>();
    contact_ = solids::BodyContact(c.at("contact_method").get<std::string>() == "projection"
                                       ? solids::ContactMethod::Projection
                                       : solids::ContactMethod::CrossingFraction);
    if (kind_ == "cloth")
      buildCloth(scene, c);
    else
      buildSolid(scene, c);
    system_.gravity = sceneVector<3>(c.at("gravity"));
    windDrag_ = c.at("wind_drag").get<double>();
    winds_ = turbulentWinds<3>(scene);
    const json& pins = c.at("pins");
    for (std::size_t i = 0; i < pins.size(); ++i) {
      const std::string key = fmt::format("{}.pins[{}].shape", kind_, i);
      const auto shape = sceneShape<3>(scene, pins[i].at("shape"), key);
      int pinned = 0;
      Script script{rigidMotion(pins[i]), {}, {}};
      for (std::size_t v = 0; v < system_.size(); ++v)
        if (shape->distance(system_.x[v]) <= 0.0 && !system_.pinned[v]) {
          system_.pinned[v] = 1;
          script.vertices.push_back(static_cast<int>(v));
          script.rest.push_back(system_.x[v]);
          ++pinned;
        }
      if (script.motion.moves()) scripts_.push_back(std::move(script));
      if (pinned == 0) throw InputError(fmt::format("{}: '{}' holds no vertex of the {}: nothing to pin", source_, key, kind_));
    }
    const Vec3 initialVelocity = sceneVector<3>(c.at("initial_velocity"));
    for (std::size_t p = 0; p < system_.size(); ++p)
      if (!system_.pinned[p]) system_.v[p] = initialVelocity;
    const json& bodies = scene.resolved.at("bodies");
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      std::shared_ptr<const geometry::Shape3> shape = sceneShape<3>(scene, bodies[i].at("shape"), fmt::format("bodies[{}].shape", i));
      for (std::size_t v = 0; v < system_.size(); ++v)
        if (shape->distance(system_.x[v]) < 0.0)
          throw InputError(fmt::format("{}: 'bodies[{}].shape' holds {} vertex {} at the start: the {} must begin "
                                       "outside the bodies",
                                       source_, i, kind_, v, kind_));
      const geometry::RigidMotion motion = rigidMotion(bodies[i]);
      solids::ContactBody body{std::move(shape), motion.velocity, bodies[i].at("friction").get<double>()};
      body.angularVelocity = motion.angularVelocity;
      body.center = motion.center;
      contact_.addBody(body);
      bodyShapes_.push_back(body.shape);
      bodyRest_.push_back(body);
      bodyMotion_.push_back(motion);
    }
    solids::NewmarkSettings settings;
    settings.implicitSprings = c.at("implicit_springs").get<bool>();
    settings.cgTolerance = c.at("cg_tolerance").get<double>();
    const bool collisionLoop = kind_ == "cloth" && c.at("self_collisions").get<bool>();
    settings.newtonIterations = static_cast<int>(c.at("newton_iterations").get<long long>());
    if (settings.newtonIterations == 0) settings.newtonIterations = collisionLoop ? 1 : kFrameStepLinearisations;
    settings.newtonTolerance = c.at("newton_tolerance").get<double>();
    settings.preconditioner = c.at("preconditioner").get<std::string>() == "multigrid" ? solids::SolvePreconditioner::Multigrid
                                                                                     : solids::SolvePreconditioner::Jacobi;
    stepper_ = solids::NewmarkStepper(settings);
    strainLimit_ = c.at("strain_limit").get<double>();
    if (collisionLoop) buildCollisionLoop(c, settings);
    if (parallel::worldSize() > 1) splitAmongProcesses(scene, settings);
    implicitSprings_ = settings.implicitSprings;
    springMass_.resize(system_.springs.size());
    for (std::size_t i = 0; i < system_.springs.size(); ++i) {
      const solids::Spring& s = system_.springs[i];
      const double ma = system_.pinned[static_cast<std::size_t>(s.a)] ? 0.0 : system_.mass[static_cast<std::size_t>(s.a)];
      const double mb = system_.pinned[static_cast<std::size_t>(s.b)] ? 0.0 : system_.mass[static_cast<std::size_t>(s.b)];
      springMass_[i] = ma > 0.0 && mb > 0.0 ? ma * mb / (ma + mb) : std::max(ma, mb);
    }
    // The drag's rate c A / m on each free particle, A a third of its triangles' area at rest.
    std::vector<double> dragArea(system_.size(), 0.0);
    for (const auto& t : mesh_.triangles) {
      const double area = 0.5 * (system_.x[t[1]] - system_.x[t[0]]).cross(system_.x[t[2]] - system_.x[t[0]]).norm();
      for (const int k : t) dragArea[static_cast<std::size_t>(k)] += area / 3.0;
    }
    massPerDragArea_ = std::numeric_limits<double>::infinity();
    for (std::size_t p = 0; p < system_.size(); ++p)
      if (!system_.pinned[p] && dragArea[p] > 0.0) massPerDragArea_ = std::min(massPerDragArea_, system_.mass[p] / dragArea[p]);
    previewRender_ = renderKeys(scene.resolved.at("render"), source_, scene.directory()).config;
    previewRender_.multipleScattering = false;
    if (!previewRender_.camera) {  // render.camera.auto: the domain seen along outputs.preview's axes
      const render::PreviewSettings axes = previewSettings(scene);
      previewRender_.camera = render::frameBox(spec_.origin, spec_.origin + spec_.extent(), previewRender_.width,
                                               previewRender_.height, axes.upAxis, axes.viewAxis);
    }
    emptyMedium_ = Grid<float, 3>(spec_, 0.0f);
  }

  // With the collision loop a step is an outer step of up to k_i inner steps.
  double stableTimestep() const override { return innerStableTimestep() * (loop_ ? loop_->settings().innerSteps : 1); }

  // The explicit part's limit 2 / omega. Explicit springs: omega^2 = k / (l0 mu) along each.
  // Implicit springs (ch. 5.5, with their tension across them) have no limit, and a frame can be
  // one step; what stays explicit is the wind's drag, c A / m per particle (windForces). With
  // self-collisions an inner step also moves no vertex further than the thickness relative to
  // the cloth's mean motion: repulsion (step B) acts only on pairs closer than it, and a pair that
  // crossed the band within one inner step is left to step C, whose impulse takes back the
  // pair's whole approach over the outer step (an outer step of a frame would tear the cloth
  // where pieces meet fast). The bound also keeps the outer step short enough for step A's
  // straight-line prediction: pieces that speed up towards each other (leaves in a gust) are not
  // among its pairs when it errs, and step C then pulls them back by their whole approach. Bounding
  // only the approach of A's pairs let 100 leaves of 1000 triangles tear in their second frame.
  double innerStableTimestep() const {
    double step = std::numeric_limits<double>::infinity();
    if (!implicitSprings_)
      for (std::size_t i = 0; i < system_.springs.size(); ++i) {
        const solids::Spring& s = system_.springs[i];
        if (!(springMass_[i] > 0.0) || !(s.stiffness > 0.0)) continue;
        step = std::min(step, 2.0 * std::sqrt(springMass_[i] * s.restLength / s.stiffness));
      }
    if (!winds_.empty() && windDrag_ > 0.0) step = std::min(step, 2.0 * massPerDragArea_ / windDrag_);
    if (loop_) {
      const Vec3 mean = system_.meanVelocity();
      double fastest = 0.0;
      for (std::size_t p = 0; p < system_.size(); ++p)
        if (!system_.pinned[p]) fastest = std::max(fastest, (system_.v[p] - mean).norm());
      if (fastest > 0.0) step = std::min(step, loop_->settings().repulsion.thickness / fastest);
    }
    return cfl_ * step;
  }

  void step(double dt) override {
    if (!winds_.empty() && windDrag_ > 0.0) {
      ScopedStage stage(timers_, kind_ == "cloth" ? "cloth: wind" : "solid: wind");
      windForces();
    }
    scriptPins(time_, dt);
    solids::NewmarkStats s;
    if (loop_) {
      s = collisionStep(dt);  // places moving bodies before each inner step
    } else {
      ScopedStage stage(timers_, kind_ == "cloth" ? "cloth: step" : "solid: step");
      moveBodies(time_ + dt);
      s = stepper_.step(system_, dt, contact_.empty() ? nullptr : &contact_);
      if (strainLimit_ > 0.0) {
        solids::limitStrain(system_, strainLimit_, kStrainLimitSweeps, dt);
        if (!contact_.empty()) contact_.pushOut(system_.x, system_.v, system_.pinned);
      }
    }
    ++steps_;
    time_ += dt;
    placePins(time_);
    iterations_ += s.iterations;
    preconditionerSetups_ += s.preconditionerSetups;
    contacts_ = s.contacts;
    if (!s.converged) {
      ++unconverged_;
      logger().warn("{}: a solve of step {} did not converge ({} iterations)", kind_, steps_, s.iterations);
    }
    if (kind_ == "cloth") refereeStep();
  }

  void checkFinite(long stepIndex, double time) const override {
    for (std::size_t v = 0; v < system_.size(); ++v)
      if (!system_.x[v].allFinite() || !system_.v[v].allFinite())
        throw SimulationError(fmt::format("{}: vertex {} is not finite at step {} (t = {:.4g} s)", kind_, v, stepIndex, time));
    const double strain = maxStrain();
    if (strain > kExplodedStrain)
      throw SimulationError(fmt::format("{}: a spring is stretched to {:.3g} times its length at step {} (t = {:.4g} s): "
                                        "the {} exploded; lower time.cfl or the stiffness",
                                        kind_, strain + 1.0, stepIndex, time, kind_));
  }

  // The vertices (positions, velocities) for --resume and tools, and the bodies where they stand as
  // "obstacle_distance" (signed, negative inside) for renderers.
  void writeVolume(io::VdbWriter& writer) const override {
    if (!bodyShapes_.empty()) writer.addLevelSet("obstacle_distance", bodyDistance());
    io::PointCloud cloud;
    std::vector<io::PointAttribute> v = {{"vx", {}}, {"vy", {}}, {"vz", {}}};
    for (std::size_t p = 0; p < system_.size(); ++p) {
      cloud.positions.push_back(system_.x[p].cast<float>());
      for (int a = 0; a < 3; ++a) v[a].values.push_back(static_cast<float>(system_.v[p][a]));
    }
    cloud.attributes = std::move(v);
    writer.addPoints(vertices_, cloud, spec_.dx);
  }

  // mesh/<name>_NNNN.ply (and .obj): the surface's triangles, vertices in the same order every frame
  // (a solid's interior vertices are written too, unreferenced, so the order stays the system's).
  void writeFrameData(const fs::path& runDir, int frame) const override {
    if (meshFormat_ == "none") return;
    const fs::path dir = runDir / "mesh";
    fs::create_directories(dir);
    const TriangleMesh now = surfaceNow();
    const std::string stem = fmt::format("{}_{:04d}", name_, frame);
    if (meshFormat_ != "obj") io::writePlyMesh(dir / (stem + ".ply"), now);
    if (meshFormat_ == "obj" || meshFormat_ == "both") io::writeObj(dir / (stem + ".obj"), now);
  }

  // The surface mesh with the bodies, by the renderer of `msim render` (the scene's render.*
  // camera, lights and mesh_albedo; single scattering is all an empty medium needs).
  io::Image preview() const override {
    const TriangleMesh now = surfaceNow();
    render::FrameSurfaces surfaces;
    surfaces.meshes = {&now};
    if (!bodyShapes_.empty()) surfaces.distance = &bodyDistance();
    try {
      return render::renderFrame(previewRender_, emptyMedium_, nullptr, nullptr, surfaces).render.image;
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("{}: the preview cannot be drawn: {}", source_, e.what()));
    }
  }

  void restore(const fs::path& vdbFile, double time, long /*steps*/) override {
    time_ = time;
    moveBodies(time);
    const io::VdbFile saved(vdbFile, io::VdbProvenance::MsimRun);
    const io::PointCloud cloud = saved.points(vertices_);
    if (cloud.positions.size() != system_.size())
      throw InputError(fmt::format("{}: '{}' holds {} vertices, the {} has {}", vdbFile.string(), vertices_,
                                   cloud.positions.size(), kind_, system_.size()));
    const char* names[3] = {"vx", "vy", "vz"};
    for (int a = 0; a < 3; ++a) {
      const auto& v = savedPointAttribute(cloud, names[a], vdbFile, source_);
      for (std::size_t p = 0; p < system_.size(); ++p) system_.v[p][a] = v[p];
    }
    for (std::size_t p = 0; p < system_.size(); ++p) system_.x[p] = cloud.positions[p].cast<double>();
  }

  json statistics() const override {
    double sum = 0.0;
    for (std::size_t s = 0; s < system_.springs.size(); ++s) sum += std::abs(system_.strain(s));
    json j = {{"kinetic_energy_J", system_.kineticEnergy()},
            {"potential_energy_J", system_.potentialEnergy()},
            {"max_strain", maxStrain()},
            {"mean_strain", system_.springs.empty() ? 0.0 : sum / static_cast<double>(system_.springs.size())},
            {"contacts", contacts_},
            {"cg_iterations_per_step", steps_ > 0 ? double(iterations_) / double(steps_) : 0.0},
            {"unconverged_solves", unconverged_},
            {"preconditioner_setups", preconditionerSetups_},
            {"vertices", system_.size()},
            {"triangles", mesh_.triangles.size()}};
    if (loop_) {
      j["repulsion_pairs"] = last_.pointTrianglePairs + last_.edgeEdgePairs;
      j["repulsions"] = last_.repulsions;
      j["inner_steps"] = last_.innerSteps;
      j["self_collisions"] = last_.collisions.collisions;
      j["impact_zones"] = last_.collisions.impactZones;
      j["collision_passes"] = last_.collisions.passes;
      j["unresolved_collision_steps"] = unresolvedSteps_;
    }
    if (kind_ == "cloth") {
      j["self_intersections"] = selfIntersections_;
      j["vertices_inside_bodies"] = verticesInside_;
      j["intersecting_steps"] = intersectingSteps_;
    }
    if (!system_.tetrahedra.empty()) {
      long inverted = 0;
      for (const solids::TetrahedronSpring& t : system_.tetrahedra) inverted += solids::tetrahedronVolume6(system_, t.v) <= 0.0;
      j["tetrahedra"] = system_.tetrahedra.size();
      j["inverted_tetrahedra"] = inverted;
    }
    return j;
  }

 private:
  // The exact referee after every step, independent of the collision handling
  // (collision/triangle_intersection.hpp): intersecting triangle pairs and vertices inside bodies.
  // A step that leaves any is counted and named in a warning.
  void refereeStep() {
    ScopedStage stage(timers_, "cloth: intersection check");
    selfIntersections_ = static_cast<long>(solids::countSelfIntersections(system_.x, mesh_.triangles));
    verticesInside_ = 0;
    for (std::size_t v = 0; v < system_.size(); ++v)
      for (const auto& shape : bodyShapes_) verticesInside_ += shape->distance(system_.x[v]) < -1e-9;
    if (selfIntersections_ == 0 && verticesInside_ == 0) return;
    ++intersectingSteps_;
    logger().warn("cloth: step {} (t = {:.4g} s) ends with {} intersecting triangle pairs and {} vertices inside "
                  "bodies",
                  steps_, time_, selfIntersections_, verticesInside_);
  }

  // Each triangle's drag c A ((u - v) . n) n at the step's start, u the winds at its centroid and
  // v its mean velocity, a third on each vertex (linear drag along the normal, as in Selle ch. 6's
  // leaves and wardrobe).
  void windForces() {
    system_.external.assign(system_.size(), Vec3::Zero());
    for (const auto& t : mesh_.triangles) {
      const Vec3 a = system_.x[t[0]], b = system_.x[t[1]], c = system_.x[t[2]];
      const Vec3 cross = (b - a).cross(c - a);
      const double twiceArea = cross.norm();
      if (!(twiceArea > 0.0)) continue;
      const Vec3 n = cross / twiceArea, centroid = (a + b + c) / 3.0;
      Vec3 wind = Vec3::Zero();
      for (const auto& w : winds_) wind += w.velocity(centroid, time_);
      const Vec3 v = (system_.v[t[0]] + system_.v[t[1]] + system_.v[t[2]]) / 3.0;
      const Vec3 f = windDrag_ * 0.5 * twiceArea * (wind - v).dot(n) * n;
      for (const int k : t) system_.external[static_cast<std::size_t>(k)] += f / 3.0;
    }
  }

  // pins[] and bodies[]: velocity, angular_velocity, center.
  static geometry::RigidMotion rigidMotion(const json& entry) {
    return {sceneVector<3>(entry.at("velocity")), sceneVector<3>(entry.at("angular_velocity")),
            sceneVector<3>(entry.at("center"))};
  }

  struct Script {  // pinned vertices that move
    geometry::RigidMotion motion;
    std::vector<int> vertices;
    std::vector<Vec3> rest;  // their positions at t = 0
  };

  // The mesh's triangles over the vertices where they stand (a solid's interior vertices too).
  TriangleMesh surfaceNow() const {
    TriangleMesh now = mesh_;
    now.vertices = system_.x;
    return now;
  }

  // The bodies as they stand: signed distance at the cell centres, negative inside. Sampled once
  // for bodies at rest, once per time for moving ones (the VDB frame and the preview share it).
  const Grid<float, 3>& bodyDistance() const {
    const bool moving =
        std::any_of(bodyMotion_.begin(), bodyMotion_.end(), [](const geometry::RigidMotion& m) { return m.moves(); });
    if (bodyDistance_ && (!moving || bodyDistanceTime_ == time_)) return *bodyDistance_;
    Grid<float, 3> distance(spec_, std::numeric_limits<float>::infinity());
    for (const auto& shape : bodyShapes_) {
      const Grid<float, 3> d = shape->distanceField(spec_);
      for (std::size_t i = 0; i < distance.count(); ++i) distance[i] = std::min(distance[i], d[i]);
    }
    bodyDistance_ = std::move(distance);
    bodyDistanceTime_ = time_;
    return *bodyDistance_;
  }

  // Moving bodies (bodies[].velocity, angular_velocity) as they stand at time t: the contact step
  // evaluates them at the step's end (Selle ch. 6.5).
  void moveBodies(double t) {
    for (std::size_t b = 0; b < bodyRest_.size(); ++b) {
      const geometry::RigidMotion& motion = bodyMotion_[b];
      if (!motion.moves()) continue;
      if (motion.turns())
        bodyShapes_[b] = std::make_shared<geometry::RigidlyMoved>(bodyRest_[b].shape, motion, t);
      else
        bodyShapes_[b] = std::make_shared<geometry::Translated<3>>(bodyRest_[b].shape, motion.velocity * t);
      solids::ContactBody body = bodyRest_[b];
      body.shape = bodyShapes_[b];
      body.center = motion.centerAt(t);
      contact_.setBody(b, body);
    }
  }

  // A scripted pin moves rigidly (geometry::RigidMotion). Over a step its vertices move at the
  // chord's velocity (x(t + dt) - x(t)) / dt, so the step's linear motion lands on the exact
  // positions, which placePins then sets (no drift of the radius).
  void scriptPins(double t, double dt) {
    for (const Script& script : scripts_)
      for (std::size_t k = 0; k < script.vertices.size(); ++k)
        system_.v[static_cast<std::size_t>(script.vertices[k])] =
            (script.motion.apply(script.rest[k], t + dt) - script.motion.apply(script.rest[k], t)) / dt;
  }
  void placePins(double t) {
    for (const Script& script : scripts_)
      for (std::size_t k = 0; k < script.vertices.size(); ++k)
        system_.x[static_cast<std::size_t>(script.vertices[k])] = script.motion.apply(script.rest[k], t);
  }

  // One outer step of the collision loop (Selle ch. 6.2), its stages timed as Table 6.3's A, B, C.
  solids::NewmarkStats collisionStep(double dt) {
    const double start = time_;
    // k_i inner steps (ch. 6.3), more where the explicit part's limit asks for them.
    const double innerSteps = loop_->settings().innerSteps;
    last_ = loop_->step(system_, dt, [this, dt, innerSteps] { return std::min(innerStableTimestep(), dt / innerSteps); },
                        contact_.empty() ? nullptr : &contact_,
                        [this, start](double t) { moveBodies(start + t); });
    timers_.add("cloth: pairs (A)", last_.secondsPairs);
    timers_.add("cloth: inner steps (B)", last_.secondsInner);
    timers_.add("cloth: collisions (C)", last_.secondsCollisions);
    if (last_.collisions.unresolved > 0) {
      ++unresolvedSteps_;
      logger().warn("cloth: {} self-collisions left unresolved after {} passes at step {} (impact zones of {} particles)",
                    last_.collisions.unresolved, last_.collisions.passes, steps_ + 1, last_.collisions.zoneParticles);
    }
    return last_.newmark;
  }

  void buildCollisionLoop(const json& c, const solids::NewmarkSettings& newmark) {
    solids::ClothCollisionSettings settings;
    settings.innerSteps = static_cast<int>(c.at("inner_steps").get<long long>());
    settings.repulsion.thickness = c.at("thickness").get<double>();
    // Repulsion holds apart the closest points of edges that share no vertex; with a thickness
    // above the edge length, neighbouring edges of a flat sheet are such pairs, and the cloth
    // would push itself apart.
    std::vector<double> lengths;  // of the triangles' edges at rest (interior edges twice)
    double inverseLength = 0.0;
    for (const auto& t : mesh_.triangles)
      for (int k = 0; k < 3; ++k) {
        lengths.push_back((system_.x[t[k]] - system_.x[t[(k + 1) % 3]]).norm());
        inverseLength += 1.0 / lengths.back();
      }
    std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
    const double median = lengths[lengths.size() / 2];
    if (!(settings.repulsion.thickness < median))
      throw InputError(fmt::format("{}: 'cloth.thickness' {:.3g} m is not below the mesh's median edge length {:.3g} m: "
                                   "neighbouring edges would repel each other; lower it or refine the mesh",
                                   source_, settings.repulsion.thickness, median));
    settings.repulsion.friction = c.at("self_friction").get<double>();
    double stiffness = c.at("repulsion_stiffness").get<double>();
    if (stiffness == 0.0)  // the edge springs' k / l0 [N/m], averaged over the triangles' edges
      stiffness = c.at("edge_stiffness").get<double>() * inverseLength / static_cast<double>(lengths.size());
    settings.repulsion.stiffness = stiffness;
    settings.strainLimit = strainLimit_;
    settings.strainLimitSweeps = kStrainLimitSweeps;
    loop_ = std::make_unique<solids::ClothCollisionLoop>(mesh_.triangles, system_.size(), newmark, settings);
  }

  // Under mpirun (Selle ch. 8.2): the particles cut by the recursive median at their starting
  // places, every process holding the whole cloth; the solves, the search for pairs, contacts and
  // crossings and the repulsions split (solids/particle_split.hpp), everything else run alike on
  // every process, so that all keep the same state and rank 0 writes it.
  void splitAmongProcesses(const Scene& scene, const solids::NewmarkSettings& settings) {
    const int ranks = parallel::worldSize();
    // The grid's split keys (0: not given) have no meaning for particles.
    const json& mpi = scene.resolved.at("mpi");
    const bool blocksGiven = std::any_of(mpi.at("blocks").begin(), mpi.at("blocks").end(),
                                         [](const json& n) { return n.get<double>() != 0.0; });
    for (const auto& [key, given] : {std::pair{"blocks", blocksGiven}, std::pair{"ghost_layers", mpi.at("ghost_layers").get<int>() != 0}})
      if (given)
        throw InputError(fmt::format("{}: 'mpi.{}' is for grids split into blocks; a {} splits by the recursive median of its "
                                     "particles (Selle ch. 8.2) and takes no grid layout: remove the key",
                                     source_, key, kind_));
    if ((ranks & (ranks - 1)) != 0)
      throw InputError(fmt::format("{}: a {} splits among a power of two processes (the recursive median cuts of Selle "
                                   "ch. 8.2), not {}: run it with mpirun -np 2, 4, 8, ...",
                                   source_, kind_, ranks));
    if (settings.preconditioner != solids::SolvePreconditioner::Jacobi)
      throw InputError(fmt::format("{}: '{}.preconditioner' multigrid does not split among processes (its V-cycle mixes "
                                   "the processes' rows); use \"jacobi\" under mpirun",
                                   source_, kind_));
    split_ = std::make_unique<parallel::SplitCloth>(system_.x, MPI_COMM_WORLD);
    stepper_.setSplit(split_.get());
    if (loop_) loop_->setSplit(split_.get());
  }

  // The largest stretch of any spring (compression, of bending springs across a fold above all, is
  // not a failure).
  double maxStrain() const {
    double largest = 0.0;
    for (std::size_t s = 0; s < system_.springs.size(); ++s) largest = std::max(largest, system_.strain(s));
    return largest;
  }

  void buildCloth(const Scene& scene, const json& c) {
    mesh_ = clothMesh(scene, c);
    solids::ClothMaterial material;
    material.arealDensity = c.at("density").get<double>();
    material.edgeStiffness = c.at("edge_stiffness").get<double>();
    material.edgeDamping = c.at("edge_damping").get<double>();
    material.bendStiffness = c.at("bend_stiffness").get<double>();
    material.bendDamping = c.at("bend_damping").get<double>();
    try {
      system_ = solids::clothSystem(mesh_, material);
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("{}: 'cloth': {}", meshSource_, e.what()));
    }
  }

  // BCC tetrahedra of the shape, their surface for outputs, then the initial squash.
  void buildSolid(const Scene& scene, const json& c) {
    const auto shape = sceneShape<3>(scene, c.at("shape"), "solid.shape");
    solids::TetMesh tets;
    try {
      tets = solids::bccTetMesh(*shape, c.at("spacing").get<double>());
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("{}: 'solid.shape': {}", source_, e.what()));
    }
    if (tets.tetrahedra.empty())
      throw InputError(fmt::format("{}: 'solid.spacing': no tetrahedron of that size fits in 'solid.shape'; make it smaller",
                                   source_));
    solids::SolidMaterial material;
    material.density = c.at("density").get<double>();
    material.edgeStiffness = c.at("edge_stiffness").get<double>();
    material.edgeDamping = c.at("edge_damping").get<double>();
    material.altitudeStiffness = c.at("altitude_stiffness").get<double>();
    material.altitudeDamping = c.at("altitude_damping").get<double>();
    system_ = solids::solidSystem(tets, material);
    mesh_.vertices = tets.vertices;
    mesh_.triangles = solids::boundaryTriangles(tets);
    const Vec3 scale = sceneVector<3>(c.at("initial_scale"));
    Vec3 centre = Vec3::Zero();
    for (const Vec3& x : system_.x) centre += x / static_cast<double>(system_.size());
    for (Vec3& x : system_.x) x = centre + (x - centre).cwiseProduct(scale);
  }

  TriangleMesh clothMesh(const Scene& scene, const json& c) {
    const json& m = c.at("mesh");
    const std::string file = m.at("file").get<std::string>();
    if (file.empty()) {
      const json& p = c.at("patch");
      const Vec3 quads = Vec3(p.at("quads")[0].get<double>(), p.at("quads")[1].get<double>(), 0.0);
      meshSource_ = source_;
      try {
        return solids::clothPatch(sceneVector<3>(p.at("origin")), sceneVector<3>(p.at("edge_u")),
                                  sceneVector<3>(p.at("edge_v")), static_cast<int>(quads[0]), static_cast<int>(quads[1]));
      } catch (const std::invalid_argument& e) {
        throw InputError(fmt::format("{}: 'cloth.patch': {}", source_, e.what()));
      }
    }
    const fs::path path = scene.directory() / file;
    meshSource_ = path.string();
    if (!fs::exists(path)) throw InputError(fmt::format("{}: 'cloth.mesh.file': {} does not exist", source_, path.string()));
    TriangleMesh mesh = path.extension() == ".ply" ? io::readPlyMesh(path).mesh : io::readObj(path);
    const double scale = m.at("scale").get<double>();
    const Vec3 translate = sceneVector<3>(m.at("translate"));
    for (Vec3& x : mesh.vertices) x = scale * x + translate;
    return mesh;
  }

  std::string kind_, vertices_;
  std::string source_, meshSource_, name_, meshFormat_;
  StageTimers& timers_;
  GridSpec<3> spec_;
  double cfl_;
  TriangleMesh mesh_;
  solids::MassSpringSystem system_;
  solids::BodyContact contact_;
  std::vector<std::shared_ptr<const geometry::Shape3>> bodyShapes_;  // as they stand now
  std::vector<solids::ContactBody> bodyRest_;  // as they stand at t = 0
  std::vector<geometry::RigidMotion> bodyMotion_;
  mutable std::optional<Grid<float, 3>> bodyDistance_;  // bodyDistance()'s, sampled at bodyDistanceTime_
  mutable double bodyDistanceTime_ = 0.0;
  solids::NewmarkStepper stepper_;
  std::vector<Script> scripts_;
  std::unique_ptr<solids::ClothCollisionLoop> loop_;  // cloth with self-collisions
  std::unique_ptr<parallel::SplitCloth> split_;         // under mpirun
  solids::ClothCollisionStats last_;                  // of the last outer step
  long unresolvedSteps_ = 0;
  bool implicitSprings_ = true;
  double strainLimit_ = 0.0;
  std::vector<double> springMass_;  // each spring's reduced mass (the free end's with one end pinned)
  render::FrameRenderConfig previewRender_;
  Grid<float, 3> emptyMedium_;
  std::vector<turbulence::TurbulentWind<3>> winds_;
  double windDrag_ = 0.0;
  double massPerDragArea_ = 0.0;  // the smallest m / A over the free particles [kg/m^2]
  double time_ = 0.0;  // simulated [s]
  long steps_ = 0, iterations_ = 0, unconverged_ = 0, preconditionerSetups_ = 0;
  long selfIntersections_ = 0, verticesInside_ = 0, intersectingSteps_ = 0;  // refereeStep
  int contacts_ = 0;
};

std::unique_ptr<Phenomenon> createCloth(const Scene& scene, StageTimers& timers) {
  return std::make_unique<MassSpringPhenomenon>(scene, timers, "cloth");
}

std::unique_ptr<Phenomenon> createSolid(const Scene& scene, StageTimers& timers) {
  return std::make_unique<MassSpringPhenomenon>(scene, timers, "solid");
}

}  // namespace

PhenomenonType clothPhenomenonType() {
  return {"cloth", "a mass-spring cloth on bodies with friction (Selle ch. 5-6)", &declareCloth, &massSpringBytesPerCell,
          &createCloth, true};
}

PhenomenonType solidPhenomenonType() {
  return {"solid", "a mass-spring solid of BCC tetrahedra with altitude springs (Selle ch. 5)", &declareSolid,
          &massSpringBytesPerCell, &createSolid};
}

}  // namespace msim::scene
