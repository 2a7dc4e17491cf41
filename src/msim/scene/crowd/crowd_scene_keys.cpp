#include "msim/scene/crowd/crowd_scene_keys.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/core/log.hpp"
#include "msim/core/rng.hpp"
#include "msim/crowd/direct_planner.hpp"
#include "msim/crowd/navigation_field.hpp"
#include "msim/crowd/obstacle_index.hpp"
#if MSIM_WITH_ROADMAP
#include "msim/crowd/roadmap/roadmap.hpp"
#endif
#include "msim/scene/keys/json_vectors.hpp"
#include "msim/scene/scene_file.hpp"

namespace msim::scene {
namespace {

using nlohmann::json;
using crowd::Polygon;

// Planar regions: obstacles, goal regions, spawn and inflow regions.
Schema regionSchema(std::string description, bool withPoint) {
  Schema box = Schema::object("axis-aligned rectangle");
  box.vector("min", "m", 2, "lower corner");
  box.vector("max", "m", 2, "upper corner");
  Schema circle = Schema::object("disc (a 32-sided polygon as an obstacle)");
  circle.vector("center", "m", 2, "centre");
  circle.number("radius", "m", "radius").min(0.0, Bound::Exclusive);
  Schema polygon = Schema::object("simple polygon, vertices in order (either orientation)");
  polygon.array("vertices", Schema::vectorItem("m", 2, "vertex"), "the corners").items(3);
  Schema shape = Schema::variant(std::move(description));
  if (withPoint) {
    Schema point = Schema::object("a point; agents arrive within the radius");
    point.vector("position", "m", 2, "the point");
    point.number("radius", "m", 0.5, "arrival radius").min(0.0, Bound::Exclusive);
    shape.alternative("point", std::move(point));
  }
  shape.alternative("box", std::move(box)).alternative("circle", std::move(circle)).alternative("polygon", std::move(polygon));
  return shape;
}

void agentKeys(Schema& s, bool opposite) {
  s.string("goal", opposite ? "name of a goal in goals[], or 'opposite': the point mirrored through the group's region "
                              "centre (each agent its own goal, as in the circle scene of Fig. 4.5)"
                            : "name of a goal in goals[]")
      .required();
  s.string("model", "uic", "uic: the continuum (ch. 4.4); orca: per-agent ORCA; scripted: walks 'waypoints'")
      .choices({"uic", "orca", "scripted"});
  s.number("radius", "m", 0.0, "body radius; 0 = crowd.agent.radius").min(0.0);
  s.number("max_speed", "m/s", 0.0, "walking speed (the mean of a normal distribution); 0 = crowd.agent.max_speed")
      .min(0.0);
  s.string("speed_distribution", "fixed",
           "fixed: every agent walks at max_speed; uniform: drawn from [speed_min, speed_max]; normal: N(max_speed, "
           "speed_sd) truncated to [speed_min, speed_max] (a population's spread, RiMEA test 7)")
      .choices({"fixed", "uniform", "normal"});
  s.number("speed_min", "m/s", 0.0, "uniform and normal: the slowest walker");
  s.number("speed_max", "m/s", 0.0, "uniform and normal: the fastest walker");
  s.number("speed_sd", "m/s", 0.0, "normal: the standard deviation");
}

Schema crowdKeys() {
  Schema c = Schema::object("dense crowds: agents with a continuum (Narain 2011, ch. 4)");
  Schema agent = Schema::object("defaults for every agent");
  agent.number("radius", "m", 0.25, "body radius; d_min = 2 radius between two agents").min(0.0, Bound::Exclusive);
  agent.number("max_speed", "m/s", 1.4, "preferred walking speed (1.34 m/s: Weidmann 1993)").min(0.0, Bound::Exclusive);
  c.field("agent", agent);
  Schema uic = Schema::object("the unilateral incompressibility constraint (ch. 4.4)");
  uic.boolean("enabled", true, "project the crowd flow (off: agents walk their preferred velocity, Fig. 4.3b)");
  uic.number("packing", "", 0.56,
             "alpha of eq. 4.4, the fraction of hexagonal close packing a crowd reaches; at 0.56 the discs of the "
             "pairwise separation (1.2 d_min) fill 0.56 x 1.2^2 = 81% of close packing at rho_max, below random "
             "close packing (about 93%), so pairwise resolution can reach its target").min(0.0, Bound::Exclusive).max(1.0);
  uic.number("rho_max", "1/m^2", 0.0, "maximum density; 0 = eq. 4.4, 2 alpha / (sqrt(3) d_min^2)").min(0.0);
  uic.number("tolerance", "", 5e-3, "QP tolerance: overdensity left per cell, relative to rho_max").min(0.0, Bound::Exclusive);
  uic.integer("max_iterations", 500, "MPRGP iterations per solve").min(1);
  uic.number("cell_size", "m", 0.0,
             "the continuum's cell; 0 = the domain's cell, coarsened by a whole factor to at least the agents' "
             "diameter d_min (one agent alone in a smaller cell exceeds rho_max and the continuum stalls the crowd) "
             "and refined to put 2 cells across the narrowest door; walls and doors stay exact polygons at any size, "
             "and planning has crowd.planner.cell_size")
      .min(0.0);
  uic.string("speed_density", "weidmann",
             "walking speed of the continuum's agents: 'weidmann': max_speed x v_W(rho) / 1.34 with Weidmann's (1993) "
             "fundamental diagram, rho the others per free m^2 in the 1.5 m square 0.5 m ahead (calibrated against "
             "measured bottleneck flows, docs/evacuation.md), or 'constant': max_speed at any density (the seed)")
      .choices({"weidmann", "constant"});
  c.field("uic", uic);
  Schema col = Schema::object("pairwise collision resolution after each step (ch. 4.3.3)");
  col.boolean("enabled", true, "push overlapping agents apart (off: Fig. 4.3c)");
  col.number("separation", "", 1.2, "pairs closer than this x d_min are pushed to it (ch. 4.5.1: 'somewhat larger')").min(1.0).max(2.0);
  col.integer("iterations", 6, "most Gauss-Seidel sweeps per step").min(1).max(100);
  col.number("tolerance", "", 0.03, "stop the sweeps once none moves an agent farther than this x d_min").min(0.0);
  c.field("collision_resolution", col);
  Schema orca = Schema::object("ORCA agents (van den Berg et al. 2011)");
  orca.number("neighbour_distance", "m", 3.0, "neighbours farther than this are ignored").min(0.0, Bound::Exclusive);
  orca.integer("max_neighbours", 10, "closest neighbours considered").min(1);
  orca.number("time_horizon", "s", 2.0, "avoid agents this far ahead in time").min(0.0, Bound::Exclusive);
  orca.number("time_horizon_obstacles", "s", 1.0, "avoid obstacles this far ahead in time").min(0.0, Bound::Exclusive);
  c.field("orca", orca);
  Schema ahead = Schema::object("long-range collision avoidance (Golas ch. 3, docs/crowd.md#lookahead)");
  ahead.integer("levels", 0, "i_max: look dt_i = 2^(i-1) base_step ahead for i = 1..levels (the seed: 8); 0: off")
      .min(0)
      .max(16);
  ahead.number("base_step", "s", 0.01, "dt of the horizons (the seed's 0.01 s: 8 levels reach 1.28 s)")
      .min(0.0, Bound::Exclusive)
      .max(1.0);
  ahead.number("coarsening", "", 2.0,
               "c: level i sees agents with the effective radius r / c^i (discrete) and on cells h_0 c^i (continuum)")
      .min(1.0)
      .max(4.0);
  ahead.number("sigma_max", "m/s^2", 0.0,
               "curtailing: the depth falls linearly with the local inconsistency metric to 0 at this value (eq. 3.10); "
               "0: no curtailing (constant lookahead)")
      .min(0.0);
  ahead.number("metric_window", "s", 0.4, "tau_w: the inconsistency metric's samples halve their weight every tau_w / 2")
      .min(0.0, Bound::Exclusive);
  ahead.string("metric_mode", "sqrt_eigenvalue_sum",
               "sigma = sum of the square roots of C's eigenvalues (eq. 3.9) or its trace (Fig. 3.7's caption)")
      .choices({"sqrt_eigenvalue_sum", "trace"});
  ahead.string("method", "discrete",
               "how ORCA agents look ahead: discrete (levels in ORCA's linear program, ch. 3.6), continuum (eq. 3.2 on the "
               "future densities instead of ORCA, ch. 3.5) or hybrid (the two blended by density and velocity spread, ch. 3.9); "
               "UIC agents always take the continuum lookahead as their preferred velocity")
      .choices({"discrete", "continuum", "hybrid"});
  ahead.string("discrete_solve", "single",
               "how the discrete lookahead's far levels meet level 0: single (in ORCA's one linear program with the "
               "neighbours, ch. 3.6) or cascade (solved apart every `refresh` seconds, their answer level 0's preferred "
               "velocity, Fig. 3.4)")
      .choices({"single", "cascade"});
  ahead.number("cell", "m", 1.0, "h_0: the future-density pyramid's finest cell (level i: h_0 c^i)")
      .min(0.0, Bound::Exclusive);
  ahead.number("refresh", "s", 1.0,
               "the continuum lookahead and the discrete cascade ask their far levels (1..levels) again this often, each "
               "agent keeping their suggestion in between; 0: every step (the seed)")
      .min(0.0);
  ahead.number("plan_horizon", "s", 1.0, "T: how far ahead eq. 3.1 weighs the density change along a direction")
      .min(0.0, Bound::Exclusive);
  ahead.number("max_density", "1/m^2", 5.5, "rho_max of the continuum's walking speed f(rho) = v_max (1 - rho / rho_max)")
      .min(0.0, Bound::Exclusive);
  Schema blend = Schema::object("the hybrid's weights (eqs. 3.12-3.13)");
  blend.number("density_min", "1/m^2", 2.0, "rho_cmin: pure discrete below").min(0.0);
  blend.number("density_max", "1/m^2", 4.0, "rho_dmax: pure continuum above (more than density_min)").min(0.0);
  blend.number("variance_low", "", 1.0, "c_1: continuum while the velocity spread is below c_1 x the mean speed").min(0.0);
  blend.number("variance_high", "", 2.0, "c_2: discrete once the spread reaches c_2 x the mean speed (more than variance_low)")
      .min(0.0);
  ahead.field("blend", blend);
  c.field("lookahead", ahead);
  Schema turbulence = Schema::object("inter-personal stress in extreme densities (Golas ch. 4, docs/crowd.md#stress)");
  turbulence.boolean("enabled", false,
                     "UIC agents move by eqs. 4.6-4.7 (navigation, discomfort and friction) instead of the UIC projection");
  turbulence.number("critical_density", "1/m^2", 3.5, "rho_crit: no stress below").min(0.0, Bound::Exclusive);
  turbulence.number("yield_density", "1/m^2", 5.5, "rho_yield: the discomfort's plateau and full friction (more than critical_density)")
      .min(0.0, Bound::Exclusive);
  turbulence.number("c1", "", 13.33, "eq. 4.10's scale").min(0.0, Bound::Exclusive);
  turbulence.number("c2", "", 1.5, "eq. 4.10's offset");
  turbulence.number("epsilon", "1/m^2", 0.01, "eq. 4.10's guard at the yield density").min(0.0, Bound::Exclusive);
  turbulence.string("lower_branch", "continuous",
                    "g below the critical density: continuous (the middle branch's value there) or literal (0, with "
                    "the printed constants' jump)")
      .choices({"continuous", "literal"});
  turbulence.number("friction", "", 0.75, "alpha above the yield density (0: discomfort only, Fig. 4.10's control)")
      .min(0.0)
      .max(1.0);
  turbulence.number("relaxation", "s", 0.2,
                    "tau: how fast agents take their collision-free velocity (eq. 4.3; the seed gives none: 0.2 s lets "
                    "navigation set the speed below 5 /m^2, as Fig. 4.5a, docs/crowd_turbulence.md)")
      .min(0.0, Bound::Exclusive);
  turbulence.number("max_acceleration", "m/s^2", 3.0, "a_max of eq. 4.7").min(0.0, Bound::Exclusive);
  turbulence.number("max_step", "s", 0.01,
                    "longest step with the stress model (crowd.max_step still applies): the stiff discomfort's "
                    "clamped acceleration turns from step to step and shakes agents by about a_max x step")
      .min(0.0, Bound::Exclusive);
  c.field("turbulence", turbulence);
  Schema planner = Schema::object("global planning (ch. 4.3.1)");
  planner.string("type", "auto",
                 "auto: direct without obstacles, else navigation_field; roadmap: the seed's CDT roadmap (in builds "
                 "with -DMSIM_WITH_CGAL=ON)")
      .choices({"auto", "direct", "navigation_field", "roadmap"});
  planner.number("cell_size", "m", 0.25, "navigation field cell").min(0.0, Bound::Exclusive);
  c.field("planner", planner);
  c.number("max_step", "s", 0.1, "longest time step").min(0.0, Bound::Exclusive);
  c.number("grid_cfl", "", 0.5, "grid cells the fastest agent may cross in one step (eq. 4.14 is first order)")
      .min(0.0, Bound::Exclusive);
  c.integer("seed", 1, "random placement of agents (groups, inflows)").min(0);
  c.string("colour_by", "speed",
           "colour of the agents in the pictures (pressure: Helbing's rho Var(v) over 3 x 3 cells, yellow from 0.04 /s^2)")
      .choices({"speed", "density", "group", "pressure"});
  c.boolean("trajectories", true, "write trajectories.csv (frame,id,x,y,vx,vy,inconsistency)");
  c.number("dense_fraction", "", 0.8, "'densest regions' of the nearest-neighbour metric: density >= this x rho_max")
      .min(0.0)
      .max(1.0);
  c.number("summaries_from", "s", 0.0,
           "the run-long turbulence summaries (pressure_map.png and results.turbulence: each cell's peak pressure, "
           "the samples by density) gather the frames from this time on, after the start's transient")
      .min(0.0);
  return c;
}

Schema groupSchema() {
  Schema g = Schema::object("agents placed at the start");
  g.integer("count", "number of agents").min(1).required();
  g.field("region", regionSchema("where they stand (see placement)", false).required());
  g.string("placement", "random",
           "random: uniformly at random in the region, then relaxed apart; outline: evenly spaced along its outline "
           "(a circle's circumference: the ring of Golas Fig. 3.1)")
      .choices({"random", "outline"});
  agentKeys(g, true);
  g.array("waypoints", Schema::vectorItem("m", 2, "waypoint"),
          "scripted agents: the path, relative to the region centre (each agent keeps its offset)");
  g.boolean("loop", false, "scripted agents: start over after the last waypoint");
  return g;
}

Schema inflowSchema() {
  Schema f = Schema::object("agents entering at a steady rate");
  f.field("region", regionSchema("where they appear, with the mean velocity of the agents there bound for the same goal", false).required());
  f.number("rate", "1/s", "agents per second (0 with 'recycle')").min(0.0).required();
  f.boolean("recycle", false,
            "re-admits agents that leave through exits besides its rate: the crowd keeps its count "
            "(fixed-density runs)");
  f.number("start", "s", 0.0, "first agent").min(0.0);
  f.number("stop", "s", 1e30, "no agents after this").min(0.0);
  agentKeys(f, false);
  return f;
}

Polygon regionPolygon(const json& shape) {
  const std::string type = shape.at("type").get<std::string>();
  if (type == "box") return crowd::rectangle(sceneVector<2>(shape.at("min")), sceneVector<2>(shape.at("max")));
  if (type == "circle") return crowd::regularPolygon(sceneVector<2>(shape.at("center")), shape.at("radius").get<double>(), 32);
  Polygon p;
  for (const json& v : shape.at("vertices")) p.vertices.push_back(sceneVector<2>(v));
  return p;
}

Vec2 regionCentre(const json& shape, const Polygon& polygon) {
  const std::string type = shape.at("type").get<std::string>();
  if (type == "circle") return sceneVector<2>(shape.at("center"));
  Vec2 lo, hi;
  crowd::bounds(polygon, lo, hi);
  return 0.5 * (lo + hi);
}

// `count` points evenly spaced along the region's outline: a circle's own circumference, else the
// polygon's edges by arc length (Golas Fig. 3.1's circle: agents on a ring, each walking to the
// opposite point).
std::vector<Vec2> outlinePoints(const json& shape, const Polygon& polygon, std::size_t count) {
  std::vector<Vec2> points(count);
  if (shape.at("type").get<std::string>() == "circle") {
    const Vec2 centre = sceneVector<2>(shape.at("center"));
    const double radius = shape.at("radius").get<double>();
    for (std::size_t k = 0; k < count; ++k) {
      const double angle = 2.0 * M_PI * double(k) / double(count);
      points[k] = centre + radius * Vec2(std::cos(angle), std::sin(angle));
    }
    return points;
  }
  const std::size_t n = polygon.vertices.size();
  double perimeter = 0.0;
  for (std::size_t e = 0; e < n; ++e) perimeter += (polygon.vertices[(e + 1) % n] - polygon.vertices[e]).norm();
  std::size_t edge = 0;
  double edgeStart = 0.0;  // arc length where `edge` begins
  for (std::size_t k = 0; k < count; ++k) {
    const double s = perimeter * double(k) / double(count);
    while (edge + 1 < n && edgeStart + (polygon.vertices[edge + 1] - polygon.vertices[edge]).norm() <= s) {
      edgeStart += (polygon.vertices[edge + 1] - polygon.vertices[edge]).norm();
      ++edge;
    }
    const Vec2 a = polygon.vertices[edge], b = polygon.vertices[(edge + 1) % n];
    const double length = (b - a).norm();
    points[k] = length > 0.0 ? Vec2(a + (s - edgeStart) / length * (b - a)) : a;
  }
  return points;
}

double outlineLength(const json& shape, const Polygon& polygon) {
  if (shape.at("type").get<std::string>() == "circle") return 2.0 * M_PI * shape.at("radius").get<double>();
  double perimeter = 0.0;
  for (std::size_t e = 0; e < polygon.vertices.size(); ++e)
    perimeter += (polygon.vertices[(e + 1) % polygon.vertices.size()] - polygon.vertices[e]).norm();
  return perimeter;
}

crowd::AgentModel modelOf(const std::string& name) {
  if (name == "orca") return crowd::AgentModel::Orca;
  if (name == "scripted") return crowd::AgentModel::Scripted;
  return crowd::AgentModel::Uic;
}

struct CrowdSceneBuilder {
  const Scene& scene;
  const json& r;
  std::string source;
  CrowdSceneSetup out;
  std::vector<std::string> goalNames;
  crowd::StaticObstacles obstacleIndex;

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw InputError(fmt::format("{}: '{}' {}", source, key, what));
  }

  void requireInside(const Polygon& p, const std::string& key) const {
    Vec2 lo, hi;
    crowd::bounds(p, lo, hi);
    if ((lo.array() < out.settings.lo.array() - 1e-9).any() || (hi.array() > out.settings.hi.array() + 1e-9).any())
      fail(key, fmt::format("reaches outside the domain [{}, {}] x [{}, {}]", out.settings.lo.x(), out.settings.hi.x(),
                            out.settings.lo.y(), out.settings.hi.y()));
  }

  void domainAndGrid() {
    if (scene.dimensions != 2) fail("domain.min", "crowds are planar: give 2 numbers for domain.min and domain.max");
    out.settings.lo = sceneVector<2>(r.at("domain").at("min"));
    // The walls stand where the scene puts them; the continuum's grid may overhang them.
    out.settings.hi = sceneVector<2>(r.at("domain").at("max"));
  }

  void settings() {
    const json& c = r.at("crowd");
    const double radius = c.at("agent").at("radius").get<double>();
    out.dMin = 2.0 * radius;
    const json& u = c.at("uic");
    out.settings.uic = u.at("enabled").get<bool>();
    // Eq. 4.4: hexagonal close packing of discs of diameter d_min, scaled by alpha.
    const double closePacking = 2.0 / (std::sqrt(3.0) * out.dMin * out.dMin);
    double rhoMax = u.at("rho_max").get<double>();
    if (rhoMax == 0.0) rhoMax = u.at("packing").get<double>() * closePacking;
    if (rhoMax > closePacking * (1.0 + 1e-9))
      fail("crowd.uic.rho_max", fmt::format("= {:.4g} agents/m^2 exceeds the hexagonal close packing 2/(sqrt(3) d_min^2) = "
                                            "{:.4g} of agents of radius {} m (eq. 4.4): agents would have to overlap",
                                            rhoMax, closePacking, radius));
    if (rhoMax < 0.25 * closePacking)
      logger().warn("{}: crowd.uic.rho_max = {:.3g} agents/m^2 is below a quarter of the close packing {:.3g} of agents "
                    "of radius {} m: the crowd will jam far from contact",
                    source, rhoMax, closePacking, radius);
    out.settings.uicSettings.rhoMax = rhoMax;
    out.settings.uicSettings.tolerance = u.at("tolerance").get<double>();
    out.settings.uicSettings.maxIterations = u.at("max_iterations").get<int>();
    out.settings.speedDensity.enabled = u.at("speed_density").get<std::string>() == "weidmann";
    const json& col = c.at("collision_resolution");
    out.settings.collisionResolution = col.at("enabled").get<bool>();
    out.settings.collision.separation = col.at("separation").get<float>();
    out.settings.collision.iterations = col.at("iterations").get<int>();
    out.settings.collision.tolerance = col.at("tolerance").get<float>();
    const json& o = c.at("orca");
    out.settings.orca.neighbourDist = o.at("neighbour_distance").get<float>();
    out.settings.orca.maxNeighbours = o.at("max_neighbours").get<int>();
    out.settings.orca.timeHorizon = o.at("time_horizon").get<float>();
    out.settings.orca.timeHorizonObst = o.at("time_horizon_obstacles").get<float>();
    const json& la = c.at("lookahead");
    out.settings.lookahead.levels = la.at("levels").get<int>();
    out.settings.lookahead.baseStep = la.at("base_step").get<double>();
    out.settings.lookahead.coarsening = la.at("coarsening").get<double>();
    const double sigmaMax = la.at("sigma_max").get<double>();
    out.settings.lookahead.sigmaMax = sigmaMax > 0.0 ? sigmaMax : std::numeric_limits<double>::infinity();
    out.settings.lookahead.metricWindow = la.at("metric_window").get<double>();
    out.settings.lookahead.metricMode = la.at("metric_mode").get<std::string>() == "trace"
                                            ? crowd::lookahead::MetricMode::Trace
                                            : crowd::lookahead::MetricMode::SqrtEigenvalueSum;
    const std::string method = la.at("method").get<std::string>();
    out.settings.lookahead.method = method == "continuum" ? crowd::lookahead::LookaheadMethod::Continuum
                                    : method == "hybrid"  ? crowd::lookahead::LookaheadMethod::Hybrid
                                                          : crowd::lookahead::LookaheadMethod::Discrete;
    out.settings.lookahead.discreteSolve = la.at("discrete_solve").get<std::string>() == "cascade"
                                               ? crowd::lookahead::DiscreteSolve::Cascade
                                               : crowd::lookahead::DiscreteSolve::Single;
    out.settings.lookahead.cell = la.at("cell").get<double>();
    out.settings.lookahead.refresh = la.at("refresh").get<double>();
    out.settings.lookahead.continuum.planHorizon = la.at("plan_horizon").get<double>();
    out.settings.lookahead.continuum.maxDensity = la.at("max_density").get<double>();
    const json& b = la.at("blend");
    crowd::lookahead::BlendThresholds& t = out.settings.lookahead.blend;
    t.continuumFrom = b.at("density_min").get<double>();
    t.discreteUpTo = b.at("density_max").get<double>();
    t.uniformBelow = b.at("variance_low").get<double>();
    t.disorderedFrom = b.at("variance_high").get<double>();
    if (!(t.discreteUpTo > t.continuumFrom))
      fail("crowd.lookahead.blend.density_max", fmt::format("= {} must be more than crowd.lookahead.blend.density_min = {} "
                                                            "(eq. 3.12 blends between them)", t.discreteUpTo, t.continuumFrom));
    if (!(t.disorderedFrom > t.uniformBelow))
      fail("crowd.lookahead.blend.variance_high", fmt::format("= {} must be more than crowd.lookahead.blend.variance_low = {} "
                                                              "(eq. 3.13 blends between them)", t.disorderedFrom, t.uniformBelow));
    const json& tu = c.at("turbulence");
    if (tu.at("enabled").get<bool>()) {
      crowd::stress::StressSettings st;
      st.laws.critical = tu.at("critical_density").get<double>();
      st.laws.yield = tu.at("yield_density").get<double>();
      if (!(st.laws.yield > st.laws.critical))
        fail("crowd.turbulence.yield_density", fmt::format("= {} must be more than crowd.turbulence.critical_density = {}",
                                                           st.laws.yield, st.laws.critical));
      st.laws.c1 = tu.at("c1").get<double>();
      st.laws.c2 = tu.at("c2").get<double>();
      st.laws.epsilon = tu.at("epsilon").get<double>();
      st.laws.continuousLowerBranch = tu.at("lower_branch").get<std::string>() == "continuous";
      st.laws.frictionMax = tu.at("friction").get<double>();
      st.relaxation = tu.at("relaxation").get<double>();
      st.maxAcceleration = tu.at("max_acceleration").get<double>();
      out.settings.stress = st;
    }
    out.settings.seed = c.at("seed").get<std::uint64_t>();
    out.maxStep = c.at("max_step").get<double>();
    // The stress model's discomfort is stiff: its waves run at sqrt(g'(rho)), 10 m/s at 5 /m^2 and
    // 190 m/s just below the yield density, and its acceleration, clamped at a_max (eq. 4.7),
    // overshoots and turns from one step to the next, shaking agents by about a_max dt. The crowd
    // pressure and speeds depend on the step until it is short (docs/crowd_turbulence.md measures
    // the Hajj merge at 0.05, 0.01 and 0.005 s). 0.01 s is the step of Golas' Table 3.1.
    if (tu.at("enabled").get<bool>()) out.maxStep = std::min(out.maxStep, tu.at("max_step").get<double>());
    out.gridCfl = c.at("grid_cfl").get<double>();
    out.colourBy = c.at("colour_by").get<std::string>();
    out.trajectories = c.at("trajectories").get<bool>();
    out.denseFraction = c.at("dense_fraction").get<double>();
    out.summariesFrom = c.at("summaries_from").get<double>();
    const double duration = r.at("time").at("duration").get<double>();
    if (out.summariesFrom >= duration)
      fail("crowd.summaries_from", fmt::format("= {} s is not before the run's end (time.duration = {} s): the "
                                               "turbulence summaries would gather no frame", out.summariesFrom, duration));
  }

  // The UIC's grid over the walkable box, from the box's lower corner; where its cells overhang
  // the box the simulation counts them covered. Automatic: the domain's cell, coarsened by a whole
  // factor to at least the agents' diameter (a cell of side h holds at most 1/h^2 of one agent's
  // density, which beyond rho_max makes the continuum hold back even a lone walker), and refined
  // where the narrowest passage (a door) is under kCellsPerPassage cells wide: on coarser cells a
  // door passes fewer people than on finer ones (the evacuation room through two 1 m doors takes
  // 28% longer on cells of 0.83 m, 1.2 across, than on 0.5 m), and two cells across pass what
  // finer cells pass.
  void continuumGrid(double cellSize) {
    constexpr double kCellsPerPassage = 2.0;
    const GridSpec<2> domain = scene.gridSpec<2>();
    double cell = cellSize;
    if (cell == 0.0) {
      const int factor = std::max(1, static_cast<int>(std::ceil(out.dMin / domain.dx - 1e-9)));
      cell = factor * domain.dx;
      const double passage = crowd::narrowestPassage(out.obstacles, out.settings.lo, out.settings.hi, out.dMin);
      if (std::max(out.dMin, passage / kCellsPerPassage) < cell) {
        cell = std::max(out.dMin, passage / kCellsPerPassage);
        logger().info("{}: the crowd continuum takes cells of {:.3g} m, {:g} across the narrowest passage ({:.3g} m); "
                      "set crowd.uic.cell_size to choose",
                      source, cell, kCellsPerPassage, passage);
      } else if (factor > 1) {
        logger().info("{}: the crowd continuum takes cells of {:g} m ({} x {} domain cells, at least the agents' diameter "
                      "{:g} m); set crowd.uic.cell_size to choose",
                      source, cell, factor, factor, out.dMin);
      }
    } else if (cell < out.dMin) {
      logger().warn("{}: crowd.uic.cell_size = {:g} m is below the agents' diameter {:g} m: one agent alone can exceed "
                    "rho_max in a cell and the continuum may stall the crowd",
                    source, cell, out.dMin);
    }
    const Vec2 extent = out.settings.hi - out.settings.lo;
    IVec2 res;
    for (int a = 0; a < 2; ++a) res[a] = std::max(1, static_cast<int>(std::ceil(extent[a] / cell - 1e-9)));
    out.settings.grid = GridSpec<2>(out.settings.lo, cell, res);
  }

  void obstacles() {
    const json& list = r.at("obstacles");
    for (std::size_t k = 0; k < list.size(); ++k) {
      const std::string key = fmt::format("obstacles[{}]", k);
      Polygon p = regionPolygon(list[k].at("shape"));
      crowd::validateSimple(p, fmt::format("{}: '{}.shape'", source, key));
      requireInside(p, key + ".shape");
      const Vec2 velocity = sceneVector<2>(list[k].at("velocity"));
      const Vec2 amplitude = sceneVector<2>(list[k].at("oscillation"));
      const double frequency = list[k].at("frequency").get<double>();
      if (velocity.isZero() && (amplitude.isZero() || frequency == 0.0)) {
        out.obstacles.push_back(std::move(p));
      } else {
        out.moving.push_back(crowd::MovingObstacle{std::move(p), velocity, amplitude, frequency});
      }
    }
    // Agents are placed clear of the moving obstacles' start positions too.
    std::vector<Polygon> atStart = out.obstacles;
    for (const crowd::MovingObstacle& m : out.moving) atStart.push_back(m.shape);
    obstacleIndex = crowd::StaticObstacles(atStart, largestRadius());
  }

  void goals() {
    const json& list = r.at("goals");
    for (std::size_t k = 0; k < list.size(); ++k) {
      const std::string key = fmt::format("goals[{}]", k);
      const std::string name = list[k].at("name").get<std::string>();
      if (name.empty() || name == "opposite") fail(key + ".name", "must be a non-empty name other than 'opposite'");
      if (std::find(goalNames.begin(), goalNames.end(), name) != goalNames.end())
        fail(key + ".name", fmt::format("'{}' names two goals", name));
      crowd::Goal g;
      g.exit = list[k].at("exit").get<bool>();
      const json& shape = list[k].at("shape");
      if (shape.at("type") == "point") {
        g.point = sceneVector<2>(shape.at("position"));
        g.arrivalRadius = shape.at("radius").get<double>();
        requireInside(crowd::regularPolygon(g.point, 1e-6, 3), key + ".shape.position");
      } else {
        g.kind = crowd::Goal::Kind::Region;
        g.regions.push_back(regionPolygon(shape));
        crowd::validateSimple(g.regions.back(), fmt::format("{}: '{}.shape'", source, key));
        requireInside(g.regions.back(), key + ".shape");
      }
      const json& more = list[k].at("more_shapes");
      if (!more.empty() && g.kind == crowd::Goal::Kind::Point)
        fail(key + ".more_shapes", "a set of regions needs 'shape' to be a region too, not a point");
      for (std::size_t m = 0; m < more.size(); ++m) {
        const std::string member = fmt::format("{}.more_shapes[{}]", key, m);
        g.regions.push_back(regionPolygon(more[m]));
        crowd::validateSimple(g.regions.back(), fmt::format("{}: '{}'", source, member));
        requireInside(g.regions.back(), member);
      }
      goalNames.push_back(name);
      out.goals.push_back(std::move(g));
    }
  }

  std::uint32_t goalIndex(const json& entry, const std::string& key) const {
    const std::string name = entry.at("goal").get<std::string>();
    const auto it = std::find(goalNames.begin(), goalNames.end(), name);
    if (it == goalNames.end()) {
      std::string known;
      for (const auto& n : goalNames) known += (known.empty() ? "'" : ", '") + n + "'";
      fail(key + ".goal", fmt::format("names no goal: '{}' (goals: {}; or 'opposite')", name,
                                      known.empty() ? std::string("none") : known));
    }
    return static_cast<std::uint32_t>(it - goalNames.begin());
  }

  crowd::AgentSpec agentSpec(const json& entry, std::uint32_t group) const {
    const json& c = r.at("crowd").at("agent");
    crowd::AgentSpec a;
    a.model = modelOf(entry.at("model").get<std::string>());
    const double radius = entry.at("radius").get<double>();
    const double speed = entry.at("max_speed").get<double>();
    a.radius = static_cast<float>(radius > 0.0 ? radius : c.at("radius").get<double>());
    a.maxSpeed = static_cast<float>(speed > 0.0 ? speed : c.at("max_speed").get<double>());
    a.group = group;
    return a;
  }

  // The walking speeds of a group or inflow (speed_distribution and its keys); exit 2 naming the
  // key for speeds that can be zero or negative.
  crowd::SpeedDistribution speedDistribution(const json& entry, const crowd::AgentSpec& base, const std::string& key) const {
    crowd::SpeedDistribution d;
    const std::string kind = entry.at("speed_distribution").get<std::string>();
    d.kind = kind == "uniform" ? crowd::SpeedDistribution::Kind::Uniform
             : kind == "normal" ? crowd::SpeedDistribution::Kind::Normal
                                : crowd::SpeedDistribution::Kind::Fixed;
    d.mean = base.maxSpeed;
    d.sd = entry.at("speed_sd").get<double>();
    d.min = entry.at("speed_min").get<double>();
    d.max = entry.at("speed_max").get<double>();
    try {
      d.validate(key);
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("{}: {}", source, e.what()));
    }
    return d;
  }

  // Uniform random points in the region where an agent of the radius clears every obstacle.
  Vec2 randomPoint(Rng& rng, const Polygon& region, float radius, const std::string& key) const {
    const Vec2 x = crowd::randomFreePoint(rng, region, radius, obstacleIndex);
    if (!x.allFinite())
      fail(key, fmt::format("has no free room for agents of radius {} m: it lies inside obstacles", radius));
    return x;
  }

  // Largest agent radius any group or inflow asks for (the obstacle index answers up to it).
  float largestRadius() const {
    double largest = r.at("crowd").at("agent").at("radius").get<double>();
    for (const char* list : {"groups", "inflows"})
      for (const json& e : r.at(list)) largest = std::max(largest, e.at("radius").get<double>());
    return static_cast<float>(largest);
  }

  // Every agent can reach its goal (the planner knows the obstacles); names the group and goal.
  void checkReachable() const {
    for (std::size_t i = 0; i < out.agents.size(); ++i) {
      if (out.agents.model[i] == crowd::AgentModel::Scripted) continue;
      const Vec2 x = out.agents.position[i].cast<double>();
      const std::uint32_t g = out.agents.goal[i];
      if (!std::isfinite(out.planner->distance(g, x)))
        fail(fmt::format("groups[{}].goal", out.agents.group[i]),
             fmt::format("'{}' cannot be reached from ({:.2f}, {:.2f}), where an agent of the group stands: walls "
                         "enclose the goal or the agent",
                         g < goalNames.size() ? goalNames[g] : std::string("opposite"), x.x(), x.y()));
    }
  }

  void groups() {
    const json& list = r.at("groups");
    Rng rng(out.settings.seed);
    for (std::size_t k = 0; k < list.size(); ++k) {
      const json& g = list[k];
      const std::string key = fmt::format("groups[{}]", k);
      const Polygon region = regionPolygon(g.at("region"));
      crowd::validateSimple(region, fmt::format("{}: '{}.region'", source, key));
      requireInside(region, key + ".region");
      const crowd::AgentSpec base = agentSpec(g, static_cast<std::uint32_t>(k));
      const long long count = g.at("count").get<long long>();
      // The group must fit at the maximum density, or the crowd starts overlapping for good.
      const double area = std::abs(crowd::signedArea(region));
      const double capacity = area * out.settings.uicSettings.rhoMax;
      if (static_cast<double>(count) > capacity)
        fail(key + ".count", fmt::format("= {} agents do not fit in the region's {:.4g} m^2 at rho_max = {:.3g} agents/m^2 "
                                         "(at most {:.0f})", count, area, out.settings.uicSettings.rhoMax, capacity));
      const bool opposite = g.at("goal").get<std::string>() == "opposite";
      const bool scripted = base.model == crowd::AgentModel::Scripted;
      if (scripted && g.at("waypoints").empty()) fail(key + ".waypoints", "scripted agents need at least one waypoint");
      if (!scripted && !g.at("waypoints").empty()) fail(key + ".waypoints", "only scripted agents follow waypoints");
      const std::uint32_t goal = opposite ? 0 : goalIndex(g, key);
      const Vec2 centre = regionCentre(g.at("region"), region);
      const crowd::SpeedDistribution speeds = speedDistribution(g, base, key);
      Rng groupRng = rng.split(k);
      std::vector<Vec2> points(static_cast<std::size_t>(count));
      if (g.at("placement").get<std::string>() == "outline") {
        const double spacing = outlineLength(g.at("region"), region) / double(count);
        if (spacing < 2.0 * base.radius)
          fail(key + ".count", fmt::format("= {} agents of radius {} m do not fit along the region's outline ({:.4g} m "
                                           "apart, less than a diameter)", count, base.radius, spacing));
        points = outlinePoints(g.at("region"), region, points.size());
      } else {
        for (Vec2& x : points) x = randomPoint(groupRng, region, base.radius, key + ".region");
      }
      crowd::sortSpatially(points);
      Rng speedRng = rng.split(list.size() + k);  // apart from the positions': adding spread moves no one
      for (const Vec2& x : points) {
        crowd::AgentSpec a = base;
        a.position = x.cast<float>();
        a.maxSpeed = static_cast<float>(speeds.sample(speedRng));
        a.goal = goal;
        if (opposite && !scripted) {
          crowd::Goal mirrored;
          mirrored.point = 2.0 * centre - x;
          mirrored.arrivalRadius = 0.1;
          a.goal = static_cast<std::uint32_t>(out.goals.size());
          out.goals.push_back(mirrored);
        }
        const std::size_t i = out.agents.add(a);
        if (scripted) {
          crowd::Script s;
          s.agentId = out.agents.id[i];
          for (const json& w : g.at("waypoints")) s.waypoints.push_back(sceneVector<2>(w) + (x - centre) + centre);
          s.loop = g.at("loop").get<bool>();
          out.scripts.push_back(std::move(s));
        }
      }
    }
  }

  void inflows() {
    const json& list = r.at("inflows");
    for (std::size_t k = 0; k < list.size(); ++k) {
      const json& f = list[k];
      const std::string key = fmt::format("inflows[{}]", k);
      crowd::Inflow in;
      in.region = regionPolygon(f.at("region"));
      crowd::validateSimple(in.region, fmt::format("{}: '{}.region'", source, key));
      requireInside(in.region, key + ".region");
      in.rate = f.at("rate").get<double>();
      in.recycle = f.at("recycle").get<bool>();
      if (in.rate == 0.0 && !in.recycle) fail(key + ".rate", "expected a positive number of agents per second (0 only with 'recycle': true)");
      in.start = f.at("start").get<double>();
      in.stop = f.at("stop").get<double>();
      if (in.stop <= in.start) fail(key + ".stop", "must come after 'start'");
      in.agent = agentSpec(f, static_cast<std::uint32_t>(r.at("groups").size() + k));
      in.speeds = speedDistribution(f, in.agent, key);
      if (in.agent.model == crowd::AgentModel::Scripted) fail(key + ".model", "inflow agents cannot be scripted");
      if (f.at("goal").get<std::string>() == "opposite") fail(key + ".goal", "inflow agents need a named goal");
      in.agent.goal = goalIndex(f, key);
      out.inflows.push_back(std::move(in));
    }
  }

  void lines() {
    const json& list = r.at("measurement_lines");
    for (std::size_t k = 0; k < list.size(); ++k) {
      CrowdMeasurementLine l;
      l.name = list[k].at("name").get<std::string>();
      l.from = sceneVector<2>(list[k].at("from"));
      l.to = sceneVector<2>(list[k].at("to"));
      if ((l.to - l.from).norm() <= 0.0) fail(fmt::format("measurement_lines[{}]", k), "has zero length");
      out.lines.push_back(std::move(l));
    }
  }

  void planner() {
    std::string type = r.at("crowd").at("planner").at("type").get<std::string>();
    if (type == "auto") type = out.obstacles.empty() ? "direct" : "navigation_field";
    out.plannerName = type;
    const std::size_t named = goalNames.size();
    if (type == "direct") {
      if (!out.obstacles.empty())
        logger().warn("{}: crowd.planner.type = 'direct' walks straight at goals through {} obstacles; agents will "
                      "press against them", source, out.obstacles.size());
      out.planner = std::make_shared<crowd::DirectPlanner>(out.goals);
      return;
    }
    if (out.goals.size() > named)
      fail("crowd.planner.type", fmt::format("'{}' plans for a few shared goals, but groups with goal 'opposite' give every "
                                             "agent its own; use 'direct' (scenes without obstacles)", type));
    if (type == "roadmap") {
#if MSIM_WITH_ROADMAP
      crowd::RoadmapOptions o;
      o.lo = out.settings.lo;
      o.hi = out.settings.hi;
      out.planner = std::make_shared<crowd::Roadmap>(out.goals, out.obstacles, o);
      return;
#else
      fail("crowd.planner.type",
           "'roadmap' needs the optional roadmap planner, which this build leaves out (it triangulates with CGAL, "
           "whose 2D triangulations are GPL-3): build with -DMSIM_WITH_CGAL=ON, or use 'navigation_field'");
#endif
    }
    crowd::NavigationFieldOptions o;
    o.lo = out.settings.lo;
    o.hi = out.settings.hi;
    o.cellSize = r.at("crowd").at("planner").at("cell_size").get<double>();
    o.clearance = r.at("crowd").at("agent").at("radius").get<double>();
    out.planner = std::make_shared<crowd::NavigationField>(out.goals, out.obstacles, o);
  }
};

}  // namespace

void declareCrowdKeys(Schema& root) {
  root.field("crowd", crowdKeys());
  Schema goal = Schema::object("a place agents walk to");
  goal.string("name", "referred to by groups[].goal and inflows[].goal").required();
  goal.field("shape", regionSchema("the goal: a point or a region", true).required());
  goal.array("more_shapes", regionSchema("a further region of the goal", false),
             "further regions of this goal: with 'shape' a set (of exits, say), each agent heading for the member "
             "nearest along its path");
  goal.boolean("exit", false, "agents that arrive leave the scene (evacuations)");
  root.array("goals", goal, "destinations");
  Schema obstacle = Schema::object("obstacle, static unless it is given a motion");
  obstacle.field("shape", regionSchema("its outline at t = 0", false).required());
  obstacle.vector("velocity", "m/s", {0.0, 0.0}, "v of the motion x(t) = x(0) + v t + A sin(2 pi f t)");
  obstacle.vector("oscillation", "m", {0.0, 0.0}, "amplitude A of the motion");
  obstacle.number("frequency", "1/s", 0.0, "f of the motion").min(0.0);
  root.array("obstacles", obstacle, "walls, pillars, stands: polygons agents walk around");
  root.array("groups", groupSchema(), "agents placed at t = 0");
  root.array("inflows", inflowSchema(), "agents entering during the run (Fig. 4.6)");
  Schema line = Schema::object("a line counting the agents that cross it");
  line.string("name", "line", "column name in run.json and stats.csv");
  line.vector("from", "m", 2, "one end");
  line.vector("to", "m", 2, "other end; agents crossing to the right of from->to count positive");
  root.array("measurement_lines", line, "flow measurement (agents/s and agents/(m s))");
}

CrowdSceneSetup buildCrowdScene(const Scene& scene) {
  CrowdSceneBuilder b{scene, scene.resolved, scene.file.string(), {}, {}, {}};
  b.domainAndGrid();
  b.settings();
  b.obstacles();
  b.continuumGrid(scene.resolved.at("crowd").at("uic").at("cell_size").get<double>());
  b.goals();
  b.groups();
  b.inflows();
  b.lines();
  b.out.groupCount = scene.resolved.at("groups").size() + scene.resolved.at("inflows").size();
  if (b.out.agents.empty() && b.out.inflows.empty())
    throw InputError(b.source + ": the scene has no agents: add 'groups' or 'inflows'");
  b.planner();
  b.checkReachable();
  return std::move(b.out);
}

}  // namespace msim::scene
