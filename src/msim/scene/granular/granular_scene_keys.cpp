#include "msim/scene/granular/granular_scene_keys.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/geometry/shape_adapters.hpp"
#include "msim/scene/granular/granular_bodies.hpp"
#include "msim/scene/keys/json_vectors.hpp"
#include "msim/scene/phenomenon_support.hpp"
#include "msim/scene/scene_file.hpp"
#include "msim/scene/schema/shape_schema.hpp"
#include "msim/scene/schema/key_suggestion.hpp"
#include "msim/scene/keys/turbulent_wind_keys.hpp"

namespace msim::scene {
namespace {

using nlohmann::json;

// The common shapes plus a capped cylinder (a silo, a column of sand).
Schema granularShapeSchema(std::string description) {
  Schema cylinder = Schema::object("capped cylinder around the segment a-b");
  cylinder.vector("a", "m", 3, "centre of one flat end");
  cylinder.vector("b", "m", 3, "centre of the other flat end");
  cylinder.number("radius", "m", "radius").min(0.0, Bound::Exclusive);
  Schema shape = shapeSchema(std::move(description));
  shape.alternative("cylinder", std::move(cylinder));
  return shape;
}

Schema granularKeys() {
  Schema g = Schema::object("granular materials: sand as a continuum with particles (Narain 2011, ch. 5)");
  g.number("cfl", "", 0.5, "no particle moves more than this many cells per step (ch. 5.5)").min(0.0, Bound::Exclusive).max(5.0);
  g.number("flip_ratio", "", 0.9, "FLIP share of the particle velocity update (1 = pure FLIP, 0 = PIC)").min(0.0).max(1.0);
  g.integer("staggered_iterations", 2, "outer pressure / friction iterations per step (ch. 5.3.5)").min(1).max(20);
  g.number("tolerance", "", 1e-5, "relative projected-gradient tolerance of each QP solve").min(0.0, Bound::Exclusive).max(1.0);
  g.integer("max_iterations", 400, "MPRGP iterations per QP solve").min(1);
  g.boolean("friction", true, "frictional stress (off: a frictionless, pressure-only material)");
  g.boolean("bilateral", false,
            "cells at least half full also resist expansion (with friction off: an inviscid liquid, for comparison "
            "with sand; off: the unilateral constraint of the seed, grains dilate freely)");
  g.boolean("split_merge", true, "split stretched particles and merge crowded ones (ch. 5.4.1)");
  g.number("particles_per_cell", "", granular::kDefaultParticlesPerCell,
           "seeding density k: particle spacing dx / cbrt(k), particle radius r = dx / (2 cbrt(k)) (8: the seed's "
           "r = dx/4)")
      .min(1.0)
      .max(granular::kMaxParticlesPerCell);
  g.integer("render_points_per_particle", 0, "render points per particle (ch. 5.6); 0 = none").min(0).max(256);
  g.number("max_step", "s", 0.01, "longest time step").min(0.0, Bound::Exclusive);
  g.integer("seed", 1, "jitter of the seeded particles").min(0);
  g.number("air_response_time", "s", 0.1,
           "response time tau of a free grain to the air of winds[]: drag (u_air - v) / tau scaled by the open volume "
           "1 - phi (Stokes: tau = rho_grain d^2 / (18 mu_air), 0.1 s for grains of about 0.1 mm)")
      .min(0.0, Bound::Exclusive);
  return g;
}

Schema materialSchema() {
  Schema m = Schema::object("a granular material");
  m.string("name", "referred to by regions[].material").required();
  m.number("density", "kg/m^3", 1600.0, "rho_max: density of the fully packed material").min(0.0, Bound::Exclusive);
  m.number("friction", "", 0.6, "alpha: Drucker-Prager friction coefficient (eq. 5.15); 0 = a frictionless fluid")
      .min(0.0)
      .max(2.0);
  m.vector("colour", "", {0.76, 0.6, 0.36}, "linear RGB in the preview").min(0.0).max(1.0);
  return m;
}

Schema regionSchema() {
  Schema r = Schema::object("material seeded at t = 0 (granular.particles_per_cell per cell, jittered)");
  r.field("shape", granularShapeSchema("where the material is").required());
  r.string("material", "", "name in materials[]; empty = the first material");
  r.number("fill_fraction", "", 1.0, "volume fraction phi of the seeded material").min(0.0, Bound::Exclusive).max(1.0);
  r.vector("velocity", "m/s", {0.0, 0.0, 0.0}, "initial velocity");
  return r;
}

Schema explosionSchema() {
  Schema e = Schema::object("an instantaneous outward impulse (Fig. 5.1)");
  e.vector("centre", "m", 3, "centre of the blast").required();
  e.number("radius", "m", "particles and body centres within it are pushed").min(0.0, Bound::Exclusive).required();
  e.number("speed", "m/s", "outward radial velocity added").min(0.0, Bound::Exclusive).required();
  e.number("time", "s", "when it goes off").min(0.0).required();
  return e;
}

Schema solidSchema() {
  Schema s = Schema::object("a static solid: walls and floors the material rests on, containers");
  s.field("shape", granularShapeSchema("the solid").required());
  s.boolean("inverted", false, "the solid is everything outside the shape (a container: the shape is its cavity)");
  return s;
}

struct GranularSceneBuilder {
  const Scene& scene;
  const json& r;
  std::string source;
  GranularSceneSetup out;
  Vec3 lo, hi;  // the domain

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw InputError(fmt::format("{}: '{}' {}", source, key, what));
  }

  bool overlapsDomain(const geometry::Bounds<3>& b) const {
    return (b.min.array() < hi.array()).all() && (b.max.array() > lo.array()).all();
  }

  void simulation() {
    if (scene.dimensions != 3) fail("domain.min", "granular scenes are 3D: give 3 numbers for domain.min and domain.max");
    lo = scene.origin;
    hi = scene.origin + scene.dx * scene.resolution.cast<double>();
    const json& g = r.at("granular");
    granular::GranularSettings s;
    s.grid = scene.gridSpec<3>();
    s.gravity = paddedVec3(r.at("gravity"));
    s.cfl = g.at("cfl").get<double>();
    s.flipRatio = g.at("flip_ratio").get<double>();
    s.stress.staggeredIterations = g.at("staggered_iterations").get<int>();
    s.stress.tolerance = g.at("tolerance").get<double>();
    s.stress.maxIterations = g.at("max_iterations").get<int>();
    s.stress.friction = g.at("friction").get<bool>();
    s.stress.bilateral = g.at("bilateral").get<bool>();
    s.splitMerge = g.at("split_merge").get<bool>();
    s.particlesPerCell = g.at("particles_per_cell").get<double>();
    s.renderPointsPerParticle = g.at("render_points_per_particle").get<std::size_t>();
    s.airResponseTime = g.at("air_response_time").get<double>();
    out.maxStep = g.at("max_step").get<double>();
    std::vector<granular::GranularMaterial> materials;
    const json& list = r.at("materials");
    for (std::size_t k = 0; k < list.size(); ++k) {
      const std::string key = fmt::format("materials[{}]", k);
      const std::string name = list[k].at("name").get<std::string>();
      if (name.empty()) fail(key + ".name", "must not be empty");
      if (std::find(out.materialNames.begin(), out.materialNames.end(), name) != out.materialNames.end())
        fail(key + ".name", fmt::format("'{}' names two materials", name));
      granular::GranularMaterial m{list[k].at("density").get<double>(), list[k].at("friction").get<double>()};
      try {
        granular::validate(m, k);
      } catch (const std::invalid_argument& e) {
        fail(key, e.what());
      }
      materials.push_back(m);
      out.materialNames.push_back(name);
      out.colours.push_back(paddedVec3(list[k].at("colour")));
    }
    try {
      out.sim = std::make_unique<granular::GranularSimulation>(s, std::move(materials));
    } catch (const std::invalid_argument& e) {
      fail("granular", e.what());
    }
  }

  // Meshes answer per particle and step, so they are sampled once at half the cell size.
  std::shared_ptr<const geometry::Shape<3>> solidShape(const json& shape, const std::string& key) const {
    std::shared_ptr<const geometry::Shape<3>> exact = sceneShape<3>(scene, shape, key);
    if (shape.at("type") != "mesh") return exact;
    GridSpec<3> fine = scene.gridSpec<3>();
    fine.dx *= 0.5;
    fine.res = 2 * fine.res + IVec3::Constant(4);
    fine.origin -= Vec3::Constant(2.0 * fine.dx);
    return std::make_shared<geometry::Sampled<3>>(std::move(exact), fine);
  }

  void solids() {
    const json& list = r.at("solids");
    rigid::World& world = out.sim->world();
    for (std::size_t k = 0; k < list.size(); ++k) {
      const std::string key = fmt::format("solids[{}]", k);
      const json& shape = list[k].at("shape");
      std::shared_ptr<const geometry::Shape<3>> solid = solidShape(shape, key + ".shape");
      const bool inverted = list[k].at("inverted").get<bool>();
      if (!inverted && !overlapsDomain(solid->bounds())) fail(key + ".shape", "lies outside the domain");
      if (inverted) solid = std::make_shared<geometry::Inverted<3>>(std::move(solid));
      out.sim->addStaticSolid(solid);
      out.solids.push_back(solid);
      // Bodies collide with the solids the rigid world knows: planes, boxes and spheres.
      const std::string type = shape.at("type").get<std::string>();
      if (inverted) continue;
      if (type == "plane") {
        const Vec3 n = paddedVec3(shape.at("normal")).normalized();
        world.addPlane(rigid::Plane{n, n.dot(paddedVec3(shape.at("point"))), {}});
      } else if (type == "box") {
        const Vec3 a = paddedVec3(shape.at("min")), b = paddedVec3(shape.at("max"));
        rigid::RigidBody box = rigid::RigidBody::makeStatic(rigid::Box{0.5 * (b - a)});
        box.position = 0.5 * (a + b);
        world.addBody(std::move(box));
      } else if (type == "sphere") {
        rigid::RigidBody ball = rigid::RigidBody::makeStatic(rigid::Sphere{shape.at("radius").get<double>()});
        ball.position = paddedVec3(shape.at("center"));
        world.addBody(std::move(ball));
      }
    }
  }

  std::uint16_t materialIndex(const json& region, const std::string& key) const {
    const std::string name = region.at("material").get<std::string>();
    if (name.empty()) return 0;
    const auto it = std::find(out.materialNames.begin(), out.materialNames.end(), name);
    if (it == out.materialNames.end())
      fail(key + ".material", fmt::format("names no material: '{}' (materials: {})", name, quotedList(out.materialNames)));
    return static_cast<std::uint16_t>(it - out.materialNames.begin());
  }

  void regions() {
    const json& list = r.at("regions");
    const auto base = r.at("granular").at("seed").get<std::uint64_t>();
    for (std::size_t k = 0; k < list.size(); ++k) {
      const std::string key = fmt::format("regions[{}]", k);
      const std::shared_ptr<const geometry::Shape<3>> shape = sceneShape<3>(scene, list[k].at("shape"), key + ".shape");
      const geometry::Bounds<3> b = shape->bounds();
      if (!overlapsDomain(b)) fail(key + ".shape", "lies outside the domain: no material can be seeded there");
      granular::SeedOptions options;
      options.fillFraction = list[k].at("fill_fraction").get<double>();
      options.velocity = paddedVec3(list[k].at("velocity"));
      options.material = materialIndex(list[k], key);
      // The same seed for every region: a cell's jitter then does not depend on which region fills it.
      options.seed = base;
      try {
        out.sim->seed(b.min.cwiseMax(lo), b.max.cwiseMin(hi), [&](const Vec3& x) { return shape->distance(x) < 0.0; },
                      options);
      } catch (const std::invalid_argument& e) {
        fail(key + ".shape", fmt::format("holds no particle: it lies entirely inside solids or bodies, or is thinner "
                                         "than a grid cell ({})", e.what()));
      }
    }
  }

  void explosions() {
    const json& list = r.at("explosions");
    for (std::size_t k = 0; k < list.size(); ++k) {
      GranularExplosion e;
      e.centre = paddedVec3(list[k].at("centre"));
      e.radius = list[k].at("radius").get<double>();
      e.speed = list[k].at("speed").get<double>();
      e.time = list[k].at("time").get<double>();
      const Vec3 reach = Vec3::Constant(e.radius);
      if (!overlapsDomain({e.centre - reach, e.centre + reach}))
        fail(fmt::format("explosions[{}].centre", k), "puts the blast outside the domain");
      out.explosions.push_back(e);
    }
  }
};

}  // namespace

void declareGranularKeys(Schema& root) {
  root.vector("gravity", "m/s^2", {0.0, -9.81, 0.0}, "acceleration of gravity; the solver's up axis is opposite its "
                                                      "largest component");
  root.field("granular", granularKeys());
  root.array("materials", materialSchema(), "the granular materials (at least one)").items(1);
  root.array("regions", regionSchema(), "where material is seeded at t = 0").items(1);
  root.array("explosions", explosionSchema(), "instantaneous blasts");
  root.array("solids", solidSchema(), "static solids (a container is an 'inverted' one)");
  root.array("bodies", granularBodySchema(), "rigid bodies coupled with the material");
  declareTurbulentWinds(root);
}

GranularSceneSetup buildGranularScene(const Scene& scene) {
  GranularSceneBuilder b{scene, scene.resolved, scene.file.string(), {}, {}, {}};
  b.simulation();
  b.solids();
  try {
    b.out.bodies = addSceneBodies(scene, b.out.sim->world());
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: 'bodies' {}", b.source, e.what()));
  }
  b.regions();
  b.explosions();
  for (auto& wind : turbulentWinds<3>(scene)) b.out.sim->addWind(std::move(wind));
  return std::move(b.out);
}

}  // namespace msim::scene
