#include "msim/scene/smoke/smoke_scene_keys.hpp"

#include <cmath>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/scene/keys/json_vectors.hpp"
#include "msim/scene/phenomenon_support.hpp"
#include "msim/scene/scene_file.hpp"
#include "msim/scene/keys/scene_obstacles.hpp"
#include "msim/scene/schema/shape_schema.hpp"
#include "msim/scene/keys/vortex_particle_keys.hpp"
#include "msim/scene/keys/subgrid_turbulence_keys.hpp"
#include "msim/scene/keys/turbulent_wind_keys.hpp"

namespace msim::scene {

namespace {

using nlohmann::json;

Schema advectionKeys() {
  Schema a = Schema::object("how velocity and scalars are carried by the flow (Selle ch. 2)");
  a.string("scheme", "maccormack", "first_order, or the second-order BFECC / MacCormack built on the block (ch. 2.4)")
      .choices({"first_order", "bfecc", "maccormack"});
  a.string("building_block", "semi_lagrangian", "the first-order step: semi-Lagrangian (any CFL) or upwind (CFL <= 1)")
      .choices({"semi_lagrangian", "upwind"});
  a.string("limiter", "revert", "where a corrected value leaves its stencil's range (ch. 2.7): revert to first order, clamp, or none")
      .choices({"revert", "clamp", "none"});
  a.boolean("first_order_near_solids", true, "first-order values where a stencil touches an obstacle (ch. 2.9)");
  a.string("scalars", "advector",
           "density, temperature and fuel: 'advector' uses the scheme above (sharpest), 'conservative' a finite-volume "
           "flux form that conserves their totals to round-off")
      .choices({"advector", "conservative"});
  return a;
}

Schema smokeKeys() {
  Schema smoke = Schema::object("incompressible smoke on a MAC grid (Selle ch. 2-3)");
  smoke.field("advection", advectionKeys());
  smoke.number("cfl", "", 1.0, "cells the fastest face may cross in one substep (then scaled by time.cfl)")
      .min(0.0, Bound::Exclusive)
      .max(5.0);
  smoke.number("fluid_density", "kg/m^3", 1.0, "density of the air in the pressure equation").min(0.0, Bound::Exclusive);
  smoke.number("ambient_temperature", "K", 293.15, "temperature of the surrounding air").min(0.0, Bound::Exclusive);
  smoke.string("up_axis", "y", "buoyancy pushes hot gas along +this axis").choices({"x", "y", "z"});
  Schema buoyancy = Schema::object("f = (-alpha rho + beta (T - T_ambient)) e_up (Fedkiw, Stam and Jensen 2001)");
  buoyancy.number("alpha", "m^4/(kg s^2)", 0.0, "sinking per unit smoke density").min(0.0);
  buoyancy.number("beta", "m/(s^2 K)", 0.0, "lift per kelvin above ambient").min(0.0);
  smoke.field("buoyancy", buoyancy);
  smoke.number("vorticity_confinement", "", 0.0, "epsilon of the confinement force (ch. 3.2.1); 0 = off").min(0.0);
  smoke.number("wind_coupling", "1/s", 1.0,
               "rate at which the air is pulled towards the turbulent winds (winds[]): drag c (u_wind - u)")
      .min(0.0);
  smoke.number("viscosity", "m^2/s", 0.0, "kinematic viscosity, solved implicitly; 0 = inviscid as in Selle").min(0.0);
  smoke.number("density_dissipation", "1/s", 0.0, "smoke density decays as exp(-rate t)").min(0.0);
  smoke.number("temperature_dissipation", "1/s", 0.0, "T - T_ambient decays as exp(-rate t)").min(0.0);
  Schema pressure = Schema::object("the pressure projection (Selle ch. 3.2)");
  pressure.string("preconditioner", "multigrid", "PCG preconditioner: geometric multigrid or MIC(0)")
      .choices({"multigrid", "mic0"});
  pressure.number("tolerance", "", 1e-5, "relative max-norm residual of the pressure solve").min(0.0, Bound::Exclusive).max(1.0);
  pressure.integer("max_iterations", 500, "PCG iteration cap").min(1);
  smoke.field("pressure", pressure);
  Schema turbulence = Schema::object(
      "procedural sub-grid turbulence (Narain ch. 3): an energy model on the grid, noise particles synthesising "
      "curl-noise eddies on a finer grid that carries the smoke");
  declareSubgridTurbulenceKeys(turbulence, "simulate sub-grid turbulence; density and temperature then live on the fine grid",
                               1.5e-5);
  turbulence.boolean("coupling", true, "the simulated flow is advected by itself plus the turbulence (ch. 3.5.2)");
  turbulence.number("smoke_threshold", "kg/m^3", 1e-4, "cells with less smoke (and not near smoke) get no eddies")
      .min(0.0);
  turbulence.boolean("write_velocity", false,
                     "write the fine velocity U + u' as 'vel' in the VDB frames (large: 12 bytes per fine cell)");
  smoke.field("turbulence", turbulence);
  smoke.field("vortex_particles", vortexParticleKeys());
  smoke.vector("initial_velocity", "m/s", {0.0, 0.0, 0.0}, "velocity of the air at t = 0").lengths({2, 3});
  Schema walls = Schema::object("velocity of each closed side of the domain");
  for (const auto& axis : kDomainSideKeys)
    for (const char* side : axis)
      walls.vector(side, "m/s", {0.0, 0.0, 0.0},
                   "normal part: inflow/outflow wall (Selle ch. 2.9); tangential part drags viscous air (a lid)")
          .lengths({2, 3});
  smoke.field("wall_velocity", walls);
  return smoke;
}

Schema fireKeys() {
  Schema fire = Schema::object("combustion (Stam ch. 6.4.2-6.4.3): fuel burns into flame, flame cools into smoke");
  fire.boolean("enabled", false, "adds the fuel and flame fields and the reactions");
  fire.number("activation_temperature", "K", 2300.0, "T_a of the Arrhenius burning rate (eq. 6.3)").min(0.0, Bound::Exclusive);
  fire.number("reaction_frequency", "1/s", 0.28, "nu_a: burning rate scale").min(0.0);
  fire.number("ignition_temperature", "K", 0.0, "no burning below it (0: the seed's pure Arrhenius law)").min(0.0);
  fire.number("heat_release", "K m^3/kg", 1900.0, "temperature rise per kg/m^3 of fuel burnt").min(0.0);
  fire.number("smoke_temperature", "K", 1500.0, "T_b: flames well below it turn into smoke").min(0.0, Bound::Exclusive);
  fire.number("smoke_frequency", "1/s", 7.0, "nu_b: smoke creation rate scale").min(0.0);
  fire.number("absorption", "m^2/kg", 0.4, "sigma_a: radiative cooling of flames (T^4 law)").min(0.0);
  fire.number("air_heat_capacity", "J/(m^3 K)", 1206.0, "rho c_p of the air heated by radiation").min(0.0, Bound::Exclusive);
  fire.number("fuel_dissipation", "1/s", 0.0, "unburnt fuel decays as exp(-rate t)").min(0.0);
  fire.number("emission", "", 1.0, "brightness of the flames in the preview (radiance per m per kg/m^3 at 1500 K)").min(0.0);
  return fire;
}

}  // namespace

void declareSmokeKeys(Schema& root) {
  root.field("smoke", smokeKeys());
  root.field("fire", fireKeys());

  Schema source = Schema::object("a region emitting smoke, heat, fuel or air");
  source.field("shape", shapeSchema());
  source.string("mode", "add", "add: the numbers are rates per second; set: values imposed in covered cells")
      .choices({"add", "set"});
  source.number("density", "kg/m^3 (set) or kg/(m^3 s) (add)", 1.0, "smoke density").min(0.0);
  source.number("temperature", "K (set) or K/s (add)", 0.0, "set: gas temperature (0 = leave as is); add: heating rate").min(0.0);
  source.number("fuel", "kg/m^3 (set) or kg/(m^3 s) (add)", 0.0, "fuel for fire (needs fire.enabled)").min(0.0);
  source.boolean("inflow", false, "impose 'velocity' on the faces of covered cells before the projection");
  source.vector("velocity", "m/s", {0.0, 0.0, 0.0}, "inflow velocity").lengths({2, 3});
  source.number("expansion", "1/s", 0.0,
                "div u the covered cells keep while the source emits: the gas release of an explosion or a flame "
                "pushing the air out (Selle Fig. 3.4)");
  source.number("start", "s", 0.0, "emits from this time").min(0.0);
  source.number("stop", "s", 0.0, "emits until this time; 0 = to the end").min(0.0);
  root.array("sources", source, "emitters");

  root.array("obstacles", sceneObstacleSchema("a solid the smoke flows around (face fractions: no stair-step leaks)"),
             "static or moving solids");
  declareTurbulentWinds(root);
}

template <int D>
fluid::SmokeParams<D> smokeParams(const Scene& scene) {
  const json& r = scene.resolved;
  const json& s = r.at("smoke");
  const std::string file = scene.file.string();
  fluid::SmokeParams<D> p;

  const json& a = s.at("advection");
  const std::string scheme = a.at("scheme"), block = a.at("building_block"), limiter = a.at("limiter");
  p.advection.scheme = scheme == "first_order" ? numerics::AdvectionScheme::FirstOrder
                       : scheme == "bfecc"     ? numerics::AdvectionScheme::BFECC
                                               : numerics::AdvectionScheme::MacCormack;
  p.advection.block = block == "upwind" ? numerics::BuildingBlock::Upwind : numerics::BuildingBlock::SemiLagrangian;
  p.advection.limiter = limiter == "none"    ? numerics::ExtremaLimiter::None
                        : limiter == "clamp" ? numerics::ExtremaLimiter::ClampExtrema
                                             : numerics::ExtremaLimiter::RevertToFirstOrder;
  p.advection.firstOrderNearSolids = a.at("first_order_near_solids").get<bool>();
  p.scalarTransport = a.at("scalars") == "conservative" ? fluid::ScalarTransport::Conservative
                                                        : fluid::ScalarTransport::Advector;
  p.cfl = s.at("cfl").get<double>();
  if (p.advection.block == numerics::BuildingBlock::Upwind && p.cfl > 1.0)
    throw InputError(fmt::format("{}: 'smoke.cfl' is {} but the upwind building block is only stable up to 1", file, p.cfl));

  p.fluidDensity = s.at("fluid_density").get<double>();
  p.buoyancy.alpha = s.at("buoyancy").at("alpha").get<double>();
  p.buoyancy.beta = s.at("buoyancy").at("beta").get<double>();
  p.buoyancy.ambientTemperature = s.at("ambient_temperature").get<double>();
  p.buoyancy.upAxis = s.at("up_axis").get<std::string>()[0] - 'x';
  if (p.buoyancy.upAxis >= D)
    throw InputError(fmt::format("{}: 'smoke.up_axis' is 'z' but the scene is 2D", file));
  p.vorticityEpsilon = s.at("vorticity_confinement").get<double>();
  p.windCoupling = s.at("wind_coupling").get<double>();
  p.viscosity = s.at("viscosity").get<double>();
  p.densityDissipation = s.at("density_dissipation").get<double>();
  p.temperatureDissipation = s.at("temperature_dissipation").get<double>();
  p.projection.preconditioner = s.at("pressure").at("preconditioner") == "mic0"
                                    ? numerics::PressurePreconditioner::Mic0
                                    : numerics::PressurePreconditioner::Multigrid;
  p.projection.pcg.tolerance = s.at("pressure").at("tolerance").get<double>();
  p.projection.pcg.maxIterations = s.at("pressure").at("max_iterations").get<int>();
  // The runner chooses the substeps; the solver never subdivides a step itself.
  p.maxSubsteps = 1;

  const json& sides = r.at("domain").at("boundaries");
  const json& walls = s.at("wall_velocity");
  double netInflow = 0.0;
  bool allWalls = true;
  for (int axis = 0; axis < D; ++axis)
    for (int side = 0; side < 2; ++side) {
      const char* name = kDomainSideKeys[axis][side];
      const bool open = sides.at(name) == "open";
      p.sides.side[axis][side] = open ? numerics::DomainSide::Open : numerics::DomainSide::Wall;
      const Vec3 v = paddedVec3(walls.at(name));
      if (open && v.squaredNorm() > 0.0)
        throw InputError(fmt::format("{}: 'smoke.wall_velocity.{}' is set but 'domain.boundaries.{}' is 'open'; "
                                     "make that side 'closed' to give it a velocity",
                                     file, name, name));
      allWalls = allWalls && !open;
      for (int b = 0; b < D; ++b) p.wallVelocity[axis][side][b] = v[b];
      double area = 1.0;
      for (int b = 0; b < D; ++b)
        if (b != axis) area *= scene.resolution[b] * scene.dx;
      netInflow += (side == 0 ? v[axis] : -v[axis]) * area;
    }
  if (allWalls && std::abs(netInflow) > 1e-9) {
    throw InputError(fmt::format(
        "{}: 'smoke.wall_velocity' puts a net {:.4g} m^{}/s into a domain closed on every side; an incompressible fluid "
        "needs as much outflow as inflow (or open a side in 'domain.boundaries')",
        file, netInflow, D));
  }
  return p;
}

fluid::CombustionParams combustionParams(const json& r) {
  const json& f = r.at("fire");
  fluid::CombustionParams c;
  c.activationTemperature = f.at("activation_temperature").get<double>();
  c.reactionFrequency = f.at("reaction_frequency").get<double>();
  c.ignitionTemperature = f.at("ignition_temperature").get<double>();
  c.heatRelease = f.at("heat_release").get<double>();
  c.smokeTemperature = f.at("smoke_temperature").get<double>();
  c.smokeFrequency = f.at("smoke_frequency").get<double>();
  c.absorption = f.at("absorption").get<double>();
  c.airHeatCapacity = f.at("air_heat_capacity").get<double>();
  c.ambientTemperature = r.at("smoke").at("ambient_temperature").get<double>();
  return c;
}

template fluid::SmokeParams<2> smokeParams<2>(const Scene&);
template fluid::SmokeParams<3> smokeParams<3>(const Scene&);

fluid::SmokeTurbulenceParams smokeTurbulenceParams(const json& resolved) {
  const json& t = resolved.at("smoke").at("turbulence");
  fluid::SmokeTurbulenceParams p;
  static_cast<turbulence::SubgridTurbulenceParams&>(p) = subgridTurbulenceParams(t);
  p.coupling = t.at("coupling").get<bool>();
  p.smokeThreshold = t.at("smoke_threshold").get<double>();
  p.writeVelocity = t.at("write_velocity").get<bool>();
  p.densityDissipation = resolved.at("smoke").at("density_dissipation").get<double>();
  p.temperatureDissipation = resolved.at("smoke").at("temperature_dissipation").get<double>();
  return p;
}

}  // namespace msim::scene
